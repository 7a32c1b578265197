// Whether a screen-space ray stays in the G-buffer's sight: the march of a tracer that hands
// the rays it cannot vouch for to an exact fallback (STOP_UNSEEN: fallback "bvh" with
// fallback_confidence, passes/trace_linear.comp and lib/hiz_walk.glsl). A depth buffer holds
// the nearest surfaces along each pixel centre's view ray and nothing of what lies behind
// them; a ray that travels through space it does not show may meet a surface there (the
// underside of a sphere, the back of a box) and find a hit farther on that is not the one it
// meets. The ray is lost from sight, and the march ends as a miss for the fallback, where
//   1. it lies behind a surface's slab [d, d + thickness] (the thickness is a guess about what
//      is behind a surface, not knowledge): behind the last layer the peeling kept, or, with
//      deep layers, behind a layer that faces the camera (inside its object). Behind a layer
//      that faces away and in front of the next one the space is known empty;
//   2. a surface's edge may lie on its way between two samples, which no sample shows:
//      a. along the march, the sample lies behind the previous sample's surface continued to
//         it (1/z is affine in screen space, so a plane continues exactly: a convex crease or
//         a silhouette lies between them) and the ray reaches behind that continuation;
//      b. across it, the neighbouring pixel the ray passes nearer to (the other one of the two
//         its half-pixel-wide footprint straddles) shows a surface nearer than this one by
//         more than the thickness (a silhouette beside the ray), and the ray reaches its depth.
// The linear march (passes/trace_linear.comp) keeps rule 2's chain of samples (sight_step). The
// Hi-Z walk (lib/hiz_walk.glsl) skips whole cells, and a chain broken at each coarse step let
// rays pass a box's crease or a sphere's silhouette between two samples unseen; it reads the
// sight map instead, which hiz_build writes with the pyramid (passes/hiz_build.comp, HIZ_SIGHT):
// per pixel and layer, the hull of the slabs [e, e + thickness] of the surfaces beside the pixel
// that may reach into it at depth e in front of its sample, whichever way the ray comes: rule 2a
// toward each of its 4 neighbours (the neighbour's surface, known to run on from the pixels beyond
// it, continued to the pixel), rule 2b where the neighbour's surface is not known to run on (a
// nearer sample, by more than the thickness), none where the pixel and its neighbour lie on one
// surface (however steeply it recedes) or the neighbour's surface turns away behind the pixel's (a
// floor running under a wall). A level-0 step in front of its sample whose depths reach into that
// hull is lost; the pyramid's min is the sight map's, so a coarse cell the walk skips holds no
// such edge.
// What is left is what the confidence test of the hit can check (lib/screen_confidence.glsl).
// Needs frame_uniforms. Depths are positive view depths.

// Fraction of a pixel footprint by which a sample must lie behind the previous surface's
// continuation to count as an edge (depth rounding on a plane stays far below it).
const float SIGHT_EDGE = 0.05;

struct Sight {
    float prev_w;   // 1 / depth of the previous sample (0: none yet)
    float slope_w;  // its change from the sample before
    bool smooth_;   // the previous two samples lie on one surface (within the thickness)
    bool lost;
};

Sight sight_start() {
    Sight s;
    s.prev_w = 0.0;
    s.slope_w = 0.0;
    s.smooth_ = false;
    s.lost = false;
    return s;
}

// One sample of the march: the ray covers view depths [lo, hi] there; d is the depth of the
// nearest surface at or beyond the ray at the sample (the far plane where there is none),
// `behind` whether the ray has passed behind a surface there (rule 1), d_side the same layer's
// depth at the neighbouring pixel across the march.
void sight_step(inout Sight s, float lo, float hi, float d, bool behind, float d_side, float thick) {
    float w = 1.0 / d;
    float ext_w = s.prev_w + s.slope_w;
    float tol = SIGHT_EDGE * 2.0 * d / (frame.proj[1][1] * frame.viewport.y);
    bool edge = s.smooth_ && ext_w > 0.0 && 1.0 / ext_w < d - tol;
    s.lost = s.lost || behind || (edge && hi < d && hi * ext_w >= 1.0) || (d_side < d - thick && hi >= d_side);
    s.smooth_ = s.prev_w > 0.0 && abs(d - 1.0 / s.prev_w) <= thick;
    s.slope_w = w - s.prev_w;
    s.prev_w = w;
}
