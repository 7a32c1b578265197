// Direct lighting of a surface point: Lambert diffuse + GGX specular for every punctual
// light, each light's visibility, and a constant ambient term.
// This is the one shading function of the project: the lighting pass shades every
// G-buffer layer with it, and ground-truth reflections shade their hit points with it, so
// the two differ only in which points they see.
//
// The including shader defines how much of a light reaches the point (the frame's shadow
// map in lib/shadow_map.glsl; a traced shadow ray in the reference pass):
//     float light_visibility(LightData light, vec3 p_view, vec3 n_view, vec3 l_view, float light_distance);
// Needs frame_uniforms.glsl, scene_data.glsl, brdf.glsl, lights.glsl, gbuffer.glsl.

float light_visibility(LightData light, vec3 p_view, vec3 n_view, vec3 l_view, float light_distance);

// p: view-space position, v: unit vector from p toward the viewer; emission: the radiance the
// surface emits (glTF emission, lib/material.glsl's material_emission at the surface's texture
// coordinates, or lib/gbuffer_emission.glsl's for a G-buffer sample); dielectric_f0: the
// non-metal part's F0 (lib/material.glsl's material_dielectric_f0 at the surface's texture
// coordinates, or lib/gbuffer_specular.glsl's for a G-buffer sample).
vec3 shade_surface(GSample g, vec3 emission, vec3 dielectric_f0, vec3 p, vec3 v) {
    vec3 n = g.normal;
    float NoV = max(dot(n, v), 1e-4);
    float alpha = ggx_alpha(g.roughness);
    vec3 F0 = mix(dielectric_f0, g.albedo, g.metallic);  // glTF metallic workflow
    vec3 diffuse_color = g.albedo * (1.0 - g.metallic);
    vec3 radiance = frame.ambient.rgb * g.albedo;
    // glTF emission leaves the surface whatever lights it.
    radiance += emission;

    int count = LIGHTS_IN_FRAME;
    for (int i = 0; i < count; ++i) {
        LightData light = LIGHT_AT(i);
        vec3 l;
        vec3 irradiance = light.radiance.rgb;
        float light_distance = 3.4e38;  // a directional light: no end
        if (light.position_type.w == 0.0) {
            l = -normalize(light.direction_shadow.xyz);
        } else {
            vec3 to_light = light.position_type.xyz - p;
            float d2 = max(dot(to_light, to_light), 1e-8);
            l = to_light * inversesqrt(d2);
            light_distance = sqrt(d2);
            irradiance /= d2;  // inverse-square falloff of a point light's intensity
            // KHR_lights_punctual's recommended range window, clamp(1 - (d / range)^4, 0, 1)^2.
            float w = clamp(1.0 - d2 * d2 * light.cone.z * light.cone.z, 0.0, 1.0);
            // Its recommended spot falloff: clamp(cos(angle to the axis) * scale + offset, 0, 1)^2
            float spot = 1.0;
            if (light.position_type.w == 2.0)
                spot = clamp(dot(normalize(light.direction_shadow.xyz), -l) * light.cone.x + light.cone.y, 0.0, 1.0);
            irradiance *= w * w * spot * spot;
        }
        float NoL = dot(n, l);
        if (NoL <= 0.0) continue;
        float visibility = light_visibility(light, p, n, l, light_distance);
        if (visibility <= 0.0) continue;
        irradiance *= visibility;
        vec3 h = normalize(l + v);
        float NoH = max(dot(n, h), 0.0);
        float VoH = max(dot(v, h), 0.0);
        vec3 F = fresnel_schlick(F0, VoH);
        vec3 specular = F * (ggx_D(NoH, alpha) * ggx_G(NoL, NoV, alpha) / (4.0 * NoL * NoV));
        vec3 diffuse = (1.0 - F) * diffuse_color / PI;
        radiance += (diffuse + specular) * irradiance * NoL;
    }
    return radiance;
}
