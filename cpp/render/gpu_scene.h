// The GPU copy of a Scene: one interleaved vertex buffer and one index buffer for all
// meshes, per-object and per-material storage buffers, and a texture per (image, colour
// space). Built once per geometry revision (Scene::geometry_revision) and cached by the
// Renderer; a moved object or an edited material updates its own entry only (update()), and
// the BVH rebuilds the moved objects' trees only (scene/bvh.h).
#pragma once

#include <array>
#include <deque>
#include <map>
#include <string>
#include <utility>
#include <tuple>
#include <memory>
#include <vector>

#include "core/gl_resources.h"
#include "render/gpu_structs.h"
#include "scene/embree_scene.h"
#include "scene/scene.h"

namespace ssr {

struct GpuVertex {
    glm::vec3 position;
    glm::vec3 normal;
    glm::vec2 uv;
    glm::vec4 tangent;  // w = handedness; all zero when the mesh has no tangents
    // glTF COLOR_0, white when the mesh has none (the product with the base colour is then exact)
    glm::vec4 color;
    glm::vec2 uv1;      // glTF TEXCOORD_1; a copy of uv when the mesh has none (glTF: set 0 instead)
};
// Floats per vertex in the vertex storage buffer (lib/scene_geometry.glsl, passes/reference_cpu.cpp).
constexpr size_t kVertexFloats = 18;
static_assert(sizeof(GpuVertex) == kVertexFloats * sizeof(float), "GpuVertex must be tightly packed floats");

struct DrawItem {
    int object;
    int material;
    GLsizei index_count;
    size_t first_index;
    GLint base_vertex;
};

// Work done on scene copies, counted for Renderer.stats.
struct SceneWork {
    uint64_t bvh_builds = 0;             // whole BVHs built
    uint64_t bvh_updates = 0;            // BVH updates after objects moved (or their alpha test changed)
    uint64_t bvh_updated_triangles = 0;  // triangles those updates rebuilt, summed
    double bvh_update_ms = 0.0;          // the last update's wall time (its trees, uploads and Embree's scene)
    uint64_t bvh_update_last_triangles = 0;  // ... and the triangles it rebuilt
    uint64_t object_updates = 0;         // objects' entries rewritten (a transform or material index)
    uint64_t material_updates = 0;       // materials' entries rewritten or added
};

class GpuScene {
public:
    // `work` (optional): counters of the work done (Renderer.stats).
    explicit GpuScene(const Scene& scene, SceneWork* work = nullptr);
    ~GpuScene();
    // Brings the copy to the scene's revision when its geometry revision is the copy's: the
    // moved objects' and edited materials' entries are rewritten, nothing else is uploaded (the
    // BVH follows at its next use). Returns false, changing nothing, when the geometry changed
    // (the caller builds a new copy).
    bool update(const Scene& scene);
    uint64_t geometry_revision() const { return geometry_revision_; }
    // Changes with anything a depth-only pass of the scene draws (the shadow maps): geometry,
    // any object's transform, an alpha-tested material's test. Unique over all copies of all
    // scenes, so a cache keyed on it never mistakes one scene for another.
    uint64_t caster_state() const { return caster_state_; }
    // The world regions where what a depth-only pass draws changed since caster_state() was
    // `since`: each moved object's bounds before and after the move, the bounds of an object
    // whose alpha test changed. False when `since` is no state this copy went through lately
    // (another scene's, one older than the log, or none): the caller draws everything again.
    bool caster_changes_since(uint64_t since, std::vector<Bounds>& regions) const;
    // Object i's world bounds (Scene::bounds of that object alone).
    const Bounds& world_bounds(int i) const { return object_bounds_[size_t(i)]; }

