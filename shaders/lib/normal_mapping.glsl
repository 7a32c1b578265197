// Tangent-space normal mapping. With per-vertex tangents (glTF TANGENT) the frame is
// (T, B = sign * N x T, N); without them the frame comes from screen-space derivatives of
// position and uv (a cotangent frame, as in Schüler, "Normal Mapping without Precomputed
// Tangents", ShaderX5), which needs no preprocessing.

vec3 perturb_normal(vec3 n, vec4 tangent, vec3 p, vec2 uv, vec3 tangent_space_normal) {
    mat3 tbn;
    if (dot(tangent.xyz, tangent.xyz) > 1e-12 && tangent.w != 0.0) {
        vec3 t = normalize(tangent.xyz - n * dot(n, tangent.xyz));
        vec3 b = cross(n, t) * tangent.w;
        tbn = mat3(t, b, n);
    } else {
        vec3 dp1 = dFdx(p), dp2 = dFdy(p);
        vec2 duv1 = dFdx(uv), duv2 = dFdy(uv);
        vec3 dp2perp = cross(dp2, n), dp1perp = cross(n, dp1);
        vec3 t = dp2perp * duv1.x + dp1perp * duv2.x;
        vec3 b = dp2perp * duv1.y + dp1perp * duv2.y;
        float scale = max(dot(t, t), dot(b, b));
        if (scale < 1e-20) return n;  // degenerate uv mapping: keep the surface normal
        float inv = inversesqrt(scale);
        tbn = mat3(t * inv, b * inv, n);
    }
    vec3 result = tbn * tangent_space_normal;
    float len = length(result);
    return len > 1e-8 ? result / len : n;
}
