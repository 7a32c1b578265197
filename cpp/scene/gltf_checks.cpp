// The checks made on a glTF file before any parser sees it (and the file reads they guard).

#include <fcntl.h>
#include <sys/stat.h>
#include <tiny_gltf.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string_view>

#include "core/errors.h"
#include "scene/image_io.h"
#include "scene/scene_limits.h"

#include "scene/gltf_internal.h"

namespace ssr::gltf_detail {

// ---------------------------------------------------------------------------------------
// Reading hostile files. Everything the file says is checked where it is read: sizes and
// offsets with overflow-checked arithmetic, JSON nesting before any parser sees it (the
// parsers recurse), file references against the model's folder and for being regular
// files before anything is opened for reading, numbers for being finite and in range.
// ---------------------------------------------------------------------------------------

namespace {

constexpr int kMaxJsonDepth = 64;                      // real files nest ~8 deep; extras rarely more

// Length of the well-formed UTF-8 sequence at p[0..n) (RFC 3629: no overlong forms, no
// surrogates, nothing above U+10FFFF), or 0 when it is not one.
size_t utf8_sequence(const unsigned char* p, size_t n) {
    const unsigned c = p[0];
    if (c < 0x80) return 1;
    size_t len;
    unsigned lo = 0x80, hi = 0xBF;
    if (c >= 0xC2 && c <= 0xDF) len = 2;
    else if (c == 0xE0) len = 3, lo = 0xA0;
    else if (c == 0xED) len = 3, hi = 0x9F;
    else if (c >= 0xE1 && c <= 0xEF) len = 3;
    else if (c == 0xF0) len = 4, lo = 0x90;
    else if (c >= 0xF1 && c <= 0xF3) len = 4;
    else if (c == 0xF4) len = 4, hi = 0x8F;
    else return 0;
    if (n < len) return 0;
    if (p[1] < lo || p[1] > hi) return 0;
    for (size_t i = 2; i < len; ++i)
        if (p[i] < 0x80 || p[i] > 0xBF) return 0;
    return len;
}

// A short excerpt of a JSON value for a message.
std::string excerpt(const nlohmann::json& v) {
    std::string s = v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

// tinygltf's percent-decoding of uris (dlib's urldecode), so our check sees the path it opens.
std::string uri_decode(const std::string& s) {
    auto hexval = [](unsigned char c) -> unsigned {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return 0;
    };
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '+') out += ' ';
        else if (s[i] == '%' && s.size() > i + 2) {
            out += char((hexval(uint8_t(s[i + 1])) << 4) | hexval(uint8_t(s[i + 2])));
            i += 2;
        } else out += s[i];
    }
    return out;
}

std::string join_path(const std::string& a, const std::string& b) {  // tinygltf's JoinPath
    if (a.empty()) return b;
    return a.back() == '/' ? a + b : a + "/" + b;
}

}  // namespace

// A message Python can always decode: bytes that are not UTF-8, and control characters,
// become \xNN (a file name or a JSON parser's excerpt can hold anything).
std::string printable(std::string_view s) {
    static const char* hex = "0123456789abcdef";
    std::string out;
    out.reserve(s.size());
    const auto* p = reinterpret_cast<const unsigned char*>(s.data());
    for (size_t i = 0; i < s.size();) {
        const size_t len = utf8_sequence(p + i, s.size() - i);
        if (len == 0 || (p[i] < 0x20 && p[i] != '\n' && p[i] != '\t') || p[i] == 0x7F) {
            out += "\\x";
            out += hex[p[i] >> 4];
            out += hex[p[i] & 15];
            ++i;
        } else {
            out.append(s.data() + i, len);
            i += len;
        }
    }
    return out;
}

