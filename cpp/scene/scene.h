// The scene: triangle meshes, metallic-roughness materials, images, object instances with
// world transforms, punctual lights, an ambient term and an environment.
//
// Node hierarchies of loaded glTF files are flattened into objects (one per mesh primitive)
// with their world transforms; a file with animations also keeps its node tree and its
// animations (animation.h), so the objects can be posed at any time. Scene::save writes them
// back as glTF 2.0, so a scene made here opens in Blender, Mitsuba or any viewer and loads
// back identically.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scene/animation.h"

namespace ssr {

// An 8-bit RGBA image (textures are decoded to RGBA8 whatever their file format).
struct Image {
    std::string name;
    std::string source;  // file or "<embedded>" it was decoded from, for error messages
    int width = 0, height = 0;
    std::vector<uint8_t> rgba;  // row 0 = first row of the file (top of the image)
};

struct TextureRef {
    int image = -1;                 // index into Scene::images, -1 = none
    int wrap_s = 10497, wrap_t = 10497;  // glTF/GL wrap modes (REPEAT)
    int texcoord = 0;               // glTF texCoord: the mesh's set 0 (uvs) or 1 (uvs1)
    // KHR_texture_transform: the texture is sampled at (dot(transform_u, (u, v, 1)),
    // dot(transform_v, (u, v, 1))), the extension's offset x rotation x scale (identity without it).
    glm::vec3 transform_u{1.0f, 0.0f, 0.0f};
    glm::vec3 transform_v{0.0f, 1.0f, 0.0f};
    bool transformed() const { return transform_u != glm::vec3(1, 0, 0) || transform_v != glm::vec3(0, 1, 0); }
    glm::vec2 apply(const glm::vec2& uv) const {
        return {glm::dot(transform_u, glm::vec3(uv, 1.0f)), glm::dot(transform_v, glm::vec3(uv, 1.0f))};
    }
    bool valid() const { return image >= 0; }
};

// Material::reflectivity of a material that reflects as its metallic-roughness parameters say:
// r is then the luminance of its GGX specular albedo at the pixel's view angle
// (shaders/lib/specular_albedo.glsl), computed in the G-buffer pass.
constexpr float kAutoReflectivity = -1.0f;

// glTF 2.0 metallic-roughness material plus the thesis's reflectivity.
struct Material {
    std::string name;
    glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};  // linear RGB, alpha
    float metallic = 0.0f;
    float roughness = 0.5f;      // perceptual roughness as in glTF; GGX alpha = roughness^2
    float reflectivity = 0.0f;   // r of the thesis's composite c = r*c_r + (1-r)*c_d (seed 000, 2.4),
                                 // or kAutoReflectivity (glTF materials without the thesis's extras)
    bool auto_reflectivity() const { return reflectivity < 0.0f; }
    glm::vec3 emissive{0.0f};
    TextureRef base_color_texture;          // sRGB
    TextureRef metallic_roughness_texture;  // linear: G = roughness, B = metallic
    TextureRef normal_texture;              // linear, tangent space
    TextureRef emissive_texture;            // sRGB; multiplies `emissive` (glTF emissiveTexture)
    // KHR_materials_specular's textures: specular_texture's A channel (linear) multiplies
    // `specular`, specular_color_texture's RGB (sRGB) multiplies `specular_color`, per texel.
    TextureRef specular_texture;
    TextureRef specular_color_texture;
    float normal_scale = 1.0f;
    bool double_sided = false;   // back faces get flipped normals (glTF doubleSided)
    // glTF alphaMode: alpha = base_color.a x the base colour texture's alpha. MASK: a texel
    // with alpha below alpha_cutoff is a hole in every pass that decides visibility (the
    // G-buffer's constructions, the shadow map, the BVH traversals), so SSR and its truth see
    // the same holes. BLEND is tested the same way at 0.5 (visibility_cutoff): the deep
    // G-buffer keeps one opaque surface per layer and the reference traces opaque surfaces, so
    // a translucent layer would exist in neither; the loader says so in a SceneWarning.
    enum class AlphaMode { Opaque, Mask, Blend };
    AlphaMode alpha_mode = AlphaMode::Opaque;
    float alpha_cutoff = 0.5f;
    // KHR_materials_ior and KHR_materials_specular: a dielectric's specular reflectance at normal
    // incidence is min(((ior - 1) / (ior + 1))^2 x specular_color, 1) x specular (0.04 at the
    // defaults, glTF's core value); metals keep their base colour (F0 = mix(this, base, metallic)).
    float ior = 1.5f;
    float specular = 1.0f;
    glm::vec3 specular_color{1.0f};
    glm::vec3 dielectric_f0() const {
        const float r = (ior - 1.0f) / (ior + 1.0f);
        return glm::min(r * r * specular_color, glm::vec3(1.0f)) * specular;
    }
    // The alpha below which a texel is a hole, or -1 for an opaque material.
    float visibility_cutoff() const {
        return alpha_mode == AlphaMode::Opaque ? -1.0f : (alpha_mode == AlphaMode::Mask ? alpha_cutoff : 0.5f);
    }
};

