// The environment: what a pixel with no surface, or a reflection ray that leaves the screen,
// sees (seed 004's last fallback level, the "global cubemap"). A constant colour, a
// procedural sky, or an equirectangular map. Needs frame_uniforms.glsl; a shader that uses
// maps defines ENVIRONMENT_MAP 1 and binds u_environment_map.

#ifndef ENVIRONMENT_MAP
#define ENVIRONMENT_MAP 0
#endif

#if ENVIRONMENT_MAP
// The environment map's unit is kept for it in every pass (frame_texture_units, passes/compute.h).
layout(binding = TEXTURE_ENVIRONMENT_MAP) uniform sampler2D u_environment_map;  // equirectangular, u = longitude, v = 0 at the zenith
#endif

// The scene's type compiled in (0 constant, 1 sky, 2 map; the renderer defines it for every
// pass); -1: chosen at run time from frame.env_params.x.
#ifndef ENVIRONMENT_TYPE
#define ENVIRONMENT_TYPE -1
#endif

// A gradient sky at world-space height y of a unit direction: horizon to zenith above, horizon
// to ground below, with a soft transition at the horizon.
vec3 sky_gradient(float y) {
    y = clamp(y, -1.0, 1.0);
    return y >= 0.0 ? mix(frame.env_horizon.rgb, frame.env_zenith.rgb, sqrt(y))
                    : mix(frame.env_horizon.rgb, frame.env_ground.rgb, sqrt(min(-y * 4.0, 1.0)));
}

// Radiance arriving from world-space direction `dir` (unit length).
vec3 environment_radiance(vec3 dir) {
#if ENVIRONMENT_TYPE == 0
    return frame.env_color.rgb * frame.env_params.y;
#elif ENVIRONMENT_TYPE == 1
    return sky_gradient(dir.y) * frame.env_params.y;
#else
    int type = int(frame.env_params.x);
    vec3 c = frame.env_color.rgb;
    if (type == 1) {
        c = sky_gradient(dir.y);
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
#endif
}

// The same from a view-space direction of any length: the background a camera ray sees. With the
// type compiled in, the constant needs no direction and the sky only the world-space height of
// the unit direction (on llvmpipe the composite's background, run for covered pixels
// too, was half the pass).
vec3 environment_radiance_view(vec3 d_view) {
#if ENVIRONMENT_TYPE == 0
    return frame.env_color.rgb * frame.env_params.y;
#elif ENVIRONMENT_TYPE == 1
    vec3 world_up_row = vec3(frame.inv_view[0].y, frame.inv_view[1].y, frame.inv_view[2].y);
    return sky_gradient(dot(world_up_row, d_view) * inversesqrt(dot(d_view, d_view))) * frame.env_params.y;
#else
    return environment_radiance(normalize(mat3(frame.inv_view) * d_view));
#endif
}
