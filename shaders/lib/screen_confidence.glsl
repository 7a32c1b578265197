// The confidence test of a screen-space hit (issue 12), for a fallback exact enough to replace
// a doubtful hit (passes/trace_bvh.comp: fallback "bvh").
// Needs frame_uniforms, depth_convention, gbuffer, and the including shader's samplers
// u_linear_depth, u_albedo, u_normal, u_material (the G-buffer's layers).
// A depth buffer cannot tell a surface
// from the volume behind it, so a screen-space tracer accepts any crossing of a layer's
// [depth, depth + thickness] slab; the G-buffer can still check that the hit is plausible:
//   1. the surface hit faces the ray (its normal against the ray's direction): a ray cannot
//      hit the back of a surface, so a back-facing "hit" passed behind or along it;
//   2. the hit point lies on the ray: its distance from the ray's line is at most
//      CONFIDENCE_PIXELS pixel footprints at its depth (the crossing is found to within a
//      pixel; a hit accepted deep inside the thickness slab lies off the ray);
//   3. the hit pixel's object and surface are its 4 neighbours' (same layer: same object id,
//      normals within CONFIDENCE_CREASE): at a silhouette the layer's depth jumps and at a
//      crease (a box's edge) the surface turns within the pixel, and a ray crossing there
//      may pass just beside the surface the pixel shows (sub-pixel geometry).
const float CONFIDENCE_PIXELS = 2.0;
const float CONFIDENCE_CREASE = 0.9;  // cosine between the hit's normal and a neighbour's
bool screen_hit_confident(vec4 hit, vec3 origin, vec3 dir) {
    ivec2 size = ivec2(frame.viewport.xy);
    int layer = int(hit.z) - 1;
    ivec2 hp = clamp(ivec2(hit.xy), ivec2(0), size - 1);
    GSample h = gbuffer_decode(texelFetch(u_albedo, ivec3(hp, layer), 0), texelFetch(u_normal, ivec3(hp, layer), 0),
                               texelFetch(u_material, ivec3(hp, layer), 0));
    if (!h.covered || dot(h.normal, dir) >= 0.0) return false;
    float depth = texelFetch(u_linear_depth, ivec3(hp, layer), 0).r;
    vec3 hit_view = view_position(hit.xy, depth);
    float footprint = 2.0 * depth / (frame.proj[1][1] * frame.viewport.y);  // one pixel, view units
    if (length(cross(hit_view - origin, dir)) > CONFIDENCE_PIXELS * footprint) return false;
    const ivec2 nb[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    for (int i = 0; i < 4; ++i) {
        ivec2 q = clamp(hp + nb[i], ivec2(0), size - 1);
        GSample n = gbuffer_decode(texelFetch(u_albedo, ivec3(q, layer), 0), texelFetch(u_normal, ivec3(q, layer), 0),
                                   texelFetch(u_material, ivec3(q, layer), 0));
        if (n.object_id != h.object_id || dot(n.normal, h.normal) < CONFIDENCE_CREASE) return false;
    }
    return true;
}
