#include "scene/gltf_io.h"

#include <tiny_gltf.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <set>

#include "core/errors.h"
#include "scene/image_io.h"

namespace fs = std::filesystem;

namespace ssr {

namespace {

constexpr int kModeTriangles = 4, kModeStrip = 5, kModeFan = 6;

// ---------------------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------------------

// Decodes every image through OpenImageIO rather than tinygltf's stb_image.
bool decode_with_oiio(tinygltf::Image* image, const int index, std::string* err, std::string* /*warn*/,
                      int, int, const unsigned char* bytes, int size, void*) {
    try {
        std::string hint = image->mimeType;
        if (hint.empty() && !image->uri.empty()) hint = fs::path(image->uri).extension().string();
        const std::string what =
            "image " + std::to_string(index) + (image->uri.empty() ? "" : " ('" + image->uri + "')");
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
        const auto [data, stride, elem] = view(acc, index, what);
        std::vector<uint32_t> out(acc.count);
        for (size_t i = 0; i < acc.count; ++i) {
            const uint8_t* p = data + i * stride;
            switch (acc.componentType) {
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: out[i] = *p; break;
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); out[i] = v; break; }
                case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); out[i] = v; break; }
                default: fail(what + ": index accessor " + std::to_string(index) + " has a non-integer component type");
            }
        }
        return out;
    }

private:
    const tinygltf::Accessor& accessor(int index, const std::string& what) const {
        if (index < 0 || index >= int(model_.accessors.size()))
            fail(what + ": accessor index " + std::to_string(index) + " is out of range (the file has " +
                 std::to_string(model_.accessors.size()) + " accessors)");
        return model_.accessors[size_t(index)];
    }

    struct View {
        const uint8_t* data;
        size_t stride;
        size_t elem;
    };

    View view(const tinygltf::Accessor& acc, int index, const std::string& what) const {
        const std::string a = what + ": accessor " + std::to_string(index);
        if (acc.bufferView < 0 || acc.bufferView >= int(model_.bufferViews.size()))
            fail(a + " refers to bufferView " + std::to_string(acc.bufferView) + ", out of range (the file has " +
                 std::to_string(model_.bufferViews.size()) + ")");
        const auto& bv = model_.bufferViews[size_t(acc.bufferView)];
        if (bv.buffer < 0 || bv.buffer >= int(model_.buffers.size()))
            fail(a + ": bufferView " + std::to_string(acc.bufferView) + " refers to buffer " + std::to_string(bv.buffer) +
                 ", out of range");
        const auto& buf = model_.buffers[size_t(bv.buffer)];
        const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
        const int comps = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        if (comp_size <= 0 || comps <= 0) fail(a + " has an invalid component type or element type");
        const size_t elem = size_t(comp_size) * size_t(comps);
        const size_t stride = bv.byteStride ? bv.byteStride : elem;
        const size_t begin = bv.byteOffset + acc.byteOffset;
        const size_t need = acc.count ? begin + stride * (acc.count - 1) + elem : begin;
        if (acc.byteOffset + (acc.count ? stride * (acc.count - 1) + elem : 0) > bv.byteLength ||
            bv.byteOffset + bv.byteLength > buf.data.size() || need > buf.data.size())
            fail(a + " reads past the end of its buffer (" + std::to_string(need) + " bytes needed, buffer " +
                 std::to_string(bv.buffer) + " has " + std::to_string(buf.data.size()) + ")");
        return View{buf.data.data() + begin, stride, elem};
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

glm::mat4 node_local_transform(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) {
        glm::mat4 m;
        for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(n.matrix[size_t(i)]);  // column-major
        return m;
    }
    glm::mat4 t(1.0f), r(1.0f), s(1.0f);
    if (n.translation.size() == 3)
        t = glm::translate(glm::mat4(1.0f), glm::vec3(n.translation[0], n.translation[1], n.translation[2]));
    if (n.rotation.size() == 4)  // glTF stores (x, y, z, w)
        r = glm::mat4_cast(glm::normalize(glm::quat(float(n.rotation[3]), float(n.rotation[0]), float(n.rotation[1]),
                                                    float(n.rotation[2]))));
    if (n.scale.size() == 3) s = glm::scale(glm::mat4(1.0f), glm::vec3(n.scale[0], n.scale[1], n.scale[2]));
    return t * r * s;
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

TextureRef texture_ref(const tinygltf::Model& model, int texture_index, int texcoord, int image_base,
                       const GltfReader& r, const std::string& what) {
    TextureRef ref;
    if (texture_index < 0) return ref;
    if (texture_index >= int(model.textures.size()))
        r.fail(what + ": texture index " + std::to_string(texture_index) + " is out of range (the file has " +
               std::to_string(model.textures.size()) + " textures)");
    const auto& tex = model.textures[size_t(texture_index)];
    if (tex.source < 0 || tex.source >= int(model.images.size()))
        r.fail("texture " + std::to_string(texture_index) + ": image index " + std::to_string(tex.source) +
               " is out of range (the file has " + std::to_string(model.images.size()) + " images)");
    ref.image = image_base + tex.source;
    ref.texcoord = texcoord;
    if (tex.sampler >= 0 && tex.sampler < int(model.samplers.size())) {
        ref.wrap_s = model.samplers[size_t(tex.sampler)].wrapS;
        ref.wrap_t = model.samplers[size_t(tex.sampler)].wrapT;
    }
    return ref;
}

glm::vec3 vec3_from(const std::vector<double>& v, glm::vec3 fallback) {
    return v.size() >= 3 ? glm::vec3(float(v[0]), float(v[1]), float(v[2])) : fallback;
}

glm::vec3 vec3_from_value(const tinygltf::Value& v, glm::vec3 fallback) {
    if (!v.IsArray() || v.ArrayLen() < 3) return fallback;
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) out[i] = float(v.Get(i).GetNumberAsDouble());
    return out;
}

}  // namespace

