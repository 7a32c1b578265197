// Reading glTF into a Scene: tinygltf parses what the checks (gltf_checks.cpp) let through;
// every value is checked again where it is used.

#include "scene/gltf_io.h"

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
#include <glm/gtc/vec1.hpp>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string_view>

#include "core/errors.h"
#include "scene/animation.h"
#include "scene/image_io.h"
#include "scene/scene_limits.h"

#include "scene/gltf_internal.h"

namespace fs = std::filesystem;

namespace ssr {

using namespace gltf_detail;

namespace {

// Decodes every image through OpenImageIO rather than tinygltf's stb_image.
bool decode_with_oiio(tinygltf::Image* image, const int index, std::string* err, std::string* /*warn*/,
                      int, int, const unsigned char* bytes, int size, void*) {
    try {
        std::string hint = image->mimeType;
        if (hint.empty() && !image->uri.empty()) hint = fs::path(image->uri).extension().string();
        const std::string what =
            "image " + std::to_string(index) + (image->uri.empty() ? "" : " ('" + image->uri + "')");
        if (size <= 0) throw SceneError(what + ": image data is empty");
        Image img = decode_image_memory(bytes, size_t(size), hint, what);
        image->width = img.width;
        image->height = img.height;
        image->component = 4;
        image->bits = 8;
        image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
        image->image = std::move(img.rgba);
        return true;
    } catch (const std::exception& e) {
        if (err) *err += std::string(e.what()) + "\n";
        return false;
    }
}

class GltfReader {
public:
    GltfReader(const tinygltf::Model& m, std::string file) : model_(m), file_(std::move(file)) {}

    [[noreturn]] void fail(const std::string& what) const { throw SceneError(file_ + ": " + what); }

    // Reads accessor `index` as `N` floats per element (normalised integers are mapped to
    // [0,1] / [-1,1] as glTF specifies).
    template <int N>
    std::vector<glm::vec<N, float>> read_floats(int index, const std::string& what) const {
        const auto& acc = accessor(index, what);
        if (acc.sparse.isSparse) fail(what + ": sparse accessor " + std::to_string(index) + " is not supported");
        const int comps = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        if (comps != N)
            fail(what + ": accessor " + std::to_string(index) + " has " + std::to_string(comps) +
                 " components, expected " + std::to_string(N));
        switch (acc.componentType) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: case TINYGLTF_COMPONENT_TYPE_BYTE:
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: case TINYGLTF_COMPONENT_TYPE_SHORT:
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: break;
            default: fail(what + ": accessor " + std::to_string(index) + " has component type " +
                          std::to_string(acc.componentType) + ", not one glTF allows for vertex attributes");
        }
        const auto [data, stride, elem] = view(acc, index, what);
        std::vector<glm::vec<N, float>> out(acc.count);
        for (size_t i = 0; i < acc.count; ++i) {
            const uint8_t* p = data + i * stride;
            for (int c = 0; c < N; ++c) out[i][c] = component_as_float(p, acc.componentType, c, acc.normalized);
        }
        for (const auto& v : out)
            for (int c = 0; c < N; ++c)
                if (!std::isfinite(v[c])) fail(what + ": accessor " + std::to_string(index) + " contains NaN or Inf");
        return out;
    }

    std::vector<uint32_t> read_indices(int index, const std::string& what) const {
        const auto& acc = accessor(index, what);
        if (acc.sparse.isSparse) fail(what + ": sparse accessor " + std::to_string(index) + " is not supported");
        if (acc.type != TINYGLTF_TYPE_SCALAR) fail(what + ": index accessor " + std::to_string(index) + " is not SCALAR");
        if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(what + ": index accessor " + std::to_string(index) + " has component type " +
                 std::to_string(acc.componentType) + "; indices must be unsigned byte, short or int");
        const auto [data, stride, elem] = view(acc, index, what);
        std::vector<uint32_t> out(acc.count);
        for (size_t i = 0; i < acc.count; ++i) {
            const uint8_t* p = data + i * stride;
            switch (acc.componentType) {
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out[i] = *p; break;
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); out[i] = v; break; }
                default: { uint32_t v; std::memcpy(&v, p, 4); out[i] = v; break; }
            }
        }
        return out;
    }

    // COLOR_0 as RGBA (an RGB accessor gets alpha 1): float, or normalised unsigned byte or short,
    // as glTF allows for it.
    std::vector<glm::vec4> read_colors(int index, const std::string& what) const {
        const auto& acc = accessor(index, what);
        const bool normalized_int = acc.normalized && (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                                       acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        if (acc.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !normalized_int)
            fail(what + ": accessor " + std::to_string(index) +
                 " must be float or normalized unsigned byte or short (glTF COLOR_n)");
        if (acc.type == TINYGLTF_TYPE_VEC4) return read_floats<4>(index, what);
        if (acc.type != TINYGLTF_TYPE_VEC3) fail(what + ": accessor " + std::to_string(index) + " must be VEC3 or VEC4");
        std::vector<glm::vec4> out;
        for (const auto& c : read_floats<3>(index, what)) out.emplace_back(c, 1.0f);
        return out;
    }

    const tinygltf::Accessor& accessor(int index, const std::string& what) const {
        if (index < 0 || index >= int(model_.accessors.size()))
            fail(what + ": accessor index " + std::to_string(index) + " is out of range (the file has " +
                 std::to_string(model_.accessors.size()) + " accessors)");
        return model_.accessors[size_t(index)];
    }

private:
    struct View {
        const uint8_t* data;
        size_t stride;
        size_t elem;
    };

    // The accessor's bytes inside its bufferView inside its buffer. Every sum and product is
    // overflow-checked: offsets near 2^64 must not wrap into a small, in-bounds-looking value.
    View view(const tinygltf::Accessor& acc, int index, const std::string& what) const {
        const std::string a = what + ": accessor " + std::to_string(index);
        if (acc.bufferView < 0)
            fail(a + " has no bufferView (accessors without data are not supported)");
        if (acc.bufferView >= int(model_.bufferViews.size()))
            fail(a + " refers to bufferView " + std::to_string(acc.bufferView) + ", out of range (the file has " +
                 std::to_string(model_.bufferViews.size()) + ")");
        const auto& bv = model_.bufferViews[size_t(acc.bufferView)];
        const std::string v = "bufferView " + std::to_string(acc.bufferView);
        if (bv.buffer < 0 || bv.buffer >= int(model_.buffers.size()))
            fail(a + ": " + v + " refers to buffer " + std::to_string(bv.buffer) + ", out of range");
        const auto& buf = model_.buffers[size_t(bv.buffer)];
        const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
        const int comps = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        if (comp_size <= 0 || comps <= 0) fail(a + " has an invalid component type or element type");
        if (acc.count == 0) fail(a + " has count 0");
        const uint64_t elem = uint64_t(comp_size) * uint64_t(comps);
        const uint64_t stride = bv.byteStride ? uint64_t(bv.byteStride) : elem;
        if (stride < elem)
            fail(a + ": " + v + "'s byteStride " + std::to_string(stride) + " is smaller than an element (" +
                 std::to_string(elem) + " bytes)");
        uint64_t view_end = 0, span = 0, acc_end = 0, begin = 0;
        if (!checked_add(bv.byteOffset, bv.byteLength, &view_end) || view_end > buf.data.size())
            fail(v + ": byteOffset " + std::to_string(bv.byteOffset) + " + byteLength " + std::to_string(bv.byteLength) +
                 " lies outside buffer " + std::to_string(bv.buffer) + " (" + std::to_string(buf.data.size()) + " bytes)");
        if (!checked_mul(stride, uint64_t(acc.count) - 1, &span) || !checked_add(span, elem, &span) ||
            !checked_add(acc.byteOffset, span, &acc_end) || acc_end > bv.byteLength)
            fail(a + ": byteOffset " + std::to_string(acc.byteOffset) + " and count " + std::to_string(acc.count) +
                 " read past the end of " + v + " (" + std::to_string(bv.byteLength) + " bytes)");
        checked_add(bv.byteOffset, acc.byteOffset, &begin);  // < view_end, cannot overflow
        return View{buf.data.data() + begin, size_t(stride), size_t(elem)};
    }

    static float component_as_float(const uint8_t* p, int type, int c, bool normalized) {
        switch (type) {
            case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p + 4 * c, 4); return v; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { float v = p[c]; return normalized ? v / 255.0f : v; }
            case TINYGLTF_COMPONENT_TYPE_BYTE: { float v = float(int8_t(p[c])); return normalized ? std::max(v / 127.0f, -1.0f) : v; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t u; std::memcpy(&u, p + 2 * c, 2); return normalized ? u / 65535.0f : float(u); }
            case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t s; std::memcpy(&s, p + 2 * c, 2); return normalized ? std::max(s / 32767.0f, -1.0f) : float(s); }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t u; std::memcpy(&u, p + 4 * c, 4); return float(u); }
            default: return 0.0f;
        }
    }

    const tinygltf::Model& model_;
    std::string file_;
};

