// A kept surface's G-buffer sample from its material: what depth peeling's shading pass
// (passes/depth_peel.frag) writes for a fragment and what the visibility buffer's attribute pass
// (passes/gbuffer_attributes.comp) writes for a sample it rebuilt from its triangle and ray: one
// function, so both constructions shade alike. The caller passes the surface as the raster
// interpolates it, with its screen-space derivatives (the fragment's dFdx/dFdy, or the attribute
// pass's differences over the pixel's 2x2 quad, Igehy 1999's ray differentials taken one pixel
// apart), since a compute pass has no quad derivatives.
// Compile-time: MATERIAL_TEXTURES (a bit per texture slot the material kind has, 0 none),
// MATERIAL_AUTO_R, EMISSION_TEXTURE, SPECULAR_TEXTURE (passes/depth_peel.frag says what each is).
// The including shader declares the samplers the kind reads (u_base_color_texture,
// u_metallic_roughness_texture, u_normal_texture; u_emissive_texture with EMISSION_TEXTURE and
// u_specular_texture, u_specular_color_texture with SPECULAR_TEXTURE, where MATERIAL_TEXTURES is not
// 0) and u_specular_albedo. Needs scene_data, gbuffer, normal_mapping, material, specular_albedo.
#ifndef MATERIAL_TEXTURES
#define MATERIAL_TEXTURES 63
#endif
#ifndef MATERIAL_HAS
#define MATERIAL_HAS(k) ((MATERIAL_TEXTURES & (1 << (k))) != 0)
#endif
#ifndef MATERIAL_AUTO_R
#define MATERIAL_AUTO_R 1
#endif
#ifndef EMISSION_TEXTURE
#define EMISSION_TEXTURE 0
#endif
#ifndef SPECULAR_TEXTURE
#define SPECULAR_TEXTURE 0
#endif

struct GBufferSurface {
    vec3 view_position;    // the surface point, view space
    vec3 view_normal;      // interpolated vertex normal (not normalised), view space
    vec4 uv;               // xy: TEXCOORD_0, zw: TEXCOORD_1
    vec4 view_tangent;     // interpolated vertex tangent, view space; w bitangent sign
    vec4 color;            // glTF COLOR_0
    vec4 duv_dx, duv_dy;   // screen derivatives of uv (texture LOD)
    vec3 dpos_dx, dpos_dy; // ... of view_position (a tangent frame where the mesh has no tangents)
    bool front_facing;
    int object;
};

struct GBufferTexel {
    GSample g;
    vec4 emission;  // gbuffer.emission (EMISSION_TEXTURE): rgb emitted radiance, a 1
    vec4 specular;  // gbuffer.specular (SPECULAR_TEXTURE): rgb dielectric F0, a 1
    bool hole;      // an alpha-tested material's hole: no surface
};

// m: the material of object s.object (the caller reads it: a uniform load in a draw of one object).
GBufferTexel gbuffer_shade(GBufferSurface s, MaterialData m) {
    GBufferTexel o;
    vec3 n = normalize(s.view_normal);
    vec3 t = vec3(0.0), b = vec3(0.0);
    bool has_frame = false;
#if MATERIAL_TEXTURES
    // Each texture at its own coordinates (KHR_texture_transform; the identity without it).
    // Texture k's texel, or white where the material has none (a constant condition: folded).
#define MATERIAL_TEXEL(tex, k) (MATERIAL_HAS(k) ? sample_material_texture(tex, m, k, s.uv, s.duv_dx, s.duv_dy) : vec4(1.0))
    if (MATERIAL_HAS(2) && m.flags.z != 0) {
        // The normal texture's coordinates' derivatives: the transform's linear part of the
        // surface's (texture_uv of a derivative minus texture_uv of 0 drops the offset).
        vec2 n_dx = texture_uv(m, 2, s.duv_dx) - texture_uv(m, 2, vec4(0.0));
        vec2 n_dy = texture_uv(m, 2, s.duv_dy) - texture_uv(m, 2, vec4(0.0));
        has_frame = tangent_frame_from_vertex(n, s.view_tangent, texture_linear(m, 2), t, b) ||
                    tangent_frame_from_gradients(n, s.dpos_dx, s.dpos_dy, n_dx, n_dy, t, b);
    }
    vec4 base_texel = MATERIAL_TEXEL(u_base_color_texture, 0);
    o.hole = material_alpha_hole(m, base_texel, s.color.a);
    o.g = material_sample(m, base_texel, MATERIAL_TEXEL(u_metallic_roughness_texture, 1),
                          MATERIAL_TEXEL(u_normal_texture, 2).xyz, n, t, b, has_frame, s.front_facing, s.object);
#if EMISSION_TEXTURE
    vec3 emission = material_emission(m, MATERIAL_TEXEL(u_emissive_texture, 3));
#endif
#if SPECULAR_TEXTURE
    vec3 dielectric_f0 = material_dielectric_f0(m, MATERIAL_TEXEL(u_specular_texture, 4),
                                                MATERIAL_TEXEL(u_specular_color_texture, 5));
#endif
#else
    o.hole = material_alpha_hole(m, vec4(1.0), s.color.a);
    // No texture: material_sample ignores the texel values (its flags are 0).
    o.g = material_sample(m, vec4(1.0), vec4(1.0), vec3(0.5, 0.5, 1.0), n, t, b, false, s.front_facing, s.object);
#if EMISSION_TEXTURE
    vec3 emission = material_emission(m, vec4(1.0));
#endif
#if SPECULAR_TEXTURE
    vec3 dielectric_f0 = m.dielectric_f0.rgb;
#endif
#endif
    // glTF COLOR_0 multiplies the base colour (a factor of 1 without vertex colours: exact).
    o.g.albedo *= s.color.rgb;
#if EMISSION_TEXTURE
    o.emission = vec4(emission, 1.0);
#else
    o.emission = vec4(0.0);
#endif
#if SPECULAR_TEXTURE
    o.specular = vec4(dielectric_f0, 1.0);
#else
    o.specular = vec4(0.0);
#endif
#if MATERIAL_AUTO_R
    if (m.params.z < 0.0) {
        // A material without the thesis's explicit r (glTF files from other tools): it reflects
        // the share of light its GGX lobe does at this view angle, E = F0 A + B.
        float NoV = max(dot(o.g.normal, normalize(-s.view_position)), 0.0);
        vec2 ab = texture(u_specular_albedo, specular_albedo_uv(NoV, o.g.roughness)).rg;
#if SPECULAR_TEXTURE
        o.g.reflectivity = specular_reflectivity(mix(dielectric_f0, o.g.albedo, o.g.metallic), ab);
#else
        // surface_f0 (lib/material.glsl) of this material.
        o.g.reflectivity = specular_reflectivity(mix(m.dielectric_f0.rgb, o.g.albedo, o.g.metallic), ab);
#endif
    }
#endif
    return o;
}
