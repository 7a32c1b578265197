// Per-frame constants (uniform buffer binding 0). Mirrors cpp/render/frame_uniforms.h:
// change both together.
layout(std140, binding = 0) uniform FrameUniforms {
    mat4 view;            // world -> view
    mat4 inv_view;        // view -> world
    mat4 proj;            // view -> clip, in the frame's depth convention
    mat4 inv_proj;        // clip -> view
    mat4 view_to_shadow;  // view -> shadow-map texture space [0,1]^3
    vec4 viewport;        // (width, height, 1/width, 1/height) in pixels
    vec4 clip;            // (near, far, layers, light count)
    vec4 ambient;         // rgb constant ambient radiance
    vec4 shadow;          // (enabled, world size of a shadow texel, normal offset in texels, PCF radius)
    vec4 env_params;      // (type: 0 constant, 1 sky, 2 map; intensity; 0; 0)
    vec4 env_color;       // rgb constant environment radiance
    vec4 env_zenith;      // rgb sky radiance straight up
    vec4 env_horizon;     // rgb sky radiance at the horizon
    vec4 env_ground;      // rgb radiance below the horizon
    mat4 view_proj_unjittered;  // world -> clip without the TAA jitter (motion vectors)
    mat4 previous_view_proj;    // ... of the previous frame of the sequence (this frame's without one)
} frame;
