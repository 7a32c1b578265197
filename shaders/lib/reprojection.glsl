// Reprojection: where a surface point seen in this frame was in the previous frame
// (seed 002, 4.6.5, Listing 4.9). The point's current view-space position, reconstructed from
// the G-buffer's depth, goes to the previous frame's clip space by VP_prev * V_curr^-1, the
// product the renderer forms in double precision; this equals the listing's
// VP_prev * VP_curr^-1 applied to the current clip-space position, without the precision a
// clip-space round trip loses. A point of an object that moved goes through the object's
// transforms as well (lib/object_motion.glsl). Pure function: the including pass supplies the
// matrix.

// Previous-frame window position (pixels, GL convention: origin bottom-left, pixel centres at
// .5) in .xy, and the point's positive view depth in the previous frame in .z (<= 0: the
// point was behind the previous camera).
vec3 reproject_to_previous(mat4 view_to_previous_clip, vec3 p_view, vec2 viewport) {
    vec4 c = view_to_previous_clip * vec4(p_view, 1.0);
    if (c.w <= 0.0) return vec3(-1.0, -1.0, c.w);
    return vec3((c.xy / c.w * 0.5 + 0.5) * viewport, c.w);
}

// Why a pixel's history was rejected (reprojection texture, .w); shared with
// python/ssrlab/renderer.py (Reprojection).
const float REPROJECT_VALID = 0.0;
const float REPROJECT_NO_HISTORY = 1.0;   // first frame of a sequence, or outside one
const float REPROJECT_NO_SURFACE = 2.0;   // the pixel shows no surface (the environment)
const float REPROJECT_OFFSCREEN = 3.0;    // the point lay outside the previous image
const float REPROJECT_DEPTH = 4.0;        // the previous frame there shows another surface
const float REPROJECT_NORMAL = 5.0;       // the previous normal there differs
const float REPROJECT_DISOCCLUDED = 6.0;  // the surface was there, behind layer 0 (reject_layers)
const float REPROJECT_REFLECTION = 7.0;   // the reflection there lay elsewhere (reprojection.reflection)