class Scene;

// A material's values checked against their domains (glTF's ranges; the G-buffer keeps albedo as
// sRGB8, so a base colour above 1 would be clamped without a word): std::invalid_argument naming
// the field. With `scene`, also that each texture names one of its images. Defined with the
// other checked values in scene_values.cpp.
void validate_material(const Material& m, const Scene* scene = nullptr);
// The same checks one field at a time, for a change of that field alone.
void check_alpha_cutoff(float cutoff);
void check_emissive(const glm::vec3& emissive);

struct Mesh {
    std::string name;
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;   // always filled (computed when the source has none)
    std::vector<glm::vec2> uvs;       // empty when the source has none
    std::vector<glm::vec4> tangents;  // empty when the source has none (derivative TBN is used)
    // glTF COLOR_0 (linear RGBA in [0, 1]; RGB files get alpha 1): multiplies the base colour and
    // its alpha. Empty when the source has none (white).
    std::vector<glm::vec4> colors;
    // glTF TEXCOORD_1, what a texture with texCoord 1 samples; empty when the source has none
    // (such a texture then samples uvs).
    std::vector<glm::vec2> uvs1;
    std::vector<uint32_t> indices;    // triangle list, always indexed after loading
    size_t triangle_count() const { return indices.size() / 3; }
};

struct Object {
    std::string name;
    int mesh = -1;
    int material = -1;
    glm::mat4 transform{1.0f};  // object to world
};

struct Light {
    enum class Type { Directional, Point, Spot };
    std::string name;
    Type type = Type::Directional;
    glm::vec3 color{1.0f};
    // Directional: irradiance on a surface facing the light (W/m^2).
    // Point: radiant intensity (W/sr); irradiance falls off as 1/d^2.
    float intensity = 1.0f;
    glm::vec3 direction{0.0f, -1.0f, 0.0f};  // directional: the direction light travels
    glm::vec3 position{0.0f};                // point, spot
    // Spot (KHR_lights_punctual): full intensity inside inner_cone, none beyond outer_cone
    // (radians from `direction`), the extension's smooth falloff between.
    float inner_cone = 0.0f, outer_cone = 0.7853982f;
    // Point and spot: the distance where the light's influence ends (KHR_lights_punctual's
    // recommended window); 0 = no end.
    float range = 0.0f;
    bool cast_shadow = false;  // casts a shadow: a directional or spot light a 2D map, a point light a cube map
};

// Lights made with their values checked (std::invalid_argument naming the value); a spot
// light's direction is normalised after light_problem has seen it.
Light directional_light(const glm::vec3& direction, const glm::vec3& color, float intensity, bool cast_shadow,
                        const std::string& name);
Light point_light(const glm::vec3& position, const glm::vec3& color, float intensity, const std::string& name);
Light spot_light(const glm::vec3& position, const glm::vec3& direction, float inner_cone, float outer_cone,
                 const glm::vec3& color, float intensity, float range, const std::string& name);

// What a reflection ray that leaves the screen (or is faded) sees.
struct Environment {
    enum class Type { Constant, Sky, Map };
    Type type = Type::Constant;
    glm::vec3 color{0.0f};            // Constant
    glm::vec3 sky_zenith{0.25f, 0.45f, 0.85f}, sky_horizon{0.8f, 0.85f, 0.9f}, ground{0.3f, 0.28f, 0.25f};  // Sky
    std::string map_path;             // Map: an equirectangular image (EXR/HDR/PNG)
    float intensity = 1.0f;
};

// A map environment of an image file that exists and is a regular file (FileNotFound,
// SceneError otherwise: a device or FIFO would hang the reader), its path made absolute.
Environment environment_map(const std::string& path, float intensity);

