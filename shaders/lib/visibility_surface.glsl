// A visibility sample's surface, rebuilt from its triangle and the pixel's primary ray (Burns and
// Hunt 2013): the vertices of the triangle in view space, exactly as the geometry pass's vertex
// stage transforms them (passes/depth_peel.vert), the ray's barycentrics on the triangle's plane
// (Möller and Trumbore 1997), and the vertex attributes interpolated with them. The ray through a
// pixel's centre meets the triangle where the rasteriser's perspective-correct interpolation puts
// that pixel, so the attributes equal the raster's up to rounding. Texture derivatives come from
// the rays of the pixel's 2x2 quad on the same plane (Igehy 1999's ray differentials, taken one
// pixel apart), the differences a fragment shader's dFdx and dFdy take.
// Needs frame_uniforms, depth_convention, scene_data. The including shader says how the scene's
// vertex and index data (lib/scene_geometry.glsl's layout: GpuVertex, 18 floats a vertex) are read:
// VISIBILITY_INDEX(i) the i-th index, VISIBILITY_VERTEX2(i) floats i and i + 1 of the vertex data
// (i even: a vertex starts at an even float, so the CPU device reads the floats in pairs, half the
// image loads; 18 floats are no whole number of vec4).

struct VisibilityTriangle {
    vec3 p0, p1, p2;   // view-space positions
    vec3 e1, e2;       // p1 - p0, p2 - p0
    vec3 q0, q1, q2;   // object-space positions
};

uint visibility_vertex(ObjectData o, int triangle, int k) {
    return VISIBILITY_INDEX(uint(o.material.y) + uint(3 * triangle + k)) + uint(o.material.z);
}

vec3 visibility_object_position(uint v) {
    uint f = v * 18u;
    return vec3(VISIBILITY_VERTEX2(f), VISIBILITY_VERTEX2(f + 2u).x);
}

VisibilityTriangle visibility_triangle(ObjectData o, int triangle) {
    VisibilityTriangle t;
    t.q0 = visibility_object_position(visibility_vertex(o, triangle, 0));
    t.q1 = visibility_object_position(visibility_vertex(o, triangle, 1));
    t.q2 = visibility_object_position(visibility_vertex(o, triangle, 2));
    t.p0 = (frame.view * (o.model * vec4(t.q0, 1.0))).xyz;
    t.p1 = (frame.view * (o.model * vec4(t.q1, 1.0))).xyz;
    t.p2 = (frame.view * (o.model * vec4(t.q2, 1.0))).xyz;
    t.e1 = t.p1 - t.p0;
    t.e2 = t.p2 - t.p0;
    return t;
}

// The view-space direction of the primary ray through window position `pixel` (pixel centres at
// .5), through the frame's projection (a TAA jitter included): view depth 1 along it.
vec3 visibility_ray(vec2 pixel) {
    return view_position(pixel, 1.0);
}

// Barycentrics (b0, b1, b2) of where the ray from the eye along `d` meets the triangle's plane,
// outside the triangle too (a quad's neighbour may lie beyond its edge, as a helper invocation does).
vec3 visibility_barycentrics(VisibilityTriangle t, vec3 d) {
    vec3 pv = cross(d, t.e2);
    float inv = 1.0 / dot(t.e1, pv);
    vec3 s = -t.p0;
    float b1 = dot(s, pv) * inv;
    float b2 = dot(d, cross(s, t.e1)) * inv;
    return vec3(1.0 - b1 - b2, b1, b2);
}

// Whether the eye sees the triangle's counter-clockwise side (glTF fronts are counter-clockwise):
// its geometric normal points back along the view ray, as the rasteriser's window-space winding says.
bool visibility_front_facing(VisibilityTriangle t) {
    return dot(cross(t.e1, t.e2), t.p0) < 0.0;
}

vec3 visibility_interpolate(vec3 b, vec3 a0, vec3 a1, vec3 a2) { return b.x * a0 + b.y * a1 + b.z * a2; }
vec4 visibility_interpolate(vec3 b, vec4 a0, vec4 a1, vec4 a2) { return b.x * a0 + b.y * a1 + b.z * a2; }

// The vertex attributes the geometry pass's vertex stage outputs, per vertex (view space).
struct VisibilityVertex {
    vec3 normal;
    vec4 uv;       // xy TEXCOORD_0, zw TEXCOORD_1
    vec4 tangent;  // w bitangent sign
    vec4 color;
};

VisibilityVertex visibility_vertex_attributes(ObjectData o, uint v) {
    uint f = v * 18u;
    VisibilityVertex a;
    vec3 n = vec3(VISIBILITY_VERTEX2(f + 2u).y, VISIBILITY_VERTEX2(f + 4u));
    a.normal = mat3(frame.view) * (mat3(o.normal_matrix) * n);
    a.uv = vec4(VISIBILITY_VERTEX2(f + 6u), VISIBILITY_VERTEX2(f + 16u));
    vec4 t = vec4(VISIBILITY_VERTEX2(f + 8u), VISIBILITY_VERTEX2(f + 10u));
    a.tangent = vec4(mat3(frame.view) * (mat3(o.model) * t.xyz), t.w);
    a.color = vec4(VISIBILITY_VERTEX2(f + 12u), VISIBILITY_VERTEX2(f + 14u));
    return a;
}
