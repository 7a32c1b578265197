// Which depths may form the next layer behind a layer at window depth `previous`: strictly
// behind it (Everitt 2001's depth peeling), and with MIN_SEPARATION 1 also at least
// u_min_separation world units (view-space depth along the viewing axis) behind it: Mara,
// McGuire, Nowrouzezahrai and Luebke 2016's minimum separation, which skips the surfaces just
// behind a layer (the back of a thin wall, a decal, coplanar geometry) so that the next layer
// holds a surface the reflection rays can otherwise not see. Depth peeling's peel test
// (passes/depth_peel.frag) and the fragment lists' selection (passes/deep_gbuffer_select.comp)
// both ask this one function with the same two floats, so both constructions keep the same
// layers. Needs depth_convention.glsl.
#ifndef MIN_SEPARATION
#define MIN_SEPARATION 0
#endif

#if MIN_SEPARATION
uniform float u_min_separation;  // Settings.min_separation, world units, > 0
#endif

bool behind_layer(float z, float previous) {
#if MIN_SEPARATION
    // `precise`: no contraction that one shader might do and the other not.
    precise float threshold = linear_depth(previous) + u_min_separation;
    precise float here = linear_depth(z);
    return is_farther(z, previous) && here > threshold;
#else
    return is_farther(z, previous);
#endif
}