struct CameraDesc {
    glm::vec3 position{0.0f, 0.0f, 5.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_degrees = 60.0f;
    float near_plane = 0.1f;
    float far_plane = 100.0f;
};

struct Bounds {
    glm::vec3 min{1e30f}, max{-1e30f};
    bool empty() const { return min.x > max.x; }
    void extend(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
};

class Scene {
public:
    std::string name = "scene";
    std::vector<Mesh> meshes;
    std::vector<Material> materials;
    std::vector<Image> images;
    std::vector<Object> objects;
    std::vector<Light> lights;
    glm::vec3 ambient{0.03f};  // constant ambient radiance, times albedo
    Environment environment;
    std::optional<CameraDesc> camera;  // a default view (from the file or the scene builder)
    // Reflection probes placed by the user (world space, seed 004's local cube maps):
    // where fallback "probes" captures its cube maps. Empty: placed by Settings.probe_grid.
    std::vector<glm::vec3> probes;
    // The node trees of animated glTF files (empty for everything else) and their animations.
    std::vector<SceneNode> nodes;
    std::vector<Animation> animations;

    // Renderers cache GPU copies of a scene; any change bumps the revision. What changed is
    // kept too, so that a cache pays for what changed only: the GPU copy updates a moved
    // object's matrix or an edited material's entry and the BVH rebuilds the moved object's
    // part, where anything else (geometry, images, the object set, the environment map)
    // rebuilds the copy. Each kind has its revision: the scene's revision when it last
    // changed; objects and materials also carry their own.
    uint64_t revision() const { return revision_; }
    // Anything may have changed (geometry, images, objects added, the environment): GPU copies
    // are rebuilt. Code that changes one of the kinds below says so with its own touch_*.
    void touch() { geometry_revision_ = ++revision_; }
    // Object `i`'s transform or material index changed.
    void touch_object(int i);
    // Material `m`'s parameters changed (or it was added).
    void touch_material(int m);
    // Lights were added, removed or changed.
    void touch_lights() { lights_revision_ = ++revision_; }
    // Values read per frame only (ambient, the default camera, probe positions).
    void touch_frame() { ++revision_; }
    uint64_t geometry_revision() const { return geometry_revision_; }
    uint64_t transforms_revision() const { return transforms_revision_; }
    uint64_t materials_revision() const { return materials_revision_; }
    uint64_t lights_revision() const { return lights_revision_; }
    // The revision at which object `i` (its transform or material index) / material `m` last
    // changed; 0 before any change since the scene was made.
    uint64_t object_revision(size_t i) const { return i < object_revisions_.size() ? object_revisions_[i] : 0; }
    uint64_t material_revision(size_t m) const { return m < material_revisions_.size() ? material_revisions_[m] : 0; }
    // Sets an object's object -> world matrix after checking it (finite, invertible, bounds
    // within the scene limits): std::invalid_argument naming the object otherwise.
    void set_object_transform(int i, const glm::mat4& transform);
    uint64_t id() const { return id_; }

    int add_mesh(Mesh mesh);             // validates indices/sizes, fills normals if empty
    int add_material(const Material& m);  // validate_material against this scene's images
    // A mesh, a material and an object instancing them; the material is checked before anything
    // is added, so a refused one leaves the scene as it was.
    int add_mesh_object(Mesh mesh, const Material& material, const glm::mat4& transform, const std::string& name);
    int add_object(int mesh, int material, const glm::mat4& transform, const std::string& name);
    int add_light(const Light& l);

    // Edits checked as for every caller (std::invalid_argument naming the field, or
    // std::out_of_range for an index), each telling the GPU copies what changed.
    void check_object(int i) const;
    const Image& image(int i) const;
    // Gives object `i` material `m`: edited in place where no other object shares its material,
    // else a new material of its own (the others keep theirs).
    void set_material(int i, const Material& m);
    void set_ambient(const glm::vec3& ambient);
    void set_probes(const std::vector<glm::vec3>& probes);  // finite, at most 64
    void set_environment(const Environment& e);

    size_t triangle_count() const;       // summed over objects (instanced)
    // A 64-bit hash of everything that changes an image (geometry, materials, images,
    // transforms, lights, ambient, environment, default camera): a cache key for references.
    uint64_t content_hash() const;
    Bounds bounds() const;               // world-space bounds of all objects

    Scene();
    Scene(const Scene& other);
    Scene& operator=(const Scene& other);

private:
    uint64_t revision_ = 0;
    uint64_t geometry_revision_ = 0, transforms_revision_ = 0, materials_revision_ = 0, lights_revision_ = 0;
    std::vector<uint64_t> object_revisions_, material_revisions_;
    uint64_t id_ = 0;
};

// Area-weighted vertex normals for an indexed triangle list.
std::vector<glm::vec3> compute_vertex_normals(const std::vector<glm::vec3>& positions,
                                              const std::vector<uint32_t>& indices);

}  // namespace ssr