int load_gltf(Scene& scene, const std::string& path, const glm::mat4& transform) {
    if (!fs::exists(path)) throw FileNotFound("glTF file not found: " + path);
    if (fs::is_directory(path)) throw SceneError(path + ": is a folder, not a glTF file");

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decode_with_oiio, nullptr);
    tinygltf::Model model;
    std::string err, warn;
    bool binary = fs::path(path).extension() == ".glb";
    {
        std::ifstream probe(path, std::ios::binary);
        char magic[4] = {0, 0, 0, 0};
        probe.read(magic, 4);
        if (std::memcmp(magic, "glTF", 4) == 0) binary = true;
    }
    const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                           : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    if (!ok) {
        std::string msg = err.empty() ? warn : err;
        while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
        throw SceneError(path + ": not a valid glTF 2.0 file: " + (msg.empty() ? "unknown error" : msg));
    }
    GltfReader r(model, path);

    // Images: tinygltf keeps going when an external image is missing; we do not.
    const int image_base = int(scene.images.size());
    for (size_t i = 0; i < model.images.size(); ++i) {
        const auto& gi = model.images[i];
        if (gi.image.empty()) {
            std::string where = gi.uri.empty() ? "buffer view " + std::to_string(gi.bufferView) : "'" + gi.uri + "'";
            std::string why = "could not be loaded";
            if (!gi.uri.empty() && gi.uri.rfind("data:", 0) != 0 &&
                !fs::exists(fs::path(path).parent_path() / gi.uri))
                why = "file not found (looked for " + (fs::path(path).parent_path() / gi.uri).string() + ")";
            r.fail("image " + std::to_string(i) + " " + where + " " + why);
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
        m.double_sided = gm.doubleSided;
        m.base_color_texture = texture_ref(model, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, image_base, r, what);
        m.metallic_roughness_texture = texture_ref(model, pbr.metallicRoughnessTexture.index,
                                                   pbr.metallicRoughnessTexture.texCoord, image_base, r, what);
        m.normal_texture = texture_ref(model, gm.normalTexture.index, gm.normalTexture.texCoord, image_base, r, what);
        m.normal_scale = float(gm.normalTexture.scale);
        // The thesis's explicit reflectivity where ssrlab wrote it; otherwise the material
        // reflects as its metallic-roughness parameters say (kAutoReflectivity).
        m.reflectivity = kAutoReflectivity;
        if (gm.extras.Has("reflectivity")) m.reflectivity = float(gm.extras.Get("reflectivity").GetNumberAsDouble());
        scene.materials.push_back(m);
    }
    int default_material = -1;  // glTF's default material, added only when a primitive needs it

    // Meshes: one ssr::Mesh per glTF primitive, shared by every node that instances it.
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
            primitive_cache[key] = result;  // points and lines have no surface to reflect
            return result;
        }
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
        std::vector<uint32_t> idx;
        if (prim.indices >= 0) {
            idx = r.read_indices(prim.indices, what + " indices");
        } else {
            idx.resize(mesh.positions.size());
            for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
        }
        mesh.indices = to_triangle_list(idx, prim.mode == -1 ? kModeTriangles : prim.mode);
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
        try {
            result = {scene.add_mesh(std::move(mesh)), material};
        } catch (const std::invalid_argument& e) {
            r.fail(what + ": " + e.what());
        }
        primitive_cache[key] = result;
        return result;
    };

    // Nodes: depth-first from the default scene's roots, with cycle detection (tinygltf
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
    std::vector<int> state(model.nodes.size(), 0);  // 0 unseen, 1 on the path, 2 done
    std::function<void(int, const glm::mat4&)> visit = [&](int ni, const glm::mat4& parent) {
        if (ni < 0 || ni >= int(model.nodes.size()))
            r.fail("node index " + std::to_string(ni) + " is out of range (the file has " +
                   std::to_string(model.nodes.size()) + " nodes)");
        if (state[size_t(ni)] == 1) r.fail("node graph has a cycle through node " + std::to_string(ni));
        if (state[size_t(ni)] == 2) r.fail("node " + std::to_string(ni) + " has more than one parent");
        state[size_t(ni)] = 1;
        const auto& node = model.nodes[size_t(ni)];
        const glm::mat4 world = parent * node_local_transform(node);
        if (node.mesh >= 0) {
            if (node.mesh >= int(model.meshes.size()))
                r.fail("node " + std::to_string(ni) + ": mesh index " + std::to_string(node.mesh) +
                       " is out of range (the file has " + std::to_string(model.meshes.size()) + " meshes)");
            const auto& gmesh = model.meshes[size_t(node.mesh)];
            for (int p = 0; p < int(gmesh.primitives.size()); ++p) {
                auto [mesh, material] = primitive(node.mesh, p);
                if (mesh < 0) continue;
                std::string name = node.name.empty() ? scene.meshes[size_t(mesh)].name : node.name;
                if (gmesh.primitives.size() > 1) name += "/" + std::to_string(p);
                scene.add_object(mesh, material, world, name);
            }
        }
        if (node.camera >= 0 && !scene.camera && node.camera < int(model.cameras.size()) &&
            model.cameras[size_t(node.camera)].type == "perspective") {
            const auto& pc = model.cameras[size_t(node.camera)].perspective;
            CameraDesc cam;
            cam.position = glm::vec3(world[3]);
            cam.target = cam.position - glm::normalize(glm::vec3(world[2]));  // glTF cameras look down -z
            cam.up = glm::normalize(glm::vec3(world[1]));
            cam.fov_y_degrees = float(glm::degrees(pc.yfov));
            cam.near_plane = float(pc.znear);
            cam.far_plane = pc.zfar > pc.znear ? float(pc.zfar) : 0.0f;  // 0: fitted to the scene later
            scene.camera = cam;
        }
        if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end() && it->second.Has("light")) {
            const int li = it->second.Get("light").GetNumberAsInt();
            if (li < 0 || li >= int(model.lights.size()))
                r.fail("node " + std::to_string(ni) + ": light index " + std::to_string(li) + " is out of range");
            const auto& gl = model.lights[size_t(li)];
            Light l;
            l.name = gl.name;
            l.color = vec3_from(gl.color, glm::vec3(1.0f));
            l.intensity = float(gl.intensity);
            l.position = glm::vec3(world[3]);
            l.direction = glm::normalize(-glm::vec3(world[2]));
            if (gl.type == "directional") {
                l.type = Light::Type::Directional;
                l.cast_shadow = true;
            } else {
                l.type = Light::Type::Point;  // spot lights are treated as point lights
            }
            if (gl.extras.Has("cast_shadow")) l.cast_shadow = gl.extras.Get("cast_shadow").Get<bool>();
            if (gl.extras.Has("direction")) l.direction = vec3_from_value(gl.extras.Get("direction"), l.direction);
            if (gl.extras.Has("position")) l.position = vec3_from_value(gl.extras.Get("position"), l.position);
            scene.add_light(l);
        }
        for (int c : node.children) visit(c, world);
        state[size_t(ni)] = 2;
    };
    for (int root : roots) visit(root, transform);

    // Scene-level extras written by save_gltf.
    if (!model.scenes.empty()) {
        const auto& extras = model.scenes[size_t(model.defaultScene >= 0 ? model.defaultScene : 0)].extras;
        if (extras.Has("ssrlab")) {
            const auto& x = extras.Get("ssrlab");
            if (x.Has("ambient")) scene.ambient = vec3_from_value(x.Get("ambient"), scene.ambient);
            if (x.Has("name")) scene.name = x.Get("name").Get<std::string>();
            if (x.Has("camera") && x.Get("camera").IsObject()) {
                const auto& c = x.Get("camera");
                CameraDesc cam = scene.camera.value_or(CameraDesc{});
                cam.position = vec3_from_value(c.Get("position"), cam.position);
                cam.target = vec3_from_value(c.Get("target"), cam.target);
                cam.up = vec3_from_value(c.Get("up"), cam.up);
                if (c.Has("fov_y")) cam.fov_y_degrees = float(c.Get("fov_y").GetNumberAsDouble());
                if (c.Has("near")) cam.near_plane = float(c.Get("near").GetNumberAsDouble());
                if (c.Has("far")) cam.far_plane = float(c.Get("far").GetNumberAsDouble());
                scene.camera = cam;
            }
            if (x.Has("environment")) {
                const auto& e = x.Get("environment");
                Environment env;
                const std::string type = e.Has("type") ? e.Get("type").Get<std::string>() : "constant";
                env.type = type == "sky" ? Environment::Type::Sky : type == "map" ? Environment::Type::Map : Environment::Type::Constant;
                env.color = vec3_from_value(e.Get("color"), env.color);
                env.sky_zenith = vec3_from_value(e.Get("zenith"), env.sky_zenith);
                env.sky_horizon = vec3_from_value(e.Get("horizon"), env.sky_horizon);
                env.ground = vec3_from_value(e.Get("ground"), env.ground);
                if (e.Has("intensity")) env.intensity = float(e.Get("intensity").GetNumberAsDouble());
                if (e.Has("map")) {
                    fs::path p = e.Get("map").Get<std::string>();
                    env.map_path = p.is_absolute() ? p.string() : (fs::path(path).parent_path() / p).string();
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
        scene.camera->far_plane = 1.5f * reach;
    }
    if (scene.name == "scene") scene.name = fs::path(path).stem().string();
    scene.touch();
    return first_object;
}

// ---------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------

namespace {

class GltfBuilder {
public:
    tinygltf::Model model;

    GltfBuilder() {
        model.asset.version = "2.0";
        model.asset.generator = "ssrlab";
        model.buffers.emplace_back();
    }

    int add_view(const void* data, size_t bytes, int target) {
        auto& buf = model.buffers[0].data;
        while (buf.size() % 4) buf.push_back(0);  // glTF alignment
        tinygltf::BufferView bv;
        bv.buffer = 0;
        bv.byteOffset = buf.size();
        bv.byteLength = bytes;
        bv.target = target;
        const auto* p = static_cast<const uint8_t*>(data);
        buf.insert(buf.end(), p, p + bytes);
        model.bufferViews.push_back(bv);
        return int(model.bufferViews.size()) - 1;
    }

    template <typename V>
    int add_float_accessor(const std::vector<V>& values, int type, bool with_bounds) {
        tinygltf::Accessor acc;
        acc.bufferView = add_view(values.data(), values.size() * sizeof(V), TINYGLTF_TARGET_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        acc.count = values.size();
        acc.type = type;
        if (with_bounds) {  // glTF requires min/max on POSITION
            constexpr int n = V::length();
            acc.minValues.assign(n, 1e300);
            acc.maxValues.assign(n, -1e300);
            for (const auto& v : values)
                for (int c = 0; c < n; ++c) {
                    acc.minValues[size_t(c)] = std::min(acc.minValues[size_t(c)], double(v[c]));
                    acc.maxValues[size_t(c)] = std::max(acc.maxValues[size_t(c)], double(v[c]));
                }
        }
        model.accessors.push_back(acc);
        return int(model.accessors.size()) - 1;
    }

    int add_index_accessor(const std::vector<uint32_t>& idx) {
        tinygltf::Accessor acc;
        acc.bufferView = add_view(idx.data(), idx.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        acc.count = idx.size();
        acc.type = TINYGLTF_TYPE_SCALAR;
        model.accessors.push_back(acc);
        return int(model.accessors.size()) - 1;
    }
};

tinygltf::Value vec3_value(const glm::vec3& v) {
    return tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(double(v.x)), tinygltf::Value(double(v.y)),
                                                  tinygltf::Value(double(v.z))});
}

std::vector<double> matrix_values(const glm::mat4& m) {
    std::vector<double> out(16);
    for (int i = 0; i < 16; ++i) out[size_t(i)] = double(glm::value_ptr(m)[i]);
    return out;
}

}  // namespace

void save_gltf(const Scene& scene, const std::string& path) {
    const fs::path out(path);
    const std::string ext = out.extension().string();
    if (ext != ".gltf" && ext != ".glb")
        throw SceneError(path + ": the file name must end in .gltf or .glb");
    if (!out.parent_path().empty() && !fs::is_directory(out.parent_path()))
        throw FileNotFound("folder not found: " + out.parent_path().string());
    const bool binary = ext == ".glb";

    GltfBuilder b;
    auto& model = b.model;

    // Images (PNG in the buffer) and their textures.
    std::map<std::tuple<int, int, int>, int> texture_of;  // (image, wrap_s, wrap_t) -> texture
    std::vector<int> image_index(scene.images.size(), -1);
    auto texture = [&](const TextureRef& ref) -> int {
        if (!ref.valid()) return -1;
        if (image_index[size_t(ref.image)] < 0) {
            const Image& img = scene.images[size_t(ref.image)];
            const std::vector<uint8_t> png = encode_png(img);
            tinygltf::Image gi;
            gi.name = img.name;
            gi.mimeType = "image/png";
            gi.bufferView = b.add_view(png.data(), png.size(), 0);
            model.images.push_back(gi);
            image_index[size_t(ref.image)] = int(model.images.size()) - 1;
        }
        auto key = std::make_tuple(image_index[size_t(ref.image)], ref.wrap_s, ref.wrap_t);
        if (auto it = texture_of.find(key); it != texture_of.end()) return it->second;
        tinygltf::Sampler s;
        s.wrapS = ref.wrap_s;
        s.wrapT = ref.wrap_t;
        s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
        s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
        model.samplers.push_back(s);
        tinygltf::Texture t;
        t.source = image_index[size_t(ref.image)];
        t.sampler = int(model.samplers.size()) - 1;
        model.textures.push_back(t);
        return texture_of[key] = int(model.textures.size()) - 1;
    };

    for (const Material& m : scene.materials) {
        tinygltf::Material gm;
        gm.name = m.name;
        gm.pbrMetallicRoughness.baseColorFactor = {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a};
        gm.pbrMetallicRoughness.metallicFactor = m.metallic;
        gm.pbrMetallicRoughness.roughnessFactor = m.roughness;
        gm.emissiveFactor = {m.emissive.r, m.emissive.g, m.emissive.b};
        gm.doubleSided = m.double_sided;
        gm.pbrMetallicRoughness.baseColorTexture.index = texture(m.base_color_texture);
        gm.pbrMetallicRoughness.baseColorTexture.texCoord = m.base_color_texture.texcoord;
        gm.pbrMetallicRoughness.metallicRoughnessTexture.index = texture(m.metallic_roughness_texture);
        gm.pbrMetallicRoughness.metallicRoughnessTexture.texCoord = m.metallic_roughness_texture.texcoord;
        gm.normalTexture.index = texture(m.normal_texture);
        gm.normalTexture.texCoord = m.normal_texture.texcoord;
        gm.normalTexture.scale = m.normal_scale;
        if (!m.auto_reflectivity())
            gm.extras = tinygltf::Value(tinygltf::Value::Object{{"reflectivity", tinygltf::Value(double(m.reflectivity))}});
        model.materials.push_back(gm);
    }

    // Accessors once per mesh; a glTF mesh per (mesh, material) pair that objects use.
    struct Attribs { int pos, nrm, uv, tan, idx; };
    std::vector<Attribs> attribs;
    for (const Mesh& m : scene.meshes) {
        Attribs a{};
        a.pos = b.add_float_accessor(m.positions, TINYGLTF_TYPE_VEC3, true);
        a.nrm = b.add_float_accessor(m.normals, TINYGLTF_TYPE_VEC3, false);
        a.uv = m.uvs.empty() ? -1 : b.add_float_accessor(m.uvs, TINYGLTF_TYPE_VEC2, false);
        a.tan = m.tangents.empty() ? -1 : b.add_float_accessor(m.tangents, TINYGLTF_TYPE_VEC4, false);
        a.idx = b.add_index_accessor(m.indices);
        attribs.push_back(a);
    }
    std::map<std::pair<int, int>, int> gltf_mesh;
    tinygltf::Scene gs;
    gs.name = scene.name;
    for (const Object& o : scene.objects) {
        auto key = std::make_pair(o.mesh, o.material);
        if (!gltf_mesh.count(key)) {
            const Attribs& a = attribs[size_t(o.mesh)];
            tinygltf::Primitive p;
            p.attributes["POSITION"] = a.pos;
            p.attributes["NORMAL"] = a.nrm;
            if (a.uv >= 0) p.attributes["TEXCOORD_0"] = a.uv;
            if (a.tan >= 0) p.attributes["TANGENT"] = a.tan;
            p.indices = a.idx;
            p.material = o.material;
            p.mode = kModeTriangles;
            tinygltf::Mesh gm;
            gm.name = scene.meshes[size_t(o.mesh)].name;
            gm.primitives.push_back(p);
            model.meshes.push_back(gm);
            gltf_mesh[key] = int(model.meshes.size()) - 1;
        }
        tinygltf::Node n;
        n.name = o.name;
        n.mesh = gltf_mesh[key];
        n.matrix = matrix_values(o.transform);
        model.nodes.push_back(n);
        gs.nodes.push_back(int(model.nodes.size()) - 1);
    }

    for (const Light& l : scene.lights) {
        tinygltf::Light gl;
        gl.name = l.name;
        gl.type = l.type == Light::Type::Directional ? "directional" : "point";
        gl.color = {l.color.r, l.color.g, l.color.b};
        gl.intensity = l.intensity;
        // The node carries the light's frame; extras keep the exact vectors for a lossless reload.
        gl.extras = tinygltf::Value(tinygltf::Value::Object{{"cast_shadow", tinygltf::Value(l.cast_shadow)},
                                                            {"direction", vec3_value(l.direction)},
                                                            {"position", vec3_value(l.position)}});
        model.lights.push_back(gl);
        // A light shines down its node's -z: build a frame whose -z is the light direction.
        glm::vec3 z = -glm::normalize(l.direction);
        glm::vec3 up = std::abs(z.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
        glm::vec3 x = glm::normalize(glm::cross(up, z)), y = glm::cross(z, x);
        glm::mat4 m(glm::vec4(x, 0), glm::vec4(y, 0), glm::vec4(z, 0), glm::vec4(l.position, 1));
        tinygltf::Node n;
        n.name = l.name.empty() ? "light" + std::to_string(model.lights.size() - 1) : l.name;
        n.matrix = matrix_values(m);
        n.extensions["KHR_lights_punctual"] =
            tinygltf::Value(tinygltf::Value::Object{{"light", tinygltf::Value(int(model.lights.size()) - 1)}});
        model.nodes.push_back(n);
        gs.nodes.push_back(int(model.nodes.size()) - 1);
    }
    if (!scene.lights.empty()) model.extensionsUsed.push_back("KHR_lights_punctual");

    if (scene.camera) {
        const CameraDesc& c = *scene.camera;
        tinygltf::Camera gc;
        gc.type = "perspective";
        gc.perspective.yfov = glm::radians(double(c.fov_y_degrees));
        gc.perspective.znear = c.near_plane;
        gc.perspective.zfar = c.far_plane;
        gc.perspective.aspectRatio = 0.0;  // from the image
        model.cameras.push_back(gc);
        tinygltf::Node n;
        n.name = "camera";
        n.camera = 0;
        n.matrix = matrix_values(glm::inverse(glm::lookAt(c.position, c.target, c.up)));
        model.nodes.push_back(n);
        gs.nodes.push_back(int(model.nodes.size()) - 1);
    }

    const Environment& env = scene.environment;
    tinygltf::Value::Object env_obj{
        {"type", tinygltf::Value(std::string(env.type == Environment::Type::Sky ? "sky"
                                             : env.type == Environment::Type::Map ? "map" : "constant"))},
        {"color", vec3_value(env.color)},
        {"zenith", vec3_value(env.sky_zenith)},
        {"horizon", vec3_value(env.sky_horizon)},
        {"ground", vec3_value(env.ground)},
        {"intensity", tinygltf::Value(double(env.intensity))}};
    if (env.type == Environment::Type::Map) env_obj["map"] = tinygltf::Value(fs::absolute(env.map_path).string());
    tinygltf::Value::Object ssr_obj{{"ambient", vec3_value(scene.ambient)},
                                    {"name", tinygltf::Value(scene.name)},
                                    {"environment", tinygltf::Value(env_obj)}};
    if (scene.camera) {  // the camera node holds the view; extras keep the exact look-at for a lossless reload
        const CameraDesc& c = *scene.camera;
        ssr_obj["camera"] = tinygltf::Value(tinygltf::Value::Object{
            {"position", vec3_value(c.position)}, {"target", vec3_value(c.target)}, {"up", vec3_value(c.up)},
            {"fov_y", tinygltf::Value(double(c.fov_y_degrees))}, {"near", tinygltf::Value(double(c.near_plane))},
            {"far", tinygltf::Value(double(c.far_plane))}});
    }
    gs.extras = tinygltf::Value(tinygltf::Value::Object{{"ssrlab", tinygltf::Value(ssr_obj)}});
    model.scenes.push_back(gs);
    model.defaultScene = 0;

    if (!binary) model.buffers[0].uri = out.stem().string() + ".bin";
    if (model.buffers[0].data.empty()) model.buffers.clear(), model.bufferViews.clear();
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToFile(&model, path, /*embedImages=*/false, /*embedBuffers=*/false,
                                     /*prettyPrint=*/true, /*writeBinary=*/binary))
        throw SceneError(path + ": could not write the glTF file");
}

}  // namespace ssr
