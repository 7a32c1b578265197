// Internal to the glTF reader (gltf_read.cpp and the gltf_read_*.cpp it calls, one per section
// of the file): the checked access to accessors, the checked numbers, and the sections.
#pragma once

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "scene/animation.h"
#include "scene/gltf_internal.h"
#include "scene/scene.h"

namespace ssr::gltf_detail {

// Buffers, bufferViews and accessors (glTF 2.0, binary data storage): every read checked against the
// sizes the file gives (gltf_accessors.cpp).
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

    std::vector<uint32_t> read_indices(int index, const std::string& what) const;

    // COLOR_0 as RGBA (an RGB accessor gets alpha 1): float, or normalised unsigned byte or short,
    // as glTF allows for it.
    std::vector<glm::vec4> read_colors(int index, const std::string& what) const;

    const tinygltf::Accessor& accessor(int index, const std::string& what) const;

private:
    struct View {
        const uint8_t* data;
        size_t stride;
        size_t elem;
    };

    // The accessor's bytes inside its bufferView inside its buffer. Every sum and product is
    // overflow-checked: offsets near 2^64 must not wrap into a small, in-bounds-looking value.
    View view(const tinygltf::Accessor& acc, int index, const std::string& what) const;

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

// Number checks (gltf_read_values.cpp): `v` converted to float is finite and inside [lo, hi].
bool in_range(double v, double lo, double hi);
std::string num(double v);
void check_finite_list(const GltfReader& r, const std::vector<double>& v, const std::string& what);
bool finite_matrix(const glm::mat4& m);
glm::vec3 vec3_from(const std::vector<double>& v, glm::vec3 fallback);
// An [x, y, z] array of numbers in [lo, hi] from the file's extras.
glm::vec3 vec3_from_value(const tinygltf::Value& v, glm::vec3 fallback, const GltfReader& r, const std::string& what,
                          double lo = -1e30, double hi = 1e30);
double number_from_value(const tinygltf::Value& v, const GltfReader& r, const std::string& what, double lo, double hi);
std::string string_from_value(const tinygltf::Value& v, const GltfReader& r, const std::string& what);
bool within_world(const glm::vec3& p);
// Whether an object's transform can be drawn (scene_limits.h): a zero scale or axes scaled
// far apart make its normals NaN or zero-length.
bool invertible_transform(const glm::mat4& m);
// A checked vec3 direction: finite and of non-zero length.
bool usable_direction(const glm::vec3& v);

// Images, samplers and textures (glTF 2.0, texture data; gltf_read_textures.cpp).
// Decodes every image through OpenImageIO rather than tinygltf's stb_image.
bool decode_with_oiio(tinygltf::Image* image, const int index, std::string* err, std::string* warn, int, int,
                      const unsigned char* bytes, int size, void*);
void check_samplers(const tinygltf::Model& model, const GltfReader& r);
// Appends the file's images to the scene; `err`, `warn`: what tinygltf said while parsing.
// Returns the scene index of the file's image 0.
int read_images(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const std::string& path,
                const std::string& err, const std::string& warn);
TextureRef texture_ref(const tinygltf::Model& model, int texture_index, int texcoord, int image_base,
                       const GltfReader& r, const std::string& what, const tinygltf::ExtensionMap& extensions = {});

// Materials (glTF 2.0, materials; gltf_read_materials.cpp). read_materials returns the scene index of
// the file's material 0.
void check_materials(const tinygltf::Model& model, const GltfReader& r);
int read_materials(const tinygltf::Model& model, const GltfReader& r, Scene& scene, int image_base,
                   const std::string& path, std::vector<std::string>& warnings);

// Meshes (glTF 2.0, geometry; gltf_read_meshes.cpp): one ssr::Mesh per glTF primitive, read when a
// node first instances it and shared by every node that does.
struct PrimitiveReader {
    const tinygltf::Model& model;
    const GltfReader& r;
    Scene& scene;
    int material_base;
    const std::string& path;
    std::vector<std::string>& warnings;
    int default_material = -1;  // glTF's default material, added only when a primitive needs it
    std::set<int> uv1_warned;   // materials named in a warning about a missing TEXCOORD_1
    std::map<std::pair<int, int>, std::pair<int, int>> primitive_cache;  // (mesh, prim) -> (mesh idx, material)

    // (scene mesh, scene material) of primitive `prim_index` of mesh `mesh_index`; (-1, -1) for
    // a primitive that is skipped.
    std::pair<int, int> operator()(int mesh_index, int prim_index);
};

// Nodes and the scene graph (glTF 2.0, scenes and nodes; gltf_read_nodes.cpp): the default scene's objects,
// cameras and lights, each node's world transform premultiplied by `transform`. Returns the
// Scene::nodes index of each file node (animated files), -1 for the others.
std::vector<int> read_nodes(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const glm::mat4& transform,
                            PrimitiveReader& primitive, const std::string& path, std::vector<std::string>& warnings);

// Cameras (glTF 2.0, cameras; gltf_read_cameras.cpp).
void check_cameras(const tinygltf::Model& model, const GltfReader& r, std::vector<std::string>& warnings,
                   const std::string& file);
// The scene's camera from the first node with a perspective camera, `world` its transform.
void read_node_camera(const tinygltf::Model& model, const GltfReader& r, const tinygltf::Node& node,
                      const glm::mat4& world, const std::string& what, Scene& scene);
// A camera whose zfar glTF leaves out (an infinite projection) gets a far plane that holds the scene.
void fit_infinite_far_plane(Scene& scene, const GltfReader& r);

// Lights (KHR_lights_punctual; gltf_read_lights.cpp). read_node_light adds the node's light to
// the scene and returns its index, -1 where the node has none.
void check_lights(const tinygltf::Model& model, const GltfReader& r);
int read_node_light(const tinygltf::Model& model, const GltfReader& r, const tinygltf::Node& node,
                    const glm::mat4& world, const std::string& what, Scene& scene);

// Animations (glTF 2.0, animations; gltf_read_animations.cpp), their channels on the nodes read_nodes kept.
void read_animations(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const std::vector<int>& scene_node,
                     const std::string& path, std::vector<std::string>& warnings);

// What save_gltf writes in the default scene's extras.ssrlab (gltf_read_extras.cpp).
void read_scene_extras(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const PathPolicy& pol,
                       const std::string& path);


}  // namespace ssr::gltf_detail
