// Vertex attributes of any triangle of the scene, read from the renderer's vertex and index
// buffers (GpuVertex in cpp/render/gpu_scene.h: 18 floats per vertex, position, normal, uv,
// tangent, colour, uv1). Objects carry their mesh's first index and base vertex (scene_data.glsl).

layout(std430, binding = BUFFER_VERTEX_DATA) readonly buffer VertexData { float vertex_data[]; };
layout(std430, binding = BUFFER_INDEX_DATA) readonly buffer IndexData { uint index_data[]; };

struct SurfaceAttributes {
    vec3 normal;   // object space, interpolated
    vec4 uv;       // xy: TEXCOORD_0, zw: TEXCOORD_1 (texture_uv picks a texture's set)
    vec4 tangent;  // object space, interpolated; w sign; 0 when the mesh has none
    vec4 color;    // glTF COLOR_0, interpolated (white without)
    vec3 p0, p1, p2;  // object-space positions
    vec4 uv0, uv1, uv2;  // the vertices' two sets
};

SurfaceAttributes triangle_attributes(ObjectData o, int triangle, float b1, float b2) {
    SurfaceAttributes s;
    float b0 = 1.0 - b1 - b2;
    vec3 n = vec3(0.0);
    vec4 t = vec4(0.0);
    vec4 uv = vec4(0.0);
    vec4 c[3];
    for (int k = 0; k < 3; ++k) {
        uint v = index_data[uint(o.material.y) + uint(3 * triangle + k)] + uint(o.material.z);
        uint f = v * 18u;
        vec3 p = vec3(vertex_data[f], vertex_data[f + 1u], vertex_data[f + 2u]);
        vec3 vn = vec3(vertex_data[f + 3u], vertex_data[f + 4u], vertex_data[f + 5u]);
        vec4 vuv = vec4(vertex_data[f + 6u], vertex_data[f + 7u], vertex_data[f + 16u], vertex_data[f + 17u]);
        vec4 vt = vec4(vertex_data[f + 8u], vertex_data[f + 9u], vertex_data[f + 10u], vertex_data[f + 11u]);
        vec4 vc = vec4(vertex_data[f + 12u], vertex_data[f + 13u], vertex_data[f + 14u], vertex_data[f + 15u]);
        float w = k == 0 ? b0 : (k == 1 ? b1 : b2);
        n += w * vn;
        uv += w * vuv;
        t += w * vt;
        c[k] = vc;
        if (k == 0) { s.p0 = p; s.uv0 = vuv; }
        if (k == 1) { s.p1 = p; s.uv1 = vuv; }
        if (k == 2) { s.p2 = p; s.uv2 = vuv; }
    }
    s.normal = n;
    s.uv = uv;
    // From vertex 0 along the edges: exact where the colour is the same at all three (white
    // without COLOR_0), so an uncoloured mesh's base colour is multiplied by exactly 1.
    s.color = c[0] + b1 * (c[1] - c[0]) + b2 * (c[2] - c[0]);
    s.tangent = vec4(t.xyz, t.w >= 0.0 ? (t.w > 0.0 ? 1.0 : 0.0) : -1.0);
    return s;
}
