// Tangent-space normal mapping. The tangent frame comes from per-vertex tangents (glTF
// TANGENT: T, B = sign * N x T), from screen-space derivatives of position and uv (a
// cotangent frame, Schüler, ShaderX5; fragment shaders only), or from a triangle's own
// positions and uvs (the reference tracer). Applying the map is the same for all three.

// Frame from a vertex tangent (w = bitangent sign); false when the mesh has none. The vertex
// tangents are the directions of the mesh's u and v (dP/du, dP/dv); the normal texture is read
// at KHR_texture_transform's u' = L u + offset (`uv_linear` = L), so its axes are dP/du' and
// dP/dv', the columns of (T B) L^-1: a rotated texture turns its frame with it.
bool tangent_frame_from_vertex(vec3 n, vec4 tangent, mat2 uv_linear, out vec3 t, out vec3 b) {
    t = vec3(1.0, 0.0, 0.0);
    b = vec3(0.0, 1.0, 0.0);
    if (dot(tangent.xyz, tangent.xyz) <= 1e-12 || tangent.w == 0.0) return false;
    t = normalize(tangent.xyz - n * dot(n, tangent.xyz));
    b = cross(n, t) * tangent.w;
    float det = determinant(uv_linear);
    if (uv_linear != mat2(1.0) && abs(det) > 1e-12) {
        mat2 inv = inverse(uv_linear);
        vec3 tu = t * inv[0][0] + b * inv[0][1], tv = t * inv[1][0] + b * inv[1][1];
        t = normalize(tu);
        b = normalize(tv);
    }
    return true;
}

// Frame from how position and uv change across a surface (edge vectors dp1, dp2 with uv
// changes duv1, duv2): screen derivatives in a fragment shader, triangle edges elsewhere.
bool tangent_frame_from_gradients(vec3 n, vec3 dp1, vec3 dp2, vec2 duv1, vec2 duv2, out vec3 t, out vec3 b) {
    vec3 dp2perp = cross(dp2, n), dp1perp = cross(n, dp1);
    t = dp2perp * duv1.x + dp1perp * duv2.x;
    b = dp2perp * duv1.y + dp1perp * duv2.y;
    float scale = max(dot(t, t), dot(b, b));
    if (scale < 1e-20) return false;  // degenerate uv mapping: keep the surface normal
    float inv = inversesqrt(scale);
    t *= inv;
    b *= inv;
    return true;
}

// The perturbed normal for a tangent-space normal-map value (already unpacked to [-1, 1]
// and scaled).
vec3 apply_normal_map(vec3 n, vec3 t, vec3 b, vec3 tangent_space_normal) {
    vec3 result = mat3(t, b, n) * tangent_space_normal;
    float len = length(result);
    return len > 1e-8 ? result / len : n;
}