    void bind_geometry() const;  // VAO + storage buffers
    // Binds what the reference tracer reads (storage buffers 5-10: BVH nodes and triangles,
    // image texels and their layout, vertex and index data), building the BVH and the texel
    // buffer on first use: frames that trace no reference never pay for them.
    void bind_ray_tracing(const Scene& scene);
    // Binds the vertex and index data alone (storage buffers 9 and 10, lib/scene_geometry.glsl),
    // for passes that read triangles without the BVH (the visibility buffer's attribute pass).
    void bind_vertex_data() const;
    int bvh_depth() const { return bvh_depth_; }
    // The same triangles (bind_ray_tracing's BVH order) in an Embree scene, for tracing the
    // reference's rays on the CPU (built on first use; needs bind_ray_tracing first).
    const EmbreeTracer& embree_tracer();
    // Binds the material's textures to their units (material_texture_units; a white / flat
    // texture when absent): base colour, metallic-roughness and normal map always, the emissive
    // texture where the scene has one, the KHR_materials_specular pair where it has those.
    void bind_material_textures(int material) const;
    // The material textures' names and texture units, written once here: a shader that samples
    // them declares them by name (TEXTURE_MATERIAL_BASE_COLOR, ...; passes/compute.h, NamedUnits's
    // placed_textures), e.g. shaders/passes/depth_peel.frag.
    static const std::vector<std::pair<std::string, GLuint>>& material_texture_units() {
        static const std::vector<std::pair<std::string, GLuint>> units = {
            {"material.base_color", 0}, {"material.metallic_roughness", 1}, {"material.normal_map", 2},
            {"material.emissive", 4},   {"material.specular", 5},           {"material.specular_color", 6}};
        return units;
    }
    static GLuint material_texture_unit(size_t i) { return material_texture_units()[i].second; }
    // Whether some object's material has a specular texture (FrameFacts::specular_texture).
    bool has_specular_texture() const { return specular_texture_; }
    // Whether some object's material has an emissive texture (FrameFacts::emission_texture).
    bool has_emissive_texture() const { return emissive_texture_; }

    const std::vector<DrawItem>& draws() const { return draws_; }
    // Whether some vertex has a colour other than white (glTF COLOR_0; white multiplies by 1).
    bool has_vertex_colors() const { return vertex_colors_; }
    // The scene's buffers (GpuVertex, uint32 indices, GpuObject, GpuMaterial), for passes that read
    // them through views of their own (image buffers).
    const Buffer& vertex_buffer() const { return vertices_; }
    const Buffer& index_buffer() const { return indices_; }
    const Buffer& object_buffer() const { return objects_; }
    const Buffer& material_buffer() const { return materials_; }
    // What a material's G-buffer shading needs beyond its factors (the peeling compiles a variant
    // per combination): bit k (k < 6) it has texture slot k (base colour, metallic-roughness,
    // normal, emissive, specular, specular colour: kTextureFeatures), kAutoReflectivityFeature
    // its reflectivity is "auto".
    static constexpr int kTextureFeatures = 63, kAutoReflectivityFeature = 64;
    int material_features(int material) const { return material_features_[size_t(material)]; }
    // Whether the material's alpha makes holes (glTF MASK, BLEND tested at 0.5): the passes that
    // decide visibility test it (Material::visibility_cutoff).
    bool alpha_tested(int material) const { return alpha_tested_[size_t(material)] != 0; }
    // Whether some material is alpha-tested (the passes then compile their alpha variant).
    bool has_alpha_tested() const;
    // Draws every object for a depth-only pass: with `prog`, or `alpha_prog` (which binds the
    // material's textures and discards the holes) for an alpha-tested material; each program's
    // uniform u_object at `object_loc` / `alpha_object_loc`. Geometry must be bound. `only`
    // (optional, one flag per object): the objects drawn.
    void draw_depth(GLuint prog, GLint object_loc, GLuint alpha_prog, GLint alpha_object_loc,
                    const std::vector<uint8_t>* only = nullptr) const;
    // True when some object's material has reflectivity > 0: without one, no ray is traced.
    bool has_reflective_surfaces() const { return reflective_; }
    // The equirectangular environment map (0 when the environment is not a map).
    GLuint environment_map() const { return environment_map_.id(); }
    const Bounds& bounds() const { return bounds_; }
    uint64_t revision() const { return revision_; }
    size_t triangle_count() const { return triangles_; }
    // Object i's first triangle when every object's triangles are counted in draw order (the
    // visibility buffer's attribute pass keeps a record per such triangle); GpuObject.material.w.
    int first_triangle(int i) const { return first_triangle_[size_t(i)]; }

private:
    GLuint texture_for(const Scene& scene, const TextureRef& ref, bool srgb);
    // Material m's entry (its buffer element, textures, features, alpha test) from the scene.
    void set_material(const Scene& scene, size_t m);
    // Object i's entry (its buffer element, draw, world bounds) from the scene.
    GpuObject object_entry(const Scene& scene, size_t i) const;
    Bounds compute_object_bounds(const Scene& scene, size_t i) const;
    // The flags that follow which materials the objects use (reflective_, emissive_texture_, ...)
    // and the scene's bounds from the objects'.
    void refresh_summary(const Scene& scene);
    // What the depth-only passes read of material m: its alpha test (cutoff, factor, texture).
    static std::vector<float> alpha_key(const Material& m);
    // Rebuilds the moved objects' BVH parts and uploads what changed (bind_ray_tracing).
    void update_ray_tracing(const Scene& scene);
    void upload_bvh_changes();

