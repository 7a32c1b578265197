// The confidence test of a screen-space hit, for a fallback exact enough to replace
// a doubtful hit (passes/trace_bvh.comp: fallback "bvh").
// Needs frame_uniforms, depth_convention, gbuffer, and the including shader's samplers
// u_linear_depth, u_albedo, u_normal, u_material (the G-buffer's layers).
// A depth buffer cannot tell a surface
// from the volume behind it, so a screen-space tracer accepts any crossing of a layer's
// [depth, depth + thickness] slab; the G-buffer can still check that the hit is plausible:
//   1. the surface hit faces the ray (its normal against the ray's direction): a ray cannot
//      hit the back of a surface, so a back-facing "hit" passed behind or along it;
//   2. the ray really crosses the surface there: the ray is intersected with the plane of the
//      hit pixel's surface (its G-buffer position and normal), and that crossing must
//      project within CONFIDENCE_PIXELS of the hit and onto a pixel whose sample (same layer)
//      is the same object, lying on that plane within CONFIDENCE_PLANE pixel footprints. A
//      ray that passes behind a surface, inside its [depth, depth + thickness] slab, or
//      beside its edge crosses the plane outside the surface's own pixels. The test is in
//      pixels of the image itself, so at any resolution it asks for the sub-pixel agreement
//      a depth buffer can give (a test on the distance from the ray in pixel footprints
//      grows more lenient in world units as the image gets smaller: 2 footprints at 160x90
//      let rays 0.26 units behind hall's columns through);
//   3. the hit pixel's object and surface are its 4 neighbours' (same layer: same object id,
//      normals within CONFIDENCE_CREASE): at a silhouette the layer's depth jumps and at a
//      crease (a box's edge) the surface turns within the pixel, and a ray crossing there
//      may pass just beside the surface the pixel shows (sub-pixel geometry).
const float CONFIDENCE_PIXELS = 2.0;
const float CONFIDENCE_PLANE = 1.0;  // pixel footprints off the hit's plane
const float CONFIDENCE_CREASE = 0.9;  // cosine between the hit's normal and a neighbour's
bool screen_hit_confident(vec4 hit, vec3 origin, vec3 dir) {
    ivec2 size = ivec2(frame.viewport.xy);
    int layer = int(hit.z) - 1;
    ivec2 hp = clamp(ivec2(hit.xy), ivec2(0), size - 1);
    GSample h = gbuffer_decode(texelFetch(u_albedo, ivec3(hp, layer), 0), texelFetch(u_normal, ivec3(hp, layer), 0),
                               texelFetch(u_material, ivec3(hp, layer), 0));
    if (!h.covered || dot(h.normal, dir) >= 0.0) return false;
    float depth = texelFetch(u_linear_depth, ivec3(hp, layer), 0).r;
    vec3 hit_view = view_position(vec2(hp) + 0.5, depth);
    float facing = dot(dir, h.normal);  // < 0 (tested above)
    float t = dot(hit_view - origin, h.normal) / facing;
    if (!(t > 0.0)) return false;
    vec3 x = origin + t * dir;  // where the ray crosses the hit's plane
    if (!(x.z < 0.0)) return false;
    vec2 ndc = x.xy * vec2(frame.proj[0][0], frame.proj[1][1]) / -x.z - vec2(frame.proj[2][0], frame.proj[2][1]);
    vec2 q = (ndc * 0.5 + 0.5) * frame.viewport.xy;
    if (any(greaterThan(abs(q - (vec2(hp) + 0.5)), vec2(CONFIDENCE_PIXELS)))) return false;
    ivec2 qp = ivec2(floor(q));
    if (any(lessThan(qp, ivec2(0))) || any(greaterThanEqual(qp, size))) return false;
    GSample c = gbuffer_decode(texelFetch(u_albedo, ivec3(qp, layer), 0), texelFetch(u_normal, ivec3(qp, layer), 0),
                               texelFetch(u_material, ivec3(qp, layer), 0));
    if (!c.covered || c.object_id != h.object_id) return false;
    float cdepth = texelFetch(u_linear_depth, ivec3(qp, layer), 0).r;
    vec3 c_view = view_position(vec2(qp) + 0.5, cdepth);
    float footprint = 2.0 * cdepth / (frame.proj[1][1] * frame.viewport.y);  // one pixel, view units
    if (abs(dot(c_view - hit_view, h.normal)) > CONFIDENCE_PLANE * footprint) return false;
    const ivec2 nb[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    for (int i = 0; i < 4; ++i) {
        ivec2 q = clamp(hp + nb[i], ivec2(0), size - 1);
        GSample n = gbuffer_decode(texelFetch(u_albedo, ivec3(q, layer), 0), texelFetch(u_normal, ivec3(q, layer), 0),
                                   texelFetch(u_material, ivec3(q, layer), 0));
        if (n.object_id != h.object_id || dot(n.normal, h.normal) < CONFIDENCE_CREASE) return false;
    }
    return true;
}