// Number checks: `v` converted to float is finite and inside [lo, hi].
bool in_range(double v, double lo, double hi) {
    return std::isfinite(v) && std::isfinite(float(v)) && v >= lo && v <= hi;
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

void check_finite_list(const GltfReader& r, const std::vector<double>& v, const std::string& what) {
    for (double x : v)
        if (!in_range(x, -3.0e38, 3.0e38)) r.fail(what + " holds " + num(x) + ", not a finite float");
}

// A node's local transform as the file gives it: a matrix, or translation, rotation (normalised)
// and scale; NodeTransform::local() composes it.
NodeTransform node_local_transform(const tinygltf::Node& n, const GltfReader& r, const std::string& what) {
    NodeTransform out;
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16) r.fail(what + ": matrix has " + std::to_string(n.matrix.size()) + " values, not 16");
        check_finite_list(r, n.matrix, what + ": matrix");
        glm::mat4 m;
        for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(n.matrix[size_t(i)]);  // column-major
        if (const std::string p = affine_problem(m); !p.empty()) r.fail(what + ": matrix " + p);
        out.has_matrix = true;
        out.matrix = m;
        return out;
    }
    if (!n.translation.empty()) {
        if (n.translation.size() != 3) r.fail(what + ": translation does not have 3 values");
        check_finite_list(r, n.translation, what + ": translation");
        out.translation = glm::vec3(n.translation[0], n.translation[1], n.translation[2]);
    }
    if (!n.rotation.empty()) {  // glTF stores (x, y, z, w)
        if (n.rotation.size() != 4) r.fail(what + ": rotation does not have 4 values");
        check_finite_list(r, n.rotation, what + ": rotation");
        const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
        const double len = glm::length(q);
        if (!(len > 1e-6) || !std::isfinite(len)) r.fail(what + ": rotation quaternion has (near) zero length");
        out.rotation = glm::normalize(q);
    }
    if (!n.scale.empty()) {
        if (n.scale.size() != 3) r.fail(what + ": scale does not have 3 values");
        check_finite_list(r, n.scale, what + ": scale");
        out.scale = glm::vec3(n.scale[0], n.scale[1], n.scale[2]);
    }
    return out;
}

bool finite_matrix(const glm::mat4& m) {
    for (int i = 0; i < 16; ++i)
        if (!std::isfinite(glm::value_ptr(m)[i])) return false;
    return true;
}

// Turns strips and fans into a triangle list.
std::vector<uint32_t> to_triangle_list(const std::vector<uint32_t>& idx, int mode) {
    if (mode == kModeTriangles) return idx;
    std::vector<uint32_t> out;
    for (size_t i = 2; i < idx.size(); ++i) {
        if (mode == kModeStrip) {
            if (i % 2 == 0) out.insert(out.end(), {idx[i - 2], idx[i - 1], idx[i]});
            else out.insert(out.end(), {idx[i - 1], idx[i - 2], idx[i]});
        } else {  // fan
            out.insert(out.end(), {idx[0], idx[i - 1], idx[i]});
        }
    }
    return out;
}

double number_from_value(const tinygltf::Value& v, const GltfReader& r, const std::string& what, double lo, double hi);

TextureRef texture_ref(const tinygltf::Model& model, int texture_index, int texcoord, int image_base,
                       const GltfReader& r, const std::string& what, const tinygltf::ExtensionMap& extensions = {}) {
    TextureRef ref;
    if (texture_index < 0) return ref;
    // KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, as its specification
    // writes the matrices (rotation counter-clockwise in uv space), and an optional texCoord.
    if (auto it = extensions.find("KHR_texture_transform"); it != extensions.end()) {
        const std::string ext = what + ": KHR_texture_transform";
        const tinygltf::Value& v = it->second;
        glm::vec2 offset(0.0f), scale(1.0f);
        float rotation = 0.0f;
        auto vec2_of = [&](const char* key, glm::vec2 fallback) {
            if (!v.Has(key)) return fallback;
            const tinygltf::Value& a = v.Get(key);
            if (!a.IsArray() || a.ArrayLen() != 2) r.fail(ext + "." + key + " must be an array of 2 numbers");
            glm::vec2 out;
            for (int i = 0; i < 2; ++i) {
                const tinygltf::Value& x = a.Get(i);
                if (!x.IsNumber() && !x.IsInt()) r.fail(ext + "." + key + " must be an array of 2 numbers");
                const double d = x.GetNumberAsDouble();
                if (!in_range(d, -1e6, 1e6)) r.fail(ext + "." + key + " holds " + num(d) + ", outside [-1e6, 1e6]");
                out[i] = float(d);
            }
            return out;
        };
        offset = vec2_of("offset", offset);
        scale = vec2_of("scale", scale);
        if (v.Has("rotation")) rotation = float(number_from_value(v.Get("rotation"), r, ext + ".rotation", -1e6, 1e6));
        if (v.Has("texCoord")) texcoord = int(number_from_value(v.Get("texCoord"), r, ext + ".texCoord", 0, 7));
        const float c = std::cos(rotation), s = std::sin(rotation);
        ref.transform_u = glm::vec3(c * scale.x, s * scale.y, offset.x);
        ref.transform_v = glm::vec3(-s * scale.x, c * scale.y, offset.y);
    }
    if (texture_index >= int(model.textures.size()))
        r.fail(what + ": texture index " + std::to_string(texture_index) + " is out of range (the file has " +
               std::to_string(model.textures.size()) + " textures)");
    if (texcoord < 0 || texcoord > 7) r.fail(what + ": texCoord " + std::to_string(texcoord) + " is not a valid set");
    const auto& tex = model.textures[size_t(texture_index)];
    if (tex.source < 0 || tex.source >= int(model.images.size()))
        r.fail("texture " + std::to_string(texture_index) + ": image index " + std::to_string(tex.source) +
               " is out of range (the file has " + std::to_string(model.images.size()) + " images)");
    ref.image = image_base + tex.source;
    ref.texcoord = texcoord;
    if (tex.sampler >= int(model.samplers.size()) || tex.sampler < -1)
        r.fail("texture " + std::to_string(texture_index) + ": sampler index " + std::to_string(tex.sampler) +
               " is out of range (the file has " + std::to_string(model.samplers.size()) + " samplers)");
    if (tex.sampler >= 0) {
        ref.wrap_s = model.samplers[size_t(tex.sampler)].wrapS;
        ref.wrap_t = model.samplers[size_t(tex.sampler)].wrapT;
    }
    return ref;
}

glm::vec3 vec3_from(const std::vector<double>& v, glm::vec3 fallback) {
    return v.size() >= 3 ? glm::vec3(float(v[0]), float(v[1]), float(v[2])) : fallback;
}

// An [x, y, z] array of numbers in [lo, hi] from the file's extras.
glm::vec3 vec3_from_value(const tinygltf::Value& v, glm::vec3 fallback, const GltfReader& r, const std::string& what,
                          double lo = -1e30, double hi = 1e30) {
    if (v.Type() == tinygltf::NULL_TYPE) return fallback;
    if (!v.IsArray() || v.ArrayLen() != 3) r.fail(what + " must be an array of 3 numbers");
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) {
        const auto& x = v.Get(i);
        if (!x.IsNumber() && !x.IsInt()) r.fail(what + " must be an array of 3 numbers");
        const double d = x.GetNumberAsDouble();
        if (!in_range(d, lo, hi)) r.fail(what + " holds " + num(d) + ", outside [" + num(lo) + ", " + num(hi) + "]");
        out[i] = float(d);
    }
    return out;
}

