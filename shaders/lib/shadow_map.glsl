// shading.glsl's light_visibility() from the frame's shadow map: percentage-closer filtering
// of the directional light's shadow map at a view-space point, offset along its normal
// against acne, for the light that casts it; every other light is unshadowed.
// Needs frame_uniforms.glsl, lights.glsl; the including shader declares
//     layout(binding = N) uniform sampler2DShadow u_shadow_map;
// and defines SHADOWS (0 or 1).

#if SHADOWS
float shadow_visibility(vec3 p_view, vec3 n_view) {
    vec3 p = p_view + n_view * (frame.shadow.y * frame.shadow.z);  // texel size x offset in texels
    vec3 s = (frame.view_to_shadow * vec4(p, 1.0)).xyz;
    if (any(lessThan(s, vec3(0.0))) || any(greaterThan(s, vec3(1.0)))) return 1.0;
    int r = int(frame.shadow.w);
    vec2 texel = 1.0 / vec2(textureSize(u_shadow_map, 0));
    float lit = 0.0;
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x)
            lit += texture(u_shadow_map, vec3(s.xy + vec2(x, y) * texel, s.z));
    return lit / float((2 * r + 1) * (2 * r + 1));
}
#else
float shadow_visibility(vec3 p_view, vec3 n_view) { return 1.0; }
#endif

float light_visibility(LightData light, vec3 p_view, vec3 n_view, vec3 l_view, float light_distance) {
    return light.direction_shadow.w > 0.5 ? shadow_visibility(p_view, n_view) : 1.0;
}
