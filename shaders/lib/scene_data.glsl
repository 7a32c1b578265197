// Per-object and per-material data: the ObjectData and MaterialData records of storage buffers
// 1 and 2, read as objects[i] and materials[m]. Generated when the Renderer starts from
// cpp/render/gpu_structs.def, with the C++ structs GpuScene uploads (GpuObject, GpuMaterial);
// ssrlab._core.gpu_struct_glsl() prints them.
#include "generated/Objects.glsl"
#include "generated/Materials.glsl"

// Where texture k (0 base colour, 1 metallic-roughness, 2 normal, 3 emissive, 4 specular, 5 specular
// colour) of material m is sampled for
// the surface's texture coordinates: KHR_texture_transform's offset x rotation x scale.
vec2 texture_uv(MaterialData m, int k, vec2 uv) {
    return vec2(dot(m.uv_transform[2 * k].xyz, vec3(uv, 1.0)), dot(m.uv_transform[2 * k + 1].xyz, vec3(uv, 1.0)));
}

// A surface's two texture coordinate sets, xy TEXCOORD_0 and zw TEXCOORD_1 (a copy of set 0 where
// the mesh has no set 1, GpuScene): the one texture k reads (glTF texCoord), transformed. Every
// sampling site passes both sets, so each texture follows its own texCoord.
vec2 texture_set(MaterialData m, int k, vec4 uvs) {
    return m.uv_transform[2 * k].w != 0.0 ? uvs.zw : uvs.xy;
}
vec2 texture_uv(MaterialData m, int k, vec4 uvs) {
    return texture_uv(m, k, texture_set(m, k, uvs));
}

// The linear part of texture k's transform (rotation x scale, without the offset).
mat2 texture_linear(MaterialData m, int k) {
    return mat2(m.uv_transform[2 * k].x, m.uv_transform[2 * k + 1].x,   // column 0
                m.uv_transform[2 * k].y, m.uv_transform[2 * k + 1].y);  // column 1
}

// Texture k of material m in a rasterised pass, at the surface's coordinates uv with their screen
// derivatives, the transform applied to both (its linear part to the derivatives). Explicit
// gradients: an implicit derivative of a computed coordinate is undefined in non-uniform control
// flow (GLSL 4.50, 8.9), and on llvmpipe the alpha test's branch then sampled wrong mip levels.
vec4 sample_material_texture(sampler2D tex, MaterialData m, int k, vec2 uv, vec2 duv_dx, vec2 duv_dy) {
    mat2 linear = texture_linear(m, k);
    return textureGrad(tex, texture_uv(m, k, uv), linear * duv_dx, linear * duv_dy);
}
// The same at texture k's set of a surface's two (texture_set), with their derivatives.
vec4 sample_material_texture(sampler2D tex, MaterialData m, int k, vec4 uvs, vec4 duvs_dx, vec4 duvs_dy) {
    return sample_material_texture(tex, m, k, texture_set(m, k, uvs), texture_set(m, k, duvs_dx),
                                   texture_set(m, k, duvs_dy));
}

// Specular reflectance at normal incidence of object `object_id`'s surface (glTF metallic
// workflow): the material's dielectric F0 (KHR_materials_ior, KHR_materials_specular; 0.04 at
// their defaults) for the non-metal part, the base colour for the metal part.
vec3 surface_f0(int object_id, vec3 base_color, float metallic) {
    vec3 dielectric = object_id >= 0 ? materials[objects[object_id].material.x].dielectric_f0.rgb : vec3(0.04);
    return mix(dielectric, base_color, metallic);
}
