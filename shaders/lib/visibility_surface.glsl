// A visibility sample's surface, rebuilt from its triangle and the pixel's primary ray (Burns and
// Hunt 2013): the vertices of the triangle in view space, exactly as the geometry pass's vertex
// stage transforms them (passes/depth_peel.vert), the ray's barycentrics on the triangle's plane
// (Möller and Trumbore 1997), and the vertex attributes interpolated with them. The ray through a
// pixel's centre meets the triangle where the rasteriser's perspective-correct interpolation puts
// that pixel, so the attributes equal the raster's up to rounding. Texture derivatives come from
// the rays of the pixel's 2x2 quad on the same plane (Igehy 1999's ray differentials, taken one
// pixel apart), the differences a fragment shader's dFdx and dFdy take.
// What every sample of a triangle shares (its view-space vertices and vertex normals) is computed
// once a frame per triangle into a record (visibility_record_texels), which its samples read
// (visibility_read_record): a sample then reads 5 texels instead of its object's transforms, three
// indices and six vertex reads, and transforms nothing.
// Needs frame_uniforms, depth_convention, scene_data. The including shader says how the scene's
// vertex and index data (lib/scene_geometry.glsl's layout: GpuVertex, 18 floats a vertex) are read:
// VISIBILITY_INDEX(i) the i-th index, VISIBILITY_VERTEX2(i) floats i and i + 1 of the vertex data
// (i even: a vertex starts at an even float, so the CPU device reads the floats in pairs, half the
// image loads; 18 floats are no whole number of vec4); and the records: VISIBILITY_RECORD(i) their
// i-th texel (a vec4).

struct VisibilityTriangle {
    vec3 p0, p1, p2;   // view-space positions
    vec3 e1, e2;       // p1 - p0, p2 - p0
    vec3 q0, q1, q2;   // object-space positions
};

// Vertex k of the object's triangle; `entry` is the object's ObjectData.material (y its mesh's first
// index, z its base vertex).
uint visibility_vertex(ivec4 entry, int triangle, int k) {
    return VISIBILITY_INDEX(uint(entry.y) + uint(3 * triangle + k)) + uint(entry.z);
}

vec3 visibility_object_position(uint v) {
    uint f = v * 18u;
    return vec3(VISIBILITY_VERTEX2(f), VISIBILITY_VERTEX2(f + 2u).x);
}

VisibilityTriangle visibility_triangle(ObjectData o, int triangle) {
    VisibilityTriangle t;
    t.q0 = visibility_object_position(visibility_vertex(o.material, triangle, 0));
    t.q1 = visibility_object_position(visibility_vertex(o.material, triangle, 1));
    t.q2 = visibility_object_position(visibility_vertex(o.material, triangle, 2));
    t.p0 = (frame.view * (o.model * vec4(t.q0, 1.0))).xyz;
    t.p1 = (frame.view * (o.model * vec4(t.q1, 1.0))).xyz;
    t.p2 = (frame.view * (o.model * vec4(t.q2, 1.0))).xyz;
    t.e1 = t.p1 - t.p0;
    t.e2 = t.p2 - t.p0;
    return t;
}

// Vertex v's normal in view space, as the geometry pass's vertex stage outputs it.
vec3 visibility_vertex_normal(ObjectData o, uint v) {
    uint f = v * 18u;
    vec3 n = vec3(VISIBILITY_VERTEX2(f + 2u).y, VISIBILITY_VERTEX2(f + 4u));
    return mat3(frame.view) * (mat3(o.normal_matrix) * n);
}

// A triangle's record, 5 texels: (p0, n0.x), (p1, n0.y), (p2, n0.z), (n1, n2.x), (n2.yz, 0, 0).
const int VISIBILITY_RECORD_TEXELS = 5;
void visibility_record_texels(VisibilityTriangle t, vec3 n0, vec3 n1, vec3 n2, out vec4 r[VISIBILITY_RECORD_TEXELS]) {
    r[0] = vec4(t.p0, n0.x);
    r[1] = vec4(t.p1, n0.y);
    r[2] = vec4(t.p2, n0.z);
    r[3] = vec4(n1, n2.x);
    r[4] = vec4(n2.yz, 0.0, 0.0);
}
// Record i's triangle (view space; no object-space positions) and vertex normals.
VisibilityTriangle visibility_read_record(int i, out vec3 n0, out vec3 n1, out vec3 n2) {
    int b = VISIBILITY_RECORD_TEXELS * i;
    vec4 r0 = VISIBILITY_RECORD(b), r1 = VISIBILITY_RECORD(b + 1), r2 = VISIBILITY_RECORD(b + 2),
         r3 = VISIBILITY_RECORD(b + 3), r4 = VISIBILITY_RECORD(b + 4);
    VisibilityTriangle t;
    t.p0 = r0.xyz;
    t.p1 = r1.xyz;
    t.p2 = r2.xyz;
    t.e1 = t.p1 - t.p0;
    t.e2 = t.p2 - t.p0;
    t.q0 = t.q1 = t.q2 = vec3(0.0);
    n0 = vec3(r0.w, r1.w, r2.w);
    n1 = r3.xyz;
    n2 = vec3(r3.w, r4.xy);
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

// The vertex attributes the geometry pass's vertex stage outputs, per vertex (view space), besides
// the position and normal a triangle's record holds.
struct VisibilityVertex {
    vec4 uv;       // xy TEXCOORD_0, zw TEXCOORD_1
    vec4 tangent;  // w bitangent sign
    vec4 color;
};

VisibilityVertex visibility_vertex_attributes(ObjectData o, uint v) {
    uint f = v * 18u;
    VisibilityVertex a;
    a.uv = vec4(VISIBILITY_VERTEX2(f + 6u), VISIBILITY_VERTEX2(f + 16u));
    vec4 t = vec4(VISIBILITY_VERTEX2(f + 8u), VISIBILITY_VERTEX2(f + 10u));
    a.tangent = vec4(mat3(frame.view) * (mat3(o.model) * t.xyz), t.w);
    a.color = vec4(VISIBILITY_VERTEX2(f + 12u), VISIBILITY_VERTEX2(f + 14u));
    return a;
}
