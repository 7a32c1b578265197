// A surface's G-buffer sample from its material (glTF metallic-roughness): factors times
// texture values. The caller samples the textures (the rasteriser with mipmaps, the
// reference tracer at level 0) and passes the texel values; unused ones may be anything.
// Needs scene_data.glsl, gbuffer.glsl, normal_mapping.glsl.

// glTF alphaMode MASK (BLEND tested alike at 0.5, Material::visibility_cutoff): the surface's
// alpha, base colour factor x texture alpha, below the material's cutoff makes the texel a hole
// (emissive.w < 0 for an opaque material). The rasterised passes discard it and the BVH
// traversals step through it, so the G-buffer, the shadow map and the reference agree.
// vertex_alpha: glTF COLOR_0's alpha, a factor of the base colour's (1 without vertex colours).
bool material_alpha_hole(MaterialData m, vec4 base_texel, float vertex_alpha) {
    float alpha = m.base_color.a * (m.flags.x != 0 ? base_texel.a : 1.0) * vertex_alpha;
    return m.emissive.w >= 0.0 && alpha < m.emissive.w;
}
bool material_alpha_hole(MaterialData m, vec4 base_texel) { return material_alpha_hole(m, base_texel, 1.0); }

// glTF emission: emissiveFactor x KHR_materials_emissive_strength (m.emissive.rgb), times the
// emissive texture's texel (sRGB decoded, as the base colour's) where the material has one.
vec3 material_emission(MaterialData m, vec4 emissive_texel) {
    return m.images.w >= 0 ? m.emissive.rgb * emissive_texel.rgb : m.emissive.rgb;
}

// KHR_materials_specular: a dielectric's F0 at a texel, min(((ior - 1) / (ior + 1))^2 x
// specularColorFactor x specularColorTexture.rgb (sRGB decoded), 1) x specularFactor x
// specularTexture.a; without either texture the factors' value the materials buffer holds
// (Material::dielectric_f0), so untextured materials keep their exact F0.
vec3 material_dielectric_f0(MaterialData m, vec4 specular_texel, vec4 specular_color_texel) {
    if (m.specular_images.x < 0 && m.specular_images.y < 0) return m.dielectric_f0.rgb;
    vec3 color = m.specular_f0.rgb;
    if (m.specular_images.y >= 0) color *= specular_color_texel.rgb;
    float specular = m.specular_f0.a;
    if (m.specular_images.x >= 0) specular *= specular_texel.a;
    return min(color, vec3(1.0)) * specular;
}

// n: interpolated unit normal (view space); t, b: tangent frame (valid when has_frame);
// front_facing: the camera sees the side the normal points to.
GSample material_sample(MaterialData m, vec4 base_texel, vec4 metallic_roughness_texel, vec3 normal_texel,
                        vec3 n, vec3 t, vec3 b, bool has_frame, bool front_facing, int object_id) {
    vec4 base = m.base_color;
    if (m.flags.x != 0) base *= base_texel;
    float metallic = m.params.x, roughness = m.params.y;
    if (m.flags.y != 0) {
        roughness *= metallic_roughness_texel.g;
        metallic *= metallic_roughness_texel.b;
    }
    // glTF doubleSided: a back face shows the other side of the surface.
    if (!front_facing && m.flags.w != 0) {
        n = -n;
        b = -b;
    }
    if (m.flags.z != 0 && has_frame) {
        vec3 tn = normal_texel * 2.0 - 1.0;
        tn.xy *= m.params.w;
        n = apply_normal_map(n, t, b, normalize(tn));
    }
    GSample g;
    g.albedo = base.rgb;
    g.metallic = clamp(metallic, 0.0, 1.0);
    g.normal = n;
    g.roughness = clamp(roughness, 0.0, 1.0);
    g.reflectivity = clamp(m.params.z, 0.0, 1.0);
    g.covered = true;
    g.object_id = object_id;
    return g;
}
