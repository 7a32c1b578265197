// The environment: what a pixel with no surface, or a reflection ray that leaves the screen,
// sees (seed 004's last fallback level, the "global cubemap"). A constant colour, a
// procedural sky, or an equirectangular map. Needs frame_uniforms.glsl; a shader that uses
// maps defines ENVIRONMENT_MAP 1 and binds u_environment_map.

#ifndef ENVIRONMENT_MAP
#define ENVIRONMENT_MAP 0
#endif

#if ENVIRONMENT_MAP
// Texture unit 15 is kept for the environment map in every pass.
layout(binding = 15) uniform sampler2D u_environment_map;  // equirectangular, u = longitude, v = 0 at the zenith
#endif

// Radiance arriving from world-space direction `dir` (unit length).
vec3 environment_radiance(vec3 dir) {
    int type = int(frame.env_params.x);
    vec3 c = frame.env_color.rgb;
    if (type == 1) {
        // A gradient sky: horizon to zenith above, horizon to ground below, with a soft
        // transition at the horizon.
        float y = clamp(dir.y, -1.0, 1.0);
        c = y >= 0.0 ? mix(frame.env_horizon.rgb, frame.env_zenith.rgb, sqrt(y))
                     : mix(frame.env_horizon.rgb, frame.env_ground.rgb, sqrt(min(-y * 4.0, 1.0)));
    }
#if ENVIRONMENT_MAP
    else if (type == 2) {
        const float PI_ = 3.14159265358979;
        float u = 0.5 + atan(dir.x, -dir.z) / (2.0 * PI_);
        float v = acos(clamp(dir.y, -1.0, 1.0)) / PI_;
        c = textureLod(u_environment_map, vec2(u, v), 0.0).rgb;
    }
#endif
    return c * frame.env_params.y;
}