// Reads a regular file of at most kMaxFileBytes. The type is checked with stat before the
// file is opened, and again on the open descriptor (O_NONBLOCK: opening a FIFO does not wait
// for a writer), so devices, FIFOs and folders are refused before a single byte is read.
std::vector<uint8_t> read_regular_file(const std::string& path, const std::string& what) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) throw SceneError(what + ": cannot read '" + path + "': " + std::strerror(errno));
    if (!S_ISREG(st.st_mode))
        throw SceneError(what + ": '" + path + "' is not a regular file (a folder, device, FIFO or socket)");
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throw SceneError(what + ": cannot open '" + path + "': " + std::strerror(errno));
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        throw SceneError(what + ": '" + path + "' is not a regular file");
    if (uint64_t(st.st_size) > kMaxFileBytes)
        throw SceneError(what + ": '" + path + "' is " + std::to_string(st.st_size) + " bytes, more than the " +
                         std::to_string(kMaxFileBytes >> 20) + " MiB limit");
    std::vector<uint8_t> data(size_t(st.st_size));
    size_t got = 0;
    while (got < data.size()) {
        const ssize_t n = ::read(fd, data.data() + got, data.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw SceneError(what + ": error reading '" + path + "': " + std::strerror(errno));
        if (n == 0) break;  // the file shrank while we read it
        got += size_t(n);
    }
    data.resize(got);
    return data;
}

// Resolves a file the model refers to (a buffer or image uri, an environment map) and checks
// that it may be read: relative, inside the model's folder once symlinks are resolved (unless
// the caller allowed external files), a regular file, not too large. Returns the real path.
fs::path resolve_reference(const PathPolicy& pol, const std::string& ref, const std::string& what) {
    const std::string fail_prefix = pol.file + ": " + what + ": ";
    const std::string opt_in = "; pass allow_external_files=True to allow files outside the model's folder";
    if (ref.empty()) throw SceneError(fail_prefix + "the uri is empty");
    if (ref.find('\0') != std::string::npos) throw SceneError(fail_prefix + "the uri contains a NUL character");
    const fs::path p(ref);
    if (p.is_absolute() && !pol.allow_external)
        throw SceneError(fail_prefix + "uri '" + ref + "' is an absolute path" + opt_in);
    const fs::path full = p.is_absolute() ? p : pol.dir / p;
    struct stat st {};
    if (::stat(full.c_str(), &st) != 0)
        throw SceneError(fail_prefix + "file not found (looked for " + full.string() + ")");
    std::error_code ec;
    const fs::path real = fs::canonical(full, ec);
    if (ec) throw SceneError(fail_prefix + "cannot resolve '" + full.string() + "': " + ec.message());
    if (!pol.allow_external) {
        const fs::path rel = real.lexically_relative(pol.dir_real);
        if (rel.empty() || *rel.begin() == "..")
            throw SceneError(fail_prefix + "uri '" + ref + "' leads outside the model's folder (to " + real.string() +
                             ")" + opt_in);
    }
    if (!S_ISREG(st.st_mode))
        throw SceneError(fail_prefix + "'" + ref + "' is not a regular file (a folder, device, FIFO or socket)");
    if (uint64_t(st.st_size) > kMaxFileBytes)
        throw SceneError(fail_prefix + "'" + ref + "' is " + std::to_string(st.st_size) + " bytes, more than the " +
                         std::to_string(kMaxFileBytes >> 20) + " MiB limit");
    return real;
}

bool fs_exists(const std::string& path, void* user) { return static_cast<FsContext*>(user)->approved.count(path) > 0; }
std::string fs_expand(const std::string& path, void*) { return path; }  // no ~ or $VAR expansion
bool fs_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    const auto* ctx = static_cast<FsContext*>(user);
    const auto it = ctx->approved.find(path);
    if (it == ctx->approved.end()) {
        if (err) *err += "refused: not a checked file reference";
        return false;
    }
    try {
        *out = read_regular_file(it->second, path);
        return true;
    } catch (const std::exception& e) {
        if (err) *err += e.what();
        return false;
    }
}
bool fs_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is disabled while loading";
    return false;
}