double number_from_value(const tinygltf::Value& v, const GltfReader& r, const std::string& what, double lo, double hi) {
    if (!v.IsNumber() && !v.IsInt()) r.fail(what + " must be a number");
    const double d = v.GetNumberAsDouble();
    if (!in_range(d, lo, hi)) r.fail(what + " is " + num(d) + ", outside [" + num(lo) + ", " + num(hi) + "]");
    return d;
}

std::string string_from_value(const tinygltf::Value& v, const GltfReader& r, const std::string& what) {
    if (!v.IsString()) r.fail(what + " must be a string");
    return v.Get<std::string>();
}

// The numbers of every sampler, camera, light and material, each checked against glTF's
// ranges (and the lighting buffers' capacity) before anything is built from them.
void check_model_values(const tinygltf::Model& model, const GltfReader& r, std::vector<std::string>& warnings,
                        const std::string& file) {
    static const std::set<int> wraps{10497, 33071, 33648};
    static const std::set<int> mag_filters{-1, 9728, 9729};
    static const std::set<int> min_filters{-1, 9728, 9729, 9984, 9985, 9986, 9987};
    for (size_t i = 0; i < model.samplers.size(); ++i) {
        const auto& s = model.samplers[i];
        const std::string what = "sampler " + std::to_string(i);
        if (!wraps.count(s.wrapS)) r.fail(what + ": wrapS " + std::to_string(s.wrapS) + " is not a glTF wrap mode (33071, 33648, 10497)");
        if (!wraps.count(s.wrapT)) r.fail(what + ": wrapT " + std::to_string(s.wrapT) + " is not a glTF wrap mode (33071, 33648, 10497)");
        if (!mag_filters.count(s.magFilter)) r.fail(what + ": magFilter " + std::to_string(s.magFilter) + " is not a glTF filter");
        if (!min_filters.count(s.minFilter)) r.fail(what + ": minFilter " + std::to_string(s.minFilter) + " is not a glTF filter");
    }
    for (size_t i = 0; i < model.cameras.size(); ++i) {
        const auto& c = model.cameras[i];
        const std::string what = "camera " + std::to_string(i);
        if (c.type == "perspective") {
            const auto& p = c.perspective;
            if (!in_range(p.yfov, 1e-6, 3.14159)) r.fail(what + ": yfov " + num(p.yfov) + " is not an angle in (0, pi) radians");
            if (!in_range(p.znear, 1e-30, 1e30) || !(float(p.znear) > 0.0f)) r.fail(what + ": znear " + num(p.znear) + " must be finite and > 0");
            if (p.zfar != 0.0 && (!in_range(p.zfar, 0.0, 1e30) || !(float(p.zfar) > float(p.znear))))
                r.fail(what + ": zfar " + num(p.zfar) + " must be finite and greater than znear " + num(p.znear));
            if (!in_range(p.aspectRatio, 0.0, 1e6)) r.fail(what + ": aspectRatio " + num(p.aspectRatio) + " must be finite and >= 0");
        } else if (c.type == "orthographic") {
            warnings.push_back(file + ": " + what + " is orthographic; only perspective cameras are used, it was skipped");
        } else {
            r.fail(what + ": type '" + c.type + "' is neither perspective nor orthographic");
        }
    }
    for (size_t i = 0; i < model.lights.size(); ++i) {
        const auto& l = model.lights[i];
        const std::string what = "light " + std::to_string(i) + " ('" + l.name + "')";
        if (l.type != "directional" && l.type != "point" && l.type != "spot")
            r.fail(what + ": type '" + l.type + "' is not directional, point or spot");
        if (!l.color.empty() && l.color.size() != 3) r.fail(what + ": color does not have 3 values");
        double peak = 1.0;
        if (!l.color.empty()) {
            peak = 0.0;
            for (double x : l.color) {
                if (!in_range(x, 0.0, kMaxLightPower)) r.fail(what + ": color holds " + num(x) + ", outside [0, " + num(kMaxLightPower) + "]");
                peak = std::max(peak, x);
            }
        }
        if (!in_range(l.intensity, 0.0, kMaxLightPower))
            r.fail(what + ": intensity " + num(l.intensity) + " is outside [0, " + num(kMaxLightPower) + "]");
        if (peak * l.intensity > kMaxLightPower)
            r.fail(what + ": color x intensity " + num(peak * l.intensity) + " is more than " + num(kMaxLightPower) +
                   " (the half-float lighting buffers would overflow)");
        if (l.range != 0.0 && !in_range(l.range, 1e-30, 1e30)) r.fail(what + ": range " + num(l.range) + " must be finite and > 0");
        if (l.type == "spot") {
            if (!in_range(l.spot.innerConeAngle, 0.0, 1.5708) || !in_range(l.spot.outerConeAngle, 1e-6, 1.5708) ||
                !(l.spot.innerConeAngle < l.spot.outerConeAngle))
                r.fail(what + ": spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
        }
    }
    for (size_t i = 0; i < model.materials.size(); ++i) {
        const auto& m = model.materials[i];
        const std::string what = "material " + std::to_string(i) + " ('" + m.name + "')";
        const auto& pbr = m.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4) r.fail(what + ": baseColorFactor does not have 4 values");
        for (double x : pbr.baseColorFactor)
            if (!in_range(x, 0.0, 1.0)) r.fail(what + ": baseColorFactor holds " + num(x) + ", outside [0, 1]");
        if (!in_range(pbr.metallicFactor, 0.0, 1.0)) r.fail(what + ": metallicFactor " + num(pbr.metallicFactor) + " is outside [0, 1]");
        if (!in_range(pbr.roughnessFactor, 0.0, 1.0)) r.fail(what + ": roughnessFactor " + num(pbr.roughnessFactor) + " is outside [0, 1]");
        if (!m.emissiveFactor.empty() && m.emissiveFactor.size() != 3) r.fail(what + ": emissiveFactor does not have 3 values");
        for (double x : m.emissiveFactor)
            if (!in_range(x, 0.0, 1.0)) r.fail(what + ": emissiveFactor holds " + num(x) + ", outside [0, 1]");
        if (!in_range(m.normalTexture.scale, -1e3, 1e3)) r.fail(what + ": normalTexture.scale " + num(m.normalTexture.scale) + " is not finite");
        if (!in_range(m.alphaCutoff, 0.0, 1e30)) r.fail(what + ": alphaCutoff " + num(m.alphaCutoff) + " must be finite and >= 0");
        if (m.extras.Has("reflectivity"))
            number_from_value(m.extras.Get("reflectivity"), r, what + ": extras.reflectivity", 0.0, 1.0);
    }
}

bool within_world(const glm::vec3& p) { return world_point_problem(p).empty(); }

// Whether an object's transform can be drawn (scene_limits.h): a zero scale or axes scaled
// far apart make its normals NaN or zero-length.
bool invertible_transform(const glm::mat4& m) { return transform_problem(m).empty(); }

// A checked vec3 direction: finite and of non-zero length.
bool usable_direction(const glm::vec3& v) {
    const float len = glm::length(v);
    return std::isfinite(len) && len > 1e-20f && std::isfinite(1.0f / len);
}

// The pose ssrlab saved an animated node in (extras.ssrlab.pose: translation, rotation, scale,
// written exactly; the node's own fields are its rest pose, what other viewers animate from).
NodeTransform saved_pose(const tinygltf::Value& x, const NodeTransform& rest, const GltfReader& r, const std::string& what) {
    const std::string w = what + ": extras.ssrlab";
    if (!x.IsObject()) r.fail(w + " is not an object");
    if (!x.Has("pose")) return rest;
    const tinygltf::Value& p = x.Get("pose");
    const std::string pw = w + ".pose";
    if (!p.IsObject()) r.fail(pw + " is not an object");
    if (rest.has_matrix) r.fail(pw + ": the node is given by a matrix, which has no pose");
    NodeTransform out = rest;
    auto numbers = [&](const char* key, size_t n) {
        std::vector<double> v;
        const tinygltf::Value& a = p.Get(key);
        if (!a.IsArray() || a.ArrayLen() != n) r.fail(pw + "." + key + " must be an array of " + std::to_string(n) + " numbers");
        for (size_t i = 0; i < n; ++i) {
            const tinygltf::Value& e = a.Get(int(i));
            if (!e.IsNumber() && !e.IsInt()) r.fail(pw + "." + key + " must be an array of " + std::to_string(n) + " numbers");
            const double d = e.GetNumberAsDouble();
            if (!in_range(d, -3.0e38, 3.0e38)) r.fail(pw + "." + key + " holds " + num(d) + ", not a finite float");
            v.push_back(d);
        }
        return v;
    };
    if (p.Has("translation")) {
        const auto v = numbers("translation", 3);
        out.translation = glm::vec3(v[0], v[1], v[2]);
    }
    if (p.Has("rotation")) {  // as saved: already unit, not normalised again
        const auto v = numbers("rotation", 4);
        out.rotation = glm::dquat(v[3], v[0], v[1], v[2]);
        if (!(std::abs(glm::length(out.rotation) - 1.0) < 1e-3)) r.fail(pw + ".rotation is not a unit quaternion");
    }
    if (p.Has("scale")) {
        const auto v = numbers("scale", 3);
        out.scale = glm::vec3(v[0], v[1], v[2]);
    }
    return out;
}