    struct VertexArray {
        GLuint id = 0;
        ~VertexArray();
    };
    std::unique_ptr<VertexArray> vao_;
    Buffer vertices_, indices_, objects_, materials_;
    std::map<std::tuple<int, bool, int, int>, Texture> textures_;  // (image, srgb, wrap s, wrap t)
    std::vector<std::array<GLuint, 6>> material_textures_;
    std::vector<int> material_features_;  // per material: material_features()
    bool vertex_colors_ = false;          // has_vertex_colors()
    std::vector<uint8_t> alpha_tested_;   // per material
    std::vector<std::vector<float>> alpha_keys_;  // per material: alpha_key()
    std::vector<GpuMaterial> material_data_;      // the materials buffer's elements
    struct MeshRange {
        size_t first_index;
        GLsizei count;
        GLint base_vertex;
    };
    std::vector<MeshRange> mesh_ranges_;     // per mesh: its place in the index and vertex buffers
    std::vector<glm::mat4> object_transforms_;  // per object: the transform its entry holds
    std::vector<Bounds> object_bounds_;      // per object: its world bounds
    std::vector<int> first_triangle_;        // per object: first_triangle()
    Texture white_, flat_normal_, environment_map_;
    Buffer bvh_nodes_, bvh_triangles_, image_texels_, image_info_;
    bool ray_tracing_ready_ = false;
    std::unique_ptr<SceneBvh> bvh_;
    AlphaMasks alpha_masks_;  // the BVH triangles' alpha test (read by the Embree scene's filter)
    std::unique_ptr<EmbreeTracer> embree_;
    std::vector<int> bvh_moved_;       // objects whose BVH part is stale (moved since the last use)
    std::vector<int> bvh_alpha_;       // objects whose triangles' alpha test changed since
    SceneWork* work_ = nullptr;
    int bvh_depth_ = 0;
    uint64_t geometry_revision_ = 0;
    uint64_t caster_state_ = 0;
    // The last changes of caster_state_: each step's new state and the regions it changed
    // (caster_changes_since); caster_log_start_ the state before the first step kept.
    struct CasterStep {
        uint64_t state;
        std::vector<Bounds> regions;
    };
    std::deque<CasterStep> caster_log_;
    uint64_t caster_log_start_ = 0;
    static constexpr size_t kCasterLogSteps = 64;
    bool reflective_ = false;
    bool emissive_texture_ = false;
    bool specular_texture_ = false;
    std::vector<DrawItem> draws_;
    Bounds bounds_;
    uint64_t revision_ = 0;
    size_t triangles_ = 0;
};

}  // namespace ssr
