// Per-object and per-material data (storage buffers 1 and 2). Mirrors GpuObject and
// GpuMaterial in cpp/render/gpu_scene.h.

struct ObjectData {
    mat4 model;          // object -> world
    mat4 normal_matrix;  // inverse-transpose of model
    ivec4 material;      // x: material index, y: first index of its mesh, z: base vertex
};

struct MaterialData {
    vec4 base_color;  // linear RGB, alpha
    vec4 params;      // (metallic, roughness, reflectivity, normal scale)
    vec4 emissive;    // rgb; w: alpha below which a texel is a hole (glTF MASK/BLEND), -1 opaque
    ivec4 flags;      // (base colour texture, metallic-roughness texture, normal texture, double sided)
    ivec4 images;     // image index of each texture, -1 for none (for scene_textures.glsl)
    ivec4 wraps;      // wrap_s | wrap_t << 16 of each texture
};

layout(std430, binding = 1) readonly buffer Objects { ObjectData objects[]; };
layout(std430, binding = 2) readonly buffer Materials { MaterialData materials[]; };