// The file's animations, their channels on the nodes of the default scene (scene_node: the
// Scene::nodes index of each file node, -1 for nodes outside it). Every index, accessor and
// keyframe is checked; a message names the animation, the channel, its node and path.
void read_animations(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const std::vector<int>& scene_node,
                     const std::string& path, std::vector<std::string>& warnings) {
    for (size_t a = 0; a < model.animations.size(); ++a) {
        const auto& ga = model.animations[a];
        Animation anim;
        anim.name = ga.name.empty() ? "animation" + std::to_string(a) : ga.name;
        anim.source = path;
        const std::string aw = "animation " + std::to_string(a) + (ga.name.empty() ? "" : " ('" + ga.name + "')");
        std::set<std::pair<int, int>> seen;
        int weights = 0, outside = 0;
        std::set<std::string> other_paths;
        for (size_t c = 0; c < ga.channels.size(); ++c) {
            const auto& ch = ga.channels[c];
            const std::string cw = aw + " channel " + std::to_string(c);
            if (ch.sampler < 0 || ch.sampler >= int(ga.samplers.size()))
                r.fail(cw + ": sampler " + std::to_string(ch.sampler) + " is out of range (the animation has " +
                       std::to_string(ga.samplers.size()) + " samplers)");
            if (ch.target_node < 0) continue;  // a target without a node (extensions): nothing here to move
            if (ch.target_node >= int(model.nodes.size()))
                r.fail(cw + ": target node " + std::to_string(ch.target_node) + " is out of range (the file has " +
                       std::to_string(model.nodes.size()) + " nodes)");
            const auto& gn = model.nodes[size_t(ch.target_node)];
            const std::string nw = cw + " (node " + std::to_string(ch.target_node) +
                                   (gn.name.empty() ? "" : " '" + gn.name + "'") + ", " + ch.target_path + ")";
            AnimationChannel out;
            if (ch.target_path == "translation") out.path = AnimationChannel::Path::Translation;
            else if (ch.target_path == "rotation") out.path = AnimationChannel::Path::Rotation;
            else if (ch.target_path == "scale") out.path = AnimationChannel::Path::Scale;
            else {
                if (ch.target_path == "weights") ++weights;
                else other_paths.insert(ch.target_path);
                continue;
            }
            if (!gn.matrix.empty())
                r.fail(nw + ": the node is given by a matrix, and glTF animates only nodes given by translation, "
                            "rotation and scale");
            if (!seen.insert({ch.target_node, int(out.path)}).second)
                r.fail(nw + ": a second channel for the same node and path (glTF allows one per animation)");
            const auto& gs = ga.samplers[size_t(ch.sampler)];
            const std::string sw = nw + ": sampler " + std::to_string(ch.sampler);
            AnimationSampler& s = out.sampler;
            if (gs.interpolation == "LINEAR" || gs.interpolation.empty()) s.interpolation = AnimationSampler::Interpolation::Linear;
            else if (gs.interpolation == "STEP") s.interpolation = AnimationSampler::Interpolation::Step;
            else if (gs.interpolation == "CUBICSPLINE") s.interpolation = AnimationSampler::Interpolation::CubicSpline;
            else r.fail(sw + ": interpolation '" + gs.interpolation + "' is not LINEAR, STEP or CUBICSPLINE");
            s.components = out.path == AnimationChannel::Path::Rotation ? 4 : 3;
            // Times are float scalars; translation and scale float vectors; rotations float or
            // normalised integers (glTF 2.0, animation samplers).
            const auto& in = r.accessor(gs.input, sw + " input");
            if (in.type != TINYGLTF_TYPE_SCALAR || in.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
                r.fail(sw + ": input accessor " + std::to_string(gs.input) + " must hold float scalars (keyframe times)");
            for (const auto& t : r.read_floats<1>(gs.input, sw + " input")) s.times.push_back(t.x);
            const auto& o = r.accessor(gs.output, sw + " output");
            const bool float_values = o.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
            const bool normalized = o.normalized && (o.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                                                     o.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                                     o.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
                                                     o.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
            if (s.components == 3 && (o.type != TINYGLTF_TYPE_VEC3 || !float_values))
                r.fail(sw + ": output accessor " + std::to_string(gs.output) + " must hold float VEC3 values for " +
                       ch.target_path);
            if (s.components == 4 && (o.type != TINYGLTF_TYPE_VEC4 || !(float_values || normalized)))
                r.fail(sw + ": output accessor " + std::to_string(gs.output) +
                       " must hold VEC4 quaternions, float or normalized integers");
            if (s.components == 3)
                for (const auto& v : r.read_floats<3>(gs.output, sw + " output")) s.values.insert(s.values.end(), {v.x, v.y, v.z});
            else
                for (const auto& v : r.read_floats<4>(gs.output, sw + " output")) s.values.insert(s.values.end(), {v.x, v.y, v.z, v.w});
            if (const std::string p = check_sampler(s); !p.empty()) r.fail(sw + ": " + p);
            out.node = scene_node[size_t(ch.target_node)];
            if (out.node < 0) {
                ++outside;
                continue;
            }
            anim.duration = std::max(anim.duration, s.times.back());
            anim.channels.push_back(std::move(out));
        }
        if (weights)
            warnings.push_back(path + ": " + aw + ": " + std::to_string(weights) +
                               " channel(s) animate morph target weights, which are not rendered (ignored)");
        if (outside)
            warnings.push_back(path + ": " + aw + ": " + std::to_string(outside) +
                               " channel(s) move nodes outside the default scene (ignored)");
        if (!other_paths.empty()) {
            std::string names;
            for (const auto& p : other_paths) names += (names.empty() ? "'" : ", '") + p + "'";
            warnings.push_back(path + ": " + aw + ": channels with target path " + names + " are not rendered (ignored)");
        }
        scene.animations.push_back(std::move(anim));
    }
}

int load_gltf_checked(Scene& scene, const std::string& path, const glm::mat4& transform, const GltfLoadOptions& options,
                      std::vector<std::string>& warnings) {
    if (!fs::exists(path)) throw FileNotFound("glTF file not found: " + path);
    if (fs::is_directory(path)) throw SceneError(path + ": is a folder, not a glTF file");
    const std::vector<uint8_t> bytes = read_regular_file(path, path);

    PathPolicy pol;
    pol.file = path;
    pol.dir = fs::absolute(fs::path(path)).parent_path();
    std::error_code ec;
    pol.dir_real = fs::canonical(pol.dir, ec);
    if (ec) throw SceneError(path + ": cannot resolve the model's folder: " + ec.message());
    pol.allow_external = options.allow_external_files;
    const std::string base_dir = pol.dir.string();

    // GLB: a 12-byte header, a JSON chunk, an optional BIN chunk; every length checked in 64 bits.
    const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    std::string_view json_text;
    uint64_t glb_length = 0, glb_bin = 0;
    if (glb) {
        if (bytes.size() < 20) throw SceneError(path + ": GLB file is shorter than its 20-byte header");
        const uint32_t version = read_u32(bytes.data() + 4);
        if (version != 2) throw SceneError(path + ": GLB version " + std::to_string(version) + " is not 2");
        glb_length = read_u32(bytes.data() + 8);
        if (glb_length > bytes.size() || glb_length < 20)
            throw SceneError(path + ": GLB header says " + std::to_string(glb_length) + " bytes, the file has " +
                             std::to_string(bytes.size()));
        const uint64_t json_len = read_u32(bytes.data() + 12);
        if (read_u32(bytes.data() + 16) != 0x4E4F534Au) throw SceneError(path + ": GLB's first chunk is not JSON");
        if (20 + json_len > glb_length)
            throw SceneError(path + ": GLB JSON chunk (" + std::to_string(json_len) + " bytes) runs past the file's end");
        json_text = std::string_view(reinterpret_cast<const char*>(bytes.data()) + 20, size_t(json_len));
        const uint64_t bin_at = 20 + json_len;
        if (bin_at + 8 <= glb_length) {
            const uint64_t bin_len = read_u32(bytes.data() + bin_at);
            if (read_u32(bytes.data() + bin_at + 4) != 0x004E4942u)
                throw SceneError(path + ": GLB's second chunk is not BIN");
            if (bin_at + 8 + bin_len > glb_length)
                throw SceneError(path + ": GLB BIN chunk (" + std::to_string(bin_len) + " bytes) runs past the file's end");
            glb_bin = bin_len;
        }
    } else {
        if (fs::path(path).extension() == ".glb")
            throw SceneError(path + ": not a GLB file (it does not start with the magic 'glTF')");
        json_text = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    }
    if (const std::string problem = check_json_text(json_text); !problem.empty())
        throw SceneError(path + ": " + problem);
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(json_text.begin(), json_text.end());
    } catch (const nlohmann::json::exception& e) {
        throw SceneError(path + ": not valid JSON: " + e.what());
    }
    FsContext fsctx;
    precheck_json(j, pol, base_dir, glb, glb_bin, &fsctx);

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decode_with_oiio, nullptr);
    loader.SetFsCallbacks(tinygltf::FsCallbacks{fs_exists, fs_expand, fs_read, fs_write, &fsctx});
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(glb_length), base_dir)
                        : loader.LoadASCIIFromString(&model, &err, &warn, json_text.data(), unsigned(json_text.size()), base_dir);
    if (!ok) {
        std::string msg = err.empty() ? warn : err;
        while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
        throw SceneError(path + ": not a valid glTF 2.0 file: " + (msg.empty() ? "unknown error" : msg));
    }
    GltfReader r(model, path);
    check_model_values(model, r, warnings, path);

    if (!model.skins.empty())
        warnings.push_back(path + ": " + std::to_string(model.skins.size()) +
                           " skin(s) ignored: skinned meshes are drawn in their bind pose");
    {
        // Extensions the file uses that change what it looks like but ssrlab does not implement:
        // named together, so a user knows what the image leaves out (required ones failed above).
        std::string ignored;
        for (const std::string& name : model.extensionsUsed)
            if (!implemented_extensions().count(name)) ignored += (ignored.empty() ? "" : ", ") + name;
        if (!ignored.empty())
            warnings.push_back(path + ": extensions not rendered (ignored): " + ignored);
    }

    // Images: tinygltf keeps going when an external image is missing; we do not.
    const int image_base = int(scene.images.size());
    for (size_t i = 0; i < model.images.size(); ++i) {
        const auto& gi = model.images[i];
        if (gi.image.empty()) {
            std::string where = gi.uri.empty() ? "bufferView " + std::to_string(gi.bufferView) : "'" + gi.uri + "'";
            std::string detail = warn.empty() ? err : warn;
            while (!detail.empty() && (detail.back() == '\n' || detail.back() == ' ')) detail.pop_back();
            r.fail("image " + std::to_string(i) + " " + where + " could not be loaded" +
                   (detail.empty() ? "" : ": " + detail));
        }
        Image img;
        img.name = gi.name.empty() ? (gi.uri.empty() ? "image" + std::to_string(i) : fs::path(gi.uri).stem().string()) : gi.name;
        img.source = gi.uri.empty() ? path + "#image" + std::to_string(i) : (fs::path(path).parent_path() / gi.uri).string();
        img.width = gi.width;
        img.height = gi.height;
        img.rgba = gi.image;
        scene.images.push_back(std::move(img));
    }

    // Materials.
    const int material_base = int(scene.materials.size());
    std::string blended;  // the BLEND materials, named in one warning
    for (size_t i = 0; i < model.materials.size(); ++i) {
        const auto& gm = model.materials[i];
        const std::string what = "material " + std::to_string(i) + " ('" + gm.name + "')";
        Material m;
        m.name = gm.name.empty() ? "material" + std::to_string(i) : gm.name;
        const auto& pbr = gm.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() == 4)
            m.base_color = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2],
                                     pbr.baseColorFactor[3]);
        m.metallic = float(pbr.metallicFactor);
        m.roughness = float(pbr.roughnessFactor);
        m.emissive = vec3_from(gm.emissiveFactor, glm::vec3(0.0f));
        // KHR_materials_emissive_strength scales the [0, 1] factor; the product is what is
        // emitted, and it must stay within the half-float lighting buffers (scene_limits.h).
        if (auto it = gm.extensions.find("KHR_materials_emissive_strength");
            it != gm.extensions.end() && it->second.Has("emissiveStrength")) {
            const double strength = number_from_value(it->second.Get("emissiveStrength"), r,
                                                      what + ": KHR_materials_emissive_strength.emissiveStrength", 0.0, 1e30);
            m.emissive *= float(strength);
            if (const std::string p = radiance_problem(m.emissive, 1.0f); !p.empty())
                r.fail(what + ": emissiveFactor x emissiveStrength " + p);
        }
        // KHR_materials_ior and KHR_materials_specular: the dielectric F0 (Material::dielectric_f0).
        if (auto it = gm.extensions.find("KHR_materials_ior"); it != gm.extensions.end() && it->second.Has("ior")) {
            m.ior = float(number_from_value(it->second.Get("ior"), r, what + ": KHR_materials_ior.ior", 0.0, 1e6));
            if (m.ior > 0.0f && m.ior < 1.0f)
                r.fail(what + ": KHR_materials_ior.ior " + num(m.ior) + " must be 0 or at least 1");
        }
        if (auto it = gm.extensions.find("KHR_materials_specular"); it != gm.extensions.end()) {
            const std::string ext = what + ": KHR_materials_specular";
            if (it->second.Has("specularFactor"))
                m.specular = float(number_from_value(it->second.Get("specularFactor"), r, ext + ".specularFactor", 0.0, 1.0));
            if (it->second.Has("specularColorFactor"))
                m.specular_color = vec3_from_value(it->second.Get("specularColorFactor"), glm::vec3(1.0f), r,
                                                   ext + ".specularColorFactor", 0.0, 1e6);
            // Its textures (glTF textureInfo objects inside the extension): specularTexture's A
            // scales specularFactor, specularColorTexture's sRGB-decoded RGB specularColorFactor.
            auto info = [&](const char* key) {
                if (!it->second.Has(key)) return TextureRef{};
                const tinygltf::Value& v = it->second.Get(key);
                const std::string t = ext + "." + key;
                if (!v.IsObject() || !v.Has("index")) r.fail(t + " must be an object with an index");
                const int index = int(number_from_value(v.Get("index"), r, t + ".index", 0, 1e9));
                const int texcoord = v.Has("texCoord") ? int(number_from_value(v.Get("texCoord"), r, t + ".texCoord", 0, 7)) : 0;
                tinygltf::ExtensionMap extensions;
                if (v.Has("extensions") && v.Get("extensions").IsObject())
                    for (const auto& key_value : v.Get("extensions").Get<tinygltf::Value::Object>())
                        extensions.insert(key_value);
                return texture_ref(model, index, texcoord, image_base, r, t, extensions);
            };
            m.specular_texture = info("specularTexture");
            m.specular_color_texture = info("specularColorTexture");
        }
        m.double_sided = gm.doubleSided;
        if (gm.alphaMode == "MASK") {
            m.alpha_mode = Material::AlphaMode::Mask;
            m.alpha_cutoff = float(gm.alphaCutoff);
        } else if (gm.alphaMode == "BLEND") {
            m.alpha_mode = Material::AlphaMode::Blend;
            blended += (blended.empty() ? "" : ", ") + what;
        } else if (gm.alphaMode != "OPAQUE" && !gm.alphaMode.empty()) {
            r.fail(what + ": alphaMode '" + gm.alphaMode + "' is not OPAQUE, MASK or BLEND");
        }
        m.base_color_texture = texture_ref(model, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, image_base, r,
                                           what + ": baseColorTexture", pbr.baseColorTexture.extensions);
        m.metallic_roughness_texture =
            texture_ref(model, pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord, image_base, r,
                        what + ": metallicRoughnessTexture", pbr.metallicRoughnessTexture.extensions);
        m.normal_texture = texture_ref(model, gm.normalTexture.index, gm.normalTexture.texCoord, image_base, r,
                                       what + ": normalTexture", gm.normalTexture.extensions);
        m.normal_scale = float(gm.normalTexture.scale);
        // The emitted radiance is emissiveFactor x strength x this texture's (sRGB-decoded) texel.
        m.emissive_texture = texture_ref(model, gm.emissiveTexture.index, gm.emissiveTexture.texCoord, image_base, r,
                                         what + ": emissiveTexture", gm.emissiveTexture.extensions);
        // The thesis's explicit reflectivity where ssrlab wrote it; otherwise the material
        // reflects as its metallic-roughness parameters say (kAutoReflectivity).
        // TEXCOORD_0 and _1 are loaded; a texture on a later set samples set 0.
        for (TextureRef* t : {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture, &m.emissive_texture,
                              &m.specular_texture, &m.specular_color_texture})
            if (t->valid() && t->texcoord > 1) {
                warnings.push_back(path + ": " + what + ": texCoord " + std::to_string(t->texcoord) +
                                   " is not loaded (only TEXCOORD_0 and TEXCOORD_1); TEXCOORD_0 is used");
                t->texcoord = 0;
            }
        m.reflectivity = kAutoReflectivity;
        if (gm.extras.Has("reflectivity")) m.reflectivity = float(gm.extras.Get("reflectivity").GetNumberAsDouble());
        scene.materials.push_back(m);
    }
    if (!blended.empty())
        warnings.push_back(path + ": alphaMode BLEND drawn as MASK at alpha 0.5 (a hole below, opaque above; no "
                           "translucent layer): " + blended);
    int default_material = -1;  // glTF's default material, added only when a primitive needs it
    std::set<int> uv1_warned;   // materials named in a warning about a missing TEXCOORD_1

    // Meshes: one ssr::Mesh per glTF primitive, shared by every node that instances it.
    // Primitives that are not triangles are skipped with a warning (points and lines have no
    // surface to reflect); a triangle primitive without POSITION, or with non-integer indices,
    // is a broken file and an error.
    static const char* kModeNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
    std::map<std::pair<int, int>, std::pair<int, int>> primitive_cache;  // (mesh, prim) -> (mesh idx, material)
    auto primitive = [&](int mesh_index, int prim_index) -> std::pair<int, int> {
        auto key = std::make_pair(mesh_index, prim_index);
        if (auto it = primitive_cache.find(key); it != primitive_cache.end()) return it->second;
        const auto& gmesh = model.meshes[size_t(mesh_index)];
        const auto& prim = gmesh.primitives[size_t(prim_index)];
        const std::string what = "mesh " + std::to_string(mesh_index) + " ('" + gmesh.name + "') primitive " +
                                 std::to_string(prim_index);
        std::pair<int, int> result{-1, -1};
        if (prim.mode != kModeTriangles && prim.mode != kModeStrip && prim.mode != kModeFan && prim.mode != -1) {
            warnings.push_back(path + ": " + what + ": " +
                               (prim.mode >= 0 && prim.mode < 4
                                    ? std::string("mode ") + kModeNames[prim.mode] + " skipped (only triangles are rendered)"
                                    : "mode " + std::to_string(prim.mode) + " is not a glTF primitive mode; skipped"));
            primitive_cache[key] = result;
            return result;
        }
        if (!prim.targets.empty())
            warnings.push_back(path + ": " + what + ": " + std::to_string(prim.targets.size()) +
                               " morph target(s) ignored (drawn with base positions)");
        auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) r.fail(what + ": no POSITION attribute");
        Mesh mesh;
        mesh.name = (gmesh.name.empty() ? "mesh" + std::to_string(mesh_index) : gmesh.name) +
                    (gmesh.primitives.size() > 1 ? "/" + std::to_string(prim_index) : "");
        mesh.positions = r.read_floats<3>(pos->second, what + " POSITION");
        if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end())
            mesh.normals = r.read_floats<3>(it->second, what + " NORMAL");
        if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end())
            mesh.uvs = r.read_floats<2>(it->second, what + " TEXCOORD_0");
        if (auto it = prim.attributes.find("TANGENT"); it != prim.attributes.end())
            mesh.tangents = r.read_floats<4>(it->second, what + " TANGENT");
        if (auto it = prim.attributes.find("TEXCOORD_1"); it != prim.attributes.end())
            mesh.uvs1 = r.read_floats<2>(it->second, what + " TEXCOORD_1");
        if (auto it = prim.attributes.find("COLOR_0"); it != prim.attributes.end())
            mesh.colors = r.read_colors(it->second, what + " COLOR_0");
        for (const auto* attr : {&mesh.normals})
            if (!attr->empty() && attr->size() != mesh.positions.size())
                r.fail(what + ": NORMAL has " + std::to_string(attr->size()) + " values for " +
                       std::to_string(mesh.positions.size()) + " positions");
        if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
            r.fail(what + ": TEXCOORD_0 has " + std::to_string(mesh.uvs.size()) + " values for " +
                   std::to_string(mesh.positions.size()) + " positions");
        if (!mesh.tangents.empty() && mesh.tangents.size() != mesh.positions.size())
            r.fail(what + ": TANGENT has " + std::to_string(mesh.tangents.size()) + " values for " +
                   std::to_string(mesh.positions.size()) + " positions");
        if (!mesh.uvs1.empty() && mesh.uvs1.size() != mesh.positions.size())
            r.fail(what + ": TEXCOORD_1 has " + std::to_string(mesh.uvs1.size()) + " values for " +
                   std::to_string(mesh.positions.size()) + " positions");
        if (!mesh.colors.empty() && mesh.colors.size() != mesh.positions.size())
            r.fail(what + ": COLOR_0 has " + std::to_string(mesh.colors.size()) + " values for " +
                   std::to_string(mesh.positions.size()) + " positions");
        std::vector<uint32_t> idx;
        if (prim.indices >= 0) {
            idx = r.read_indices(prim.indices, what + " indices");
        } else {
            idx.resize(mesh.positions.size());
            for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
        }
        mesh.indices = to_triangle_list(idx, prim.mode == -1 ? kModeTriangles : prim.mode);
        if (mesh.indices.empty()) r.fail(what + ": fewer than 3 vertices, no triangle");
        int material;
        if (prim.material >= 0) {
            if (prim.material >= int(model.materials.size()))
                r.fail(what + ": material index " + std::to_string(prim.material) + " is out of range (the file has " +
                       std::to_string(model.materials.size()) + " materials)");
            material = material_base + prim.material;
        } else {
            if (default_material < 0) {
                Material dm;
                dm.name = "default";
                dm.base_color = glm::vec4(1.0f);
                dm.metallic = 1.0f;
                dm.roughness = 1.0f;
                default_material = scene.add_material(dm);
            }
            material = default_material;
        }
        // A texture on set 1 of a primitive without TEXCOORD_1 samples set 0 (GpuScene copies it).
        if (mesh.uvs1.empty() && !uv1_warned.count(material)) {
            const Material& mat = scene.materials[size_t(material)];
            for (const TextureRef* t : {&mat.base_color_texture, &mat.metallic_roughness_texture, &mat.normal_texture,
                                        &mat.emissive_texture, &mat.specular_texture, &mat.specular_color_texture})
                if (t->valid() && t->texcoord == 1) {
                    warnings.push_back(path + ": material '" + mat.name + "' samples TEXCOORD_1, which " + what +
                                       " lacks; TEXCOORD_0 is used there");
                    uv1_warned.insert(material);
                    break;
                }
        }
        try {
            result = {scene.add_mesh(std::move(mesh)), material};
        } catch (const std::invalid_argument& e) {
            r.fail(what + ": " + e.what());
        }
        primitive_cache[key] = result;
        return result;
    };

    // Nodes: depth-first from the default scene's roots with an explicit stack (a file can
    // chain nodes deeper than the C++ stack), a depth limit, and cycle detection (tinygltf
    // accepts a node that lists itself, or an ancestor, as a child).
    const int first_object = int(scene.objects.size());
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        int s = model.defaultScene >= 0 ? model.defaultScene : 0;
        if (s >= int(model.scenes.size())) r.fail("default scene " + std::to_string(s) + " is out of range");
        roots = model.scenes[size_t(s)].nodes;
    } else {  // no scenes: every node that is nobody's child is a root
        std::set<int> children;
        for (const auto& n : model.nodes) children.insert(n.children.begin(), n.children.end());
        for (int i = 0; i < int(model.nodes.size()); ++i)
            if (!children.count(i)) roots.push_back(i);
    }
    for (size_t i = 0; i < model.meshes.size(); ++i)
        if (model.meshes[i].primitives.empty())
            warnings.push_back(path + ": mesh " + std::to_string(i) + " ('" + model.meshes[i].name + "') has no primitives");
    std::vector<int> state(model.nodes.size(), 0);  // 0 unseen, 1 on the path, 2 done
    struct Visit {
        int node;
        int depth;
        bool leave;  // true: the node's subtree is done
        glm::mat4 parent;
        int parent_node;  // its parent in Scene::nodes (animated files), -1 for a root
    };
    // A file with animations keeps its node tree (Scene::nodes, in this visiting order: parents
    // before children) so that its objects can be posed at any time; scene_node[file index].
    const bool animated = !model.animations.empty();
    std::vector<int> scene_node(model.nodes.size(), -1);
    std::vector<Visit> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, 1, false, transform, -1});
    while (!stack.empty()) {
        const Visit v = stack.back();
        stack.pop_back();
        const int ni = v.node;
        if (v.leave) {
            state[size_t(ni)] = 2;
            continue;
        }
        if (ni < 0 || ni >= int(model.nodes.size()))
            r.fail("node index " + std::to_string(ni) + " is out of range (the file has " +
                   std::to_string(model.nodes.size()) + " nodes)");
        const std::string what = "node " + std::to_string(ni);
        if (state[size_t(ni)] == 1) r.fail("node graph has a cycle through node " + std::to_string(ni));
        if (state[size_t(ni)] == 2) r.fail(what + " has more than one parent");
        if (v.depth > kMaxNodeDepth)
            r.fail(what + " is nested deeper than " + std::to_string(kMaxNodeDepth) + " levels in the node hierarchy");
        state[size_t(ni)] = 1;
        const auto& node = model.nodes[size_t(ni)];
        const NodeTransform local = node_local_transform(node, r, what);
        int me = -1;
        if (animated) {
            SceneNode sn;
            sn.rest = sn.current = local;
            if (node.extras.Has("ssrlab")) sn.current = saved_pose(node.extras.Get("ssrlab"), local, r, what);
            sn.name = node.name;
            sn.file_index = ni;
            sn.parent = v.parent_node;
            if (v.parent_node < 0) sn.root_transform = transform;
            scene.nodes.push_back(std::move(sn));
            me = scene_node[size_t(ni)] = int(scene.nodes.size()) - 1;
        }
        // An animated file saved by ssrlab stands in the pose it was saved in.
        const glm::mat4 world = v.parent * (me >= 0 ? scene.nodes[size_t(me)].current : local).local();
        if (!finite_matrix(world)) r.fail(what + ": its world transform overflows to Inf or NaN");
        if (node.mesh >= 0 || node.mesh < -1) {
            if (node.mesh >= int(model.meshes.size()) || node.mesh < 0)
                r.fail(what + ": mesh index " + std::to_string(node.mesh) +
                       " is out of range (the file has " + std::to_string(model.meshes.size()) + " meshes)");
            const auto& gmesh = model.meshes[size_t(node.mesh)];
            const bool drawable = invertible_transform(world);
            if (!drawable && !gmesh.primitives.empty())
                warnings.push_back(path + ": " + what + ": its world transform is singular or degenerate (a zero scale, or axes scaled more than 1e6 apart); mesh " +
                                   std::to_string(node.mesh) + " skipped");
            for (int p = 0; drawable && p < int(gmesh.primitives.size()); ++p) {
                auto [mesh, material] = primitive(node.mesh, p);
                if (mesh < 0) continue;
                Bounds b;
                for (const auto& q : scene.meshes[size_t(mesh)].positions) b.extend(q);
                for (int k = 0; k < 8; ++k) {
                    const glm::vec3 corner((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y,
                                           (k & 4) ? b.max.z : b.min.z);
                    const glm::vec3 w(world * glm::vec4(corner, 1.0f));
                    if (!within_world(w))
                        r.fail(what + ": mesh " + std::to_string(node.mesh) + " reaches (" + num(w.x) + ", " + num(w.y) +
                               ", " + num(w.z) + ") in world space, beyond +-" + num(kMaxWorldCoordinate));
                }
                std::string name = node.name.empty() ? scene.meshes[size_t(mesh)].name : node.name;
                if (gmesh.primitives.size() > 1) name += "/" + std::to_string(p);
                const int object = scene.add_object(mesh, material, world, name);
                if (me >= 0) scene.nodes[size_t(me)].objects.push_back(object);
            }
        }
        if (node.skin >= int(model.skins.size()) || node.skin < -1)
            r.fail(what + ": skin index " + std::to_string(node.skin) + " is out of range");
        if (node.camera >= int(model.cameras.size()) || node.camera < -1)
            r.fail(what + ": camera index " + std::to_string(node.camera) + " is out of range (the file has " +
                   std::to_string(model.cameras.size()) + " cameras)");
        if (node.camera >= 0 && !scene.camera && model.cameras[size_t(node.camera)].type == "perspective") {
            const auto& pc = model.cameras[size_t(node.camera)].perspective;
            const glm::vec3 back(world[2]), up(world[1]);
            if (!usable_direction(back) || !usable_direction(up) || !usable_direction(glm::cross(back, up)))
                r.fail(what + ": camera " + std::to_string(node.camera) + "'s node transform is degenerate (no view direction)");
            CameraDesc cam;
            cam.position = glm::vec3(world[3]);
            if (!within_world(cam.position))
                r.fail(what + ": camera " + std::to_string(node.camera) + " stands beyond +-" + num(kMaxWorldCoordinate) +
                       " in world space");
            // glTF cameras look down -z; the target far enough away to differ in float from the position.
            const float reach = std::max(1.0f, 1e-3f * glm::length(cam.position));
            cam.target = cam.position - glm::normalize(back) * reach;
            cam.up = glm::normalize(up);
            cam.fov_y_degrees = float(glm::degrees(pc.yfov));
            cam.near_plane = float(pc.znear);
            cam.far_plane = pc.zfar > pc.znear ? float(pc.zfar) : 0.0f;  // 0: fitted to the scene later
            scene.camera = cam;
        }
        if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end() && it->second.Has("light")) {
            const auto& lv = it->second.Get("light");
            if (!lv.IsInt() && !lv.IsNumber()) r.fail(what + ": KHR_lights_punctual.light is not an index");
            const double ld = lv.GetNumberAsDouble();
            if (!(ld >= 0.0 && ld < double(model.lights.size())) || ld != std::floor(ld))
                r.fail(what + ": light index " + num(ld) + " is out of range (the file has " +
                       std::to_string(model.lights.size()) + " lights)");
            const int li = int(ld);
            const auto& gl = model.lights[size_t(li)];
            const std::string lwhat = "light " + std::to_string(li);
            Light l;
            l.name = gl.name;
            l.color = vec3_from(gl.color, glm::vec3(1.0f));
            l.intensity = float(gl.intensity);
            l.position = glm::vec3(world[3]);
            if (!within_world(l.position))
                r.fail(what + ": light " + std::to_string(li) + " stands beyond +-" + num(kMaxWorldCoordinate) +
                       " in world space");
            const glm::vec3 dir = -glm::vec3(world[2]);
            if (gl.type == "directional") {
                l.type = Light::Type::Directional;
                l.cast_shadow = true;
            } else {
                l.type = gl.type == "spot" ? Light::Type::Spot : Light::Type::Point;
                l.inner_cone = float(gl.spot.innerConeAngle);
                l.outer_cone = float(gl.spot.outerConeAngle);
                l.range = float(gl.range);
                // KHR_lights_punctual has no shadow flag: directional and spot lights cast one by
                // default (a layer of the 2D shadow maps each), point lights none unless
                // extras.cast_shadow asks (a cube map: six draws of the scene, six times the
                // memory, so not on by default for the many point lights a file may hold).
                l.cast_shadow = l.type == Light::Type::Spot;
            }
            if (gl.extras.Has("cast_shadow")) {
                if (!gl.extras.Get("cast_shadow").IsBool()) r.fail(lwhat + ": extras.cast_shadow is not a boolean");
                l.cast_shadow = gl.extras.Get("cast_shadow").Get<bool>();
            }
            const bool explicit_dir = gl.extras.Has("direction");
            l.direction = explicit_dir ? vec3_from_value(gl.extras.Get("direction"), dir, r, lwhat + ": extras.direction") : dir;
            if (gl.extras.Has("position"))
                l.position = vec3_from_value(gl.extras.Get("position"), l.position, r, lwhat + ": extras.position",
                                             -kMaxWorldCoordinate, kMaxWorldCoordinate);
            if (l.type != Light::Type::Point && !usable_direction(l.direction))
                r.fail(explicit_dir ? lwhat + ": extras.direction is a zero vector"
                                    : what + ": light " + std::to_string(li) + " has no direction (its node's transform is degenerate)");
            l.direction = usable_direction(l.direction) ? glm::normalize(l.direction) : glm::vec3(0.0f, -1.0f, 0.0f);
            const int light = scene.add_light(l);
            if (me >= 0) scene.nodes[size_t(me)].light = light;
        }
        stack.push_back({ni, v.depth, true, glm::mat4(1.0f), -1});
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
            stack.push_back({*c, v.depth + 1, false, world, me});
    }

    if (animated) read_animations(model, r, scene, scene_node, path, warnings);

    // Scene-level extras written by save_gltf.
    if (!model.scenes.empty()) {
        const auto& extras = model.scenes[size_t(model.defaultScene >= 0 ? model.defaultScene : 0)].extras;
        if (extras.Has("ssrlab")) {
            const auto& x = extras.Get("ssrlab");
            const std::string w = "scene extras.ssrlab";
            if (!x.IsObject()) r.fail(w + " is not an object");
            if (x.Has("ambient")) scene.ambient = vec3_from_value(x.Get("ambient"), scene.ambient, r, w + ".ambient", 0.0, kMaxRadiance);
            if (x.Has("name")) scene.name = string_from_value(x.Get("name"), r, w + ".name");
            if (x.Has("camera")) {
                const auto& c = x.Get("camera");
                const std::string cw = w + ".camera";
                if (!c.IsObject()) r.fail(cw + " is not an object");
                CameraDesc cam = scene.camera.value_or(CameraDesc{});
                cam.position = vec3_from_value(c.Get("position"), cam.position, r, cw + ".position",
                                               -kMaxWorldCoordinate, kMaxWorldCoordinate);
                cam.target = vec3_from_value(c.Get("target"), cam.target, r, cw + ".target",
                                             -kMaxWorldCoordinate, kMaxWorldCoordinate);
                cam.up = vec3_from_value(c.Get("up"), cam.up, r, cw + ".up");
                if (c.Has("fov_y")) cam.fov_y_degrees = float(number_from_value(c.Get("fov_y"), r, cw + ".fov_y", 1e-4, 179.9));
                if (c.Has("near")) cam.near_plane = float(number_from_value(c.Get("near"), r, cw + ".near", 1e-30, 1e30));
                if (c.Has("far")) cam.far_plane = float(number_from_value(c.Get("far"), r, cw + ".far", 0.0, 1e30));
                if (!usable_direction(cam.target - cam.position)) r.fail(cw + ": target equals position");
                if (!usable_direction(glm::cross(cam.target - cam.position, cam.up)))
                    r.fail(cw + ": up is zero or parallel to the view direction");
                if (cam.far_plane > 0.0f && !(cam.far_plane > cam.near_plane)) r.fail(cw + ": far must be greater than near");
                scene.camera = cam;
            }
            if (x.Has("environment")) {
                const auto& e = x.Get("environment");
                const std::string ew = w + ".environment";
                if (!e.IsObject()) r.fail(ew + " is not an object");
                Environment env;
                const std::string type = e.Has("type") ? string_from_value(e.Get("type"), r, ew + ".type") : "constant";
                if (type != "constant" && type != "sky" && type != "map")
                    r.fail(ew + ".type '" + type + "' is not constant, sky or map");
                env.type = type == "sky" ? Environment::Type::Sky : type == "map" ? Environment::Type::Map : Environment::Type::Constant;
                env.color = vec3_from_value(e.Get("color"), env.color, r, ew + ".color", 0.0, kMaxRadiance);
                env.sky_zenith = vec3_from_value(e.Get("zenith"), env.sky_zenith, r, ew + ".zenith", 0.0, kMaxRadiance);
                env.sky_horizon = vec3_from_value(e.Get("horizon"), env.sky_horizon, r, ew + ".horizon", 0.0, kMaxRadiance);
                env.ground = vec3_from_value(e.Get("ground"), env.ground, r, ew + ".ground", 0.0, kMaxRadiance);
                if (e.Has("intensity")) env.intensity = float(number_from_value(e.Get("intensity"), r, ew + ".intensity", 0.0, kMaxRadiance));
                if (env.type == Environment::Type::Map) {
                    if (!e.Has("map")) r.fail(ew + ": type 'map' without a 'map' path");
                    const std::string ref = string_from_value(e.Get("map"), r, ew + ".map");
                    // Checked now, not when the renderer reads it: a device or FIFO would hang the reader.
                    env.map_path = resolve_reference(pol, ref, "environment map").string();
                    probe_image_file(env.map_path, path + ": environment map");
                }
                scene.environment = env;
            }
        }
    }
    if (scene.camera && scene.camera->far_plane <= 0.0f) {  // glTF infinite projection: fit the far plane
        const Bounds bb = scene.bounds();
        float reach = 1.0f;
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 corner((i & 1) ? bb.max.x : bb.min.x, (i & 2) ? bb.max.y : bb.min.y, (i & 4) ? bb.max.z : bb.min.z);
            reach = std::max(reach, glm::length(corner - scene.camera->position));
        }
        if (!std::isfinite(reach) || reach > 1e30f) r.fail("the scene is too large to fit an infinite camera's far plane");
        scene.camera->far_plane = 1.5f * reach;
        if (!(scene.camera->far_plane > scene.camera->near_plane)) scene.camera->far_plane = scene.camera->near_plane * 2.0f;
    }
    if (int(scene.objects.size()) == first_object)
        warnings.push_back(path + ": no triangles were loaded (the file's default scene has nothing ssrlab can draw)");
    if (scene.name == "scene") scene.name = fs::path(path).stem().string();
    scene.touch();
    return first_object;
}

}  // namespace

int load_gltf(Scene& scene, const std::string& path, const glm::mat4& transform, const GltfLoadOptions& options,
              std::vector<std::string>* warnings) {
    std::vector<std::string> local;
    try {
        const int first = load_gltf_checked(scene, path, transform, options, local);
        if (warnings)
            for (auto& w : local) warnings->push_back(printable(w));
        return first;
    } catch (const FileNotFound& e) {
        throw FileNotFound(printable(e.what()));
    } catch (const SceneError& e) {
        throw SceneError(printable(e.what()));
    } catch (const std::bad_alloc&) {
        throw SceneError(printable(path) + ": out of memory while loading (the file's sizes are too large)");
    } catch (const std::length_error& e) {
        throw SceneError(printable(path) + ": a size in the file is too large (" + printable(e.what()) + ")");
    } catch (const std::invalid_argument& e) {
        throw SceneError(printable(path) + ": " + printable(e.what()));
    } catch (const std::out_of_range& e) {
        throw SceneError(printable(path) + ": " + printable(e.what()));
    } catch (const fs::filesystem_error& e) {
        throw SceneError(printable(path) + ": " + printable(e.what()));
    }
}

}  // namespace ssr
