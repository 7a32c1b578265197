// Screen-space reflection settings: the SsrSettings uniform block (binding BUFFER_SSR_SETTINGS),
// read as ssr.<name>, and an int constant per value of each enum setting in it (SAMPLING_VNDF,
// NOISE_PCG, THICKNESS_MODE_RAY_STEP, REUSE_WEIGHTING_BRDF, CONE_REMAINDER_HIT, ...). Both are
// generated when the Renderer starts from cpp/render/settings_fields.def, where every setting's
// unit, range and meaning is declared once; ssrlab._core.ssr_settings_glsl() prints them.
#include "generated/ssr_settings_block.glsl"
