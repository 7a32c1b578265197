// Screen-space reflection settings (uniform buffer binding 4, std140, scalars only so the
// layout is tight). Mirrors SsrUniforms in cpp/render/ssr_uniforms.h: change both together.
// Units and meanings are documented once, in python/ssrlab/settings.py.
layout(std140, binding = 4) uniform SsrSettings {
    int trace_width;         // pixels of the ray grid (the image divided by downscale)
    int trace_height;
    int downscale;           // 1, 2 or 4
    int rays_per_pixel;

    int sampling;            // SAMPLING_* below
    int noise;               // NOISE_* below
    int hammersley;          // 1: add a Hammersley point to the random numbers (seed 000, 2.3.4)
    uint seed;

    int layers;              // G-buffer layers the tracers test
    int max_steps;           // linear: steps; hiz: traversal iterations
    float stride;            // linear: pixels per step
    float jitter;            // linear: start offset, jitter * random * (stride - 1) pixels

    float max_distance;      // view-space length of a ray
    float origin_bias;       // origin offset along the normal, times the origin's view depth
    float thickness;         // view-space thickness of every depth sample
    float thickness_scale;   // THICKNESS_RAY_STEP: thickness = max(thickness, scale * ray depth step)

    int thickness_mode;      // THICKNESS_*
    int refine_steps;        // binary-search refinement steps after a linear hit
    int hiz_start_level;
    int hiz_stop_level;

    int hiz_max_level;
    int hiz_linear_steps;    // linear steps before the Hi-Z traversal (seed 002, 4.7.1)
    int hiz_use_max;         // 1: travel behind surfaces with the max pyramid (seed 002, 4.6.6)
    float hiz_crossing_offset;  // pixels past a cell boundary when crossing it

    float fade_border;       // fraction of the image (its smaller side) over which hits fade at the border
    float fade_camera_start; // cos(angle) between a ray and the direction to the camera where fading starts
    float fade_camera_end;   // ... and where it is complete
    float fade_distance_start;  // view-space travel distance where fading starts (<= 0: off)

    float fade_distance_end;
    float roughness_cutoff;  // pixels rougher than this are not traced (seed 003's threshold)
    float edge_depth_sigma;  // edge-aware reuse: relative depth difference scale
    float edge_normal_power; // edge-aware reuse: exponent on the normals' cosine

    int reuse_radius;        // 0, 1 or 2 (1: the thesis's 3x3)
    int reuse_weighting;     // REUSE_*
    int edge_aware;          // 1: depth- and normal-aware reuse and upsampling
    int cone_max_samples;    // in-circles marched per cone (seed 002, 4.4.5)

    float cone_level_bias;   // mip levels added to every cone / blur_mips fetch
    int cone_remainder;      // CONE_REMAINDER_*: what fills a cone whose weights stay below 1
    int cone_stretch;        // 1: footprints stretched along the ray at grazing angles (seed 002, 4.6.8)
    int pad0;
} ssr;

const int SAMPLING_MIRROR = 0;
const int SAMPLING_GGX = 1;                 // thesis 2.3.2 theta/phi formulas: GGX normals, pdf D(m)(m.n)
const int SAMPLING_VNDF = 2;                // Heitz 2018: GGX visible normals
const int SAMPLING_GGX_THESIS_LITERAL = 3;  // thesis 2.3.2 vector (.., 1 - cos(theta)) added to n (biased)

const int NOISE_PCG = 0;
const int NOISE_THESIS_HASH = 1;

const int THICKNESS_CONSTANT = 0;
const int THICKNESS_RAY_STEP = 1;

const int REUSE_THESIS = 0;  // neighbour rays keep their own weights (seed 000, 2.4.1)
const int REUSE_BRDF = 1;    // receiver's BRDF over the neighbour's pdf (Stachowiak 2015)

const int COMPOSITE_LINEAR = 0;  // c = r c_r + (1 - r) c_d (seed 000, 2.4.2)
const int COMPOSITE_PBR = 1;     // c = c_d + r F_schlick(n.v) c_r

const int GLOSSY_STOCHASTIC = 0;  // GGX/VNDF rays + resolve (seed 000)
const int GLOSSY_CONE = 1;        // Hi-Z cone tracing (seed 002, 4.4.5)
const int GLOSSY_BLUR_MIPS = 2;   // one ray, one pre-convolved mip fetch (seed 004)

const int CONE_REMAINDER_HIT = 0;          // the colour of the circle at the hit
const int CONE_REMAINDER_ENVIRONMENT = 1;  // the environment (seed 002, 4.4.5)