// Checks the JSON text before a parser sees it: valid UTF-8, and nesting of arrays and
// objects (outside strings) no deeper than kMaxJsonDepth. Returns an empty string or the problem.
std::string check_json_text(std::string_view text) {
    const auto* p = reinterpret_cast<const unsigned char*>(text.data());
    for (size_t i = 0; i < text.size();) {
        const size_t len = utf8_sequence(p + i, text.size() - i);
        if (len == 0) return "the JSON is not valid UTF-8 (byte " + std::to_string(i) + ")";
        i += len;
    }
    int depth = 0;
    bool in_string = false, escaped = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (in_string) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                return "the JSON nests arrays and objects deeper than " + std::to_string(kMaxJsonDepth) +
                       " levels (at byte " + std::to_string(i) + ")";
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return {};
}

const std::set<std::string>& implemented_extensions() {
    static const std::set<std::string> names{"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                             "KHR_materials_ior", "KHR_materials_specular", "KHR_texture_transform"};
    return names;
}

// Checks what tinygltf would otherwise trust: array types, buffer/bufferView/accessor sizes
// and offsets (overflow-checked; tinygltf indexes buffers with them unchecked), file references,
// required extensions, the default scene. Approves the external files tinygltf may then read.
void precheck_json(const nlohmann::json& j, const PathPolicy& pol, const std::string& base_dir, bool glb,
                   uint64_t glb_bin_size, FsContext* ctx) {
    const std::string& file = pol.file;
    auto fail = [&](const std::string& what) { throw SceneError(file + ": " + what); };
    if (!j.is_object()) fail("the JSON's top level is not an object");
    auto array = [&](const char* key) -> const nlohmann::json* {
        const auto it = j.find(key);
        if (it == j.end()) return nullptr;
        if (!it->is_array()) fail(std::string("'") + key + "' is not an array");
        return &*it;
    };
    auto object = [&](const nlohmann::json& v, const std::string& what) {
        if (!v.is_object()) fail(what + " is not a JSON object");
    };
    // A non-negative integer field (glTF's integer: JSON numbers like 4 or 4.0).
    auto uint_field = [&](const nlohmann::json& o, const char* key, const std::string& what, bool required,
                          uint64_t fallback) -> uint64_t {
        const auto it = o.find(key);
        if (it == o.end()) {
            if (required) fail(what + ": '" + key + "' is missing");
            return fallback;
        }
        if (it->is_number_unsigned()) return it->get<uint64_t>();
        if (it->is_number_float()) {
            const double d = it->get<double>();
            if (std::isfinite(d) && d >= 0.0 && d <= 9007199254740992.0 && d == std::floor(d)) return uint64_t(d);
        }
        fail(what + ": " + key + " must be a non-negative integer below 2^53, got " + excerpt(*it));
        return 0;
    };
    auto index_field = [&](const nlohmann::json& o, const char* key, const std::string& what, size_t count,
                           const char* target) -> int64_t {
        if (!o.contains(key)) return -1;
        const uint64_t v = uint_field(o, key, what, false, 0);
        if (v >= count)
            fail(what + ": " + key + " " + std::to_string(v) + " is out of range (the file has " + std::to_string(count) +
                 " " + target + ")");
        return int64_t(v);
    };

    if (const auto it = j.find("extensionsRequired"); it != j.end()) {
        if (!it->is_array()) fail("'extensionsRequired' is not an array");
        for (const auto& e : *it) {
            if (!e.is_string()) fail("extensionsRequired holds a non-string " + excerpt(e));
            const std::string name = e.get<std::string>();
            if (!implemented_extensions().count(name))
                fail("the file requires extension '" + name + "', which ssrlab does not implement");
        }
    }
    const auto* scenes = array("scenes");
    if (j.contains("scene")) {
        const size_t n = scenes ? scenes->size() : 0;
        if (n == 0) fail("'scene' names a default scene but the file has no 'scenes' array");
        index_field(j, "scene", "the default scene", n, "scenes");
    }

    std::vector<uint64_t> buffer_bytes;
    if (const auto* buffers = array("buffers")) {
        for (size_t i = 0; i < buffers->size(); ++i) {
            const std::string what = "buffer " + std::to_string(i);
            const auto& b = (*buffers)[i];
            object(b, what);
            const uint64_t len = uint_field(b, "byteLength", what, true, 0);
            if (len == 0) fail(what + ": byteLength is 0");
            if (len > kMaxFileBytes)
                fail(what + ": byteLength " + std::to_string(len) + " is more than the " +
                     std::to_string(kMaxFileBytes >> 20) + " MiB limit");
            if (const auto u = b.find("uri"); u != b.end()) {
                if (!u->is_string()) fail(what + ": uri is not a string");
                const std::string uri = u->get<std::string>();
                if (uri.rfind("data:", 0) != 0) {
                    const std::string decoded = uri_decode(uri);
                    ctx->approved[join_path(base_dir, decoded)] =
                        resolve_reference(pol, decoded, what + " ('" + uri + "')").string();
                }
            } else if (!(glb && i == 0)) {
                fail(what + " has no uri (only a GLB file's first buffer is stored in the file)");
            } else if (len > glb_bin_size) {
                fail(what + ": byteLength " + std::to_string(len) + " is more than the GLB's BIN chunk (" +
                     std::to_string(glb_bin_size) + " bytes)");
            }
            buffer_bytes.push_back(len);
        }
    }
    std::vector<std::pair<uint64_t, uint64_t>> views;  // (buffer, byteLength)
    if (const auto* bvs = array("bufferViews")) {
        for (size_t i = 0; i < bvs->size(); ++i) {
            const std::string what = "bufferView " + std::to_string(i);
            const auto& v = (*bvs)[i];
            object(v, what);
            const uint64_t b = uint_field(v, "buffer", what, true, 0);
            if (b >= buffer_bytes.size())
                fail(what + ": buffer " + std::to_string(b) + " is out of range (the file has " +
                     std::to_string(buffer_bytes.size()) + " buffers)");
            const uint64_t off = uint_field(v, "byteOffset", what, false, 0);
            const uint64_t len = uint_field(v, "byteLength", what, true, 0);
            uint64_t end = 0;
            if (len == 0) fail(what + ": byteLength is 0");
            if (!checked_add(off, len, &end) || end > buffer_bytes[b])
                fail(what + ": byteOffset " + std::to_string(off) + " + byteLength " + std::to_string(len) +
                     " lies outside buffer " + std::to_string(b) + " (" + std::to_string(buffer_bytes[b]) + " bytes)");
            if (v.contains("byteStride")) {
                const uint64_t s = uint_field(v, "byteStride", what, false, 0);
                if (s < 4 || s > 252 || s % 4 != 0)
                    fail(what + ": byteStride " + std::to_string(s) + " is not a multiple of 4 in [4, 252]");
            }
            views.emplace_back(b, len);
        }
    }
    if (const auto* images = array("images")) {
        for (size_t i = 0; i < images->size(); ++i) {
            const std::string what = "image " + std::to_string(i);
            const auto& im = (*images)[i];
            object(im, what);
            index_field(im, "bufferView", what, views.size(), "bufferViews");
            if (const auto u = im.find("uri"); u != im.end()) {
                if (!u->is_string()) fail(what + ": uri is not a string");
                const std::string uri = u->get<std::string>();
                if (uri.rfind("data:", 0) != 0) {
                    const std::string decoded = uri_decode(uri);
                    ctx->approved[join_path(base_dir, decoded)] =
                        resolve_reference(pol, decoded, what + " ('" + uri + "')").string();
                }
            } else if (!im.contains("bufferView")) {
                fail(what + " has neither a uri nor a bufferView");
            }
        }
    }
    if (const auto* accessors = array("accessors")) {
        for (size_t i = 0; i < accessors->size(); ++i) {
            const std::string what = "accessor " + std::to_string(i);
            const auto& a = (*accessors)[i];
            object(a, what);
            const uint64_t count = uint_field(a, "count", what, true, 0);
            if (count == 0) fail(what + ": count is 0");
            uint_field(a, "byteOffset", what, false, 0);
            index_field(a, "bufferView", what, views.size(), "bufferViews");
        }
    }
    // The object arrays tinygltf walks: each must be an array of objects.
    for (const char* key : {"nodes", "meshes", "materials", "textures", "samplers", "cameras", "skins", "animations"}) {
        if (const auto* arr = array(key))
            for (size_t i = 0; i < arr->size(); ++i) object((*arr)[i], std::string(key) + "[" + std::to_string(i) + "]");
    }
    if (scenes)
        for (size_t i = 0; i < scenes->size(); ++i) object((*scenes)[i], "scene " + std::to_string(i));

    // Every index into another array: tinygltf silently drops a primitive whose attribute is
    // not an integer, ignores non-integer indices and truncates large ones to int.
    auto count_of = [&](const char* key) -> size_t {
        const auto it = j.find(key);
        return it != j.end() && it->is_array() ? it->size() : 0;
    };
    const size_t n_accessors = count_of("accessors"), n_images = count_of("images"), n_samplers = count_of("samplers"),
                 n_textures = count_of("textures"), n_materials = count_of("materials"), n_meshes = count_of("meshes"),
                 n_nodes = count_of("nodes"), n_cameras = count_of("cameras"), n_skins = count_of("skins");
    auto index_list = [&](const nlohmann::json& o, const char* key, const std::string& what, size_t count,
                          const char* target) {
        const auto it = o.find(key);
        if (it == o.end()) return;
        if (!it->is_array()) fail(what + ": " + key + " is not an array");
        for (size_t k = 0; k < it->size(); ++k) {
            const nlohmann::json wrapper{{key, (*it)[k]}};
            index_field(wrapper, key, what + " " + key + "[" + std::to_string(k) + "]", count, target);
        }
    };
    auto sub_object = [&](const nlohmann::json& o, const char* key, const std::string& what) -> const nlohmann::json* {
        const auto it = o.find(key);
        if (it == o.end()) return nullptr;
        object(*it, what + ": " + key);
        return &*it;
    };
    auto small_int = [&](const nlohmann::json& o, const char* key, const std::string& what) {
        if (o.contains(key) && uint_field(o, key, what, false, 0) > 0x7FFFFFFF)
            fail(what + ": " + key + " " + excerpt(o[key]) + " is out of range");
    };
    if (n_textures)
        for (size_t i = 0; i < n_textures; ++i) {
            const auto& t = j["textures"][i];
            const std::string what = "texture " + std::to_string(i);
            index_field(t, "source", what, n_images, "images");
            index_field(t, "sampler", what, n_samplers, "samplers");
        }
    for (size_t i = 0; i < n_materials; ++i) {
        const auto& m = j["materials"][i];
        const std::string what = "material " + std::to_string(i);
        auto texture_info = [&](const nlohmann::json& parent, const char* key) {
            if (const auto* t = sub_object(parent, key, what)) {
                index_field(*t, "index", what + " " + key, n_textures, "textures");
                small_int(*t, "texCoord", what + " " + key);
            }
        };
        if (const auto* pbr = sub_object(m, "pbrMetallicRoughness", what)) {
            texture_info(*pbr, "baseColorTexture");
            texture_info(*pbr, "metallicRoughnessTexture");
        }
        for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) texture_info(m, key);
    }
    for (size_t i = 0; i < n_meshes; ++i) {
        const auto& mesh = j["meshes"][i];
        const auto prims = mesh.find("primitives");
        if (prims == mesh.end()) continue;
        if (!prims->is_array()) fail("mesh " + std::to_string(i) + ": primitives is not an array");
        for (size_t p = 0; p < prims->size(); ++p) {
            const std::string what = "mesh " + std::to_string(i) + " primitive " + std::to_string(p);
            const auto& prim = (*prims)[p];
            object(prim, what);
            if (const auto* attrs = sub_object(prim, "attributes", what))
                for (const auto& [name, value] : attrs->items())
                    index_field(nlohmann::json{{"accessor", value}}, "accessor", what + " attribute " + name, n_accessors,
                                "accessors");
            index_field(prim, "indices", what, n_accessors, "accessors");
            index_field(prim, "material", what, n_materials, "materials");
            small_int(prim, "mode", what);
            if (const auto it = prim.find("targets"); it != prim.end()) {
                if (!it->is_array()) fail(what + ": targets is not an array");
                for (size_t t = 0; t < it->size(); ++t) {
                    object((*it)[t], what + " target " + std::to_string(t));
                    for (const auto& [name, value] : (*it)[t].items())
                        index_field(nlohmann::json{{"accessor", value}}, "accessor",
                                    what + " target " + std::to_string(t) + " " + name, n_accessors, "accessors");
                }
            }
        }
    }
    size_t n_lights = 0;
    if (const auto ext = j.find("extensions"); ext != j.end() && ext->is_object())
        if (const auto lp = ext->find("KHR_lights_punctual"); lp != ext->end() && lp->is_object())
            if (const auto lights = lp->find("lights"); lights != lp->end()) {
                if (!lights->is_array()) fail("KHR_lights_punctual.lights is not an array");
                n_lights = lights->size();
                for (size_t i = 0; i < n_lights; ++i) object((*lights)[i], "light " + std::to_string(i));
            }
    for (size_t i = 0; i < n_nodes; ++i) {
        const auto& n = j["nodes"][i];
        const std::string what = "node " + std::to_string(i);
        index_field(n, "mesh", what, n_meshes, "meshes");
        index_field(n, "camera", what, n_cameras, "cameras");
        index_field(n, "skin", what, n_skins, "skins");
        index_list(n, "children", what, n_nodes, "nodes");
        if (const auto* ext = sub_object(n, "extensions", what))
            if (const auto* lp = sub_object(*ext, "KHR_lights_punctual", what + " extensions"))
                index_field(*lp, "light", what + " KHR_lights_punctual", n_lights, "lights");
    }
    if (scenes)
        for (size_t i = 0; i < scenes->size(); ++i) index_list((*scenes)[i], "nodes", "scene " + std::to_string(i), n_nodes, "nodes");
    // Animations: tinygltf reads indices here as int without a range check and skips a target
    // that is not an object; each index and field is checked against what it names.
    const size_t n_animations = count_of("animations");
    for (size_t i = 0; i < n_animations; ++i) {
        const auto& anim = j["animations"][i];
        const std::string what = "animation " + std::to_string(i);
        size_t n_samplers_here = 0;
        if (const auto it = anim.find("samplers"); it != anim.end()) {
            if (!it->is_array()) fail(what + ": samplers is not an array");
            n_samplers_here = it->size();
            for (size_t k = 0; k < n_samplers_here; ++k) {
                const auto& smp = (*it)[k];
                const std::string sw = what + " sampler " + std::to_string(k);
                object(smp, sw);
                for (const char* key : {"input", "output"}) {
                    if (!smp.contains(key)) fail(sw + ": '" + key + "' is missing");
                    index_field(smp, key, sw, n_accessors, "accessors");
                }
                if (const auto ip = smp.find("interpolation"); ip != smp.end() && !ip->is_string())
                    fail(sw + ": interpolation is not a string");
            }
        }
        if (const auto it = anim.find("channels"); it != anim.end()) {
            if (!it->is_array()) fail(what + ": channels is not an array");
            for (size_t k = 0; k < it->size(); ++k) {
                const auto& ch = (*it)[k];
                const std::string cw = what + " channel " + std::to_string(k);
                object(ch, cw);
                if (!ch.contains("sampler")) fail(cw + ": 'sampler' is missing");
                index_field(ch, "sampler", cw, n_samplers_here, "samplers in the animation");
                const auto* target = sub_object(ch, "target", cw);
                if (!target) fail(cw + ": 'target' is missing");
                index_field(*target, "node", cw + " target", n_nodes, "nodes");
                const auto p = target->find("path");
                if (p == target->end() || !p->is_string()) fail(cw + ": target.path is missing or not a string");
            }
        }
    }
    for (size_t i = 0; i < n_skins; ++i) {
        const auto& sk = j["skins"][i];
        const std::string what = "skin " + std::to_string(i);
        index_list(sk, "joints", what, n_nodes, "nodes");
        index_field(sk, "skeleton", what, n_nodes, "nodes");
        index_field(sk, "inverseBindMatrices", what, n_accessors, "accessors");
    }
}

}  // namespace ssr::gltf_detail
