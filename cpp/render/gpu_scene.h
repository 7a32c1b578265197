// The GPU copy of a Scene: one interleaved vertex buffer and one index buffer for all
// meshes, per-object and per-material storage buffers, and a texture per (image, colour
// space). Built once per scene revision and cached by the Renderer.
#pragma once

#include <array>
#include <map>
#include <tuple>
#include <memory>
#include <vector>

#include "core/gl_resources.h"
#include "scene/scene.h"

namespace ssr {

struct GpuVertex {
    glm::vec3 position;
    glm::vec3 normal;
    glm::vec2 uv;
    glm::vec4 tangent;  // w = handedness; all zero when the mesh has no tangents
};

// std430 elements (see shaders/lib/scene_data.glsl)
struct GpuObject {
    glm::mat4 model;          // object -> world
    glm::mat4 normal_matrix;  // inverse-transpose of model (upper 3x3 used)
    glm::ivec4 material;      // x = material index
};

struct GpuMaterial {
    glm::vec4 base_color;
    glm::vec4 params;    // (metallic, roughness, reflectivity, normal_scale)
    glm::vec4 emissive;  // rgb
    glm::ivec4 flags;    // (has base colour tex, has metal-rough tex, has normal tex, double sided)
};

struct DrawItem {
    int object;
    int material;
    GLsizei index_count;
    size_t first_index;
    GLint base_vertex;
};

class GpuScene {
public:
    explicit GpuScene(const Scene& scene);

    void bind_geometry() const;  // VAO + storage buffers
    // Binds the material's textures to units 0..2 (a white / flat texture when absent).
    void bind_material_textures(int material) const;

    const std::vector<DrawItem>& draws() const { return draws_; }
    // True when some object's material has reflectivity > 0: without one, no ray is traced.
    bool has_reflective_surfaces() const { return reflective_; }
    // The equirectangular environment map (0 when the environment is not a map).
    GLuint environment_map() const { return environment_map_.id(); }
    const Bounds& bounds() const { return bounds_; }
    uint64_t revision() const { return revision_; }
    size_t triangle_count() const { return triangles_; }

private:
    GLuint texture_for(const Scene& scene, const TextureRef& ref, bool srgb);

    struct VertexArray {
        GLuint id = 0;
        ~VertexArray();
    };
    std::unique_ptr<VertexArray> vao_;
    Buffer vertices_, indices_, objects_, materials_;
    std::map<std::tuple<int, bool, int, int>, Texture> textures_;  // (image, srgb, wrap s, wrap t)
    std::vector<std::array<GLuint, 3>> material_textures_;
    Texture white_, flat_normal_, environment_map_;
    bool reflective_ = false;
    std::vector<DrawItem> draws_;
    Bounds bounds_;
    uint64_t revision_ = 0;
    size_t triangles_ = 0;
};

}  // namespace ssr
