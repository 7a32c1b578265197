// The part of a trace pass that does not depend on the tracer: the ray of a trace pixel
// from the G-buffer, and the outputs every tracer writes.
//   rays.hit       RGBA32F: hit position (level-0 pixels, GL orientation), hit layer
//                  (1-based, 0 = miss, as the thesis stores it), fade
//   rays.sample    RGBA32F: weight, pdf, depth fetches spent, 1 if the pixel traced rays
//   rays.direction RGBA32F: view-space direction (full precision: a half-float direction moves
//                  a BVH ray by up to ~0.2 px at 640x360, which bounded pure BVH near 46 dB)
// A pixel that traces no ray at all (not reflective, seen edge-on: generate_ray's direction 0)
// gets all zeros in every layer: what the classify pass's clear leaves for the
// pixels it does not list, so skip on and off write the same textures.
// The including pass binds the G-buffer samplers named below.

layout(binding = IMAGE_RAYS_HIT, rgba32f) writeonly uniform image2DArray o_hit;
layout(binding = IMAGE_RAYS_SAMPLE, rgba32f) writeonly uniform image2DArray o_sample;
layout(binding = IMAGE_RAYS_DIRECTION, rgba32f) writeonly uniform image2DArray o_direction;

// The full-resolution pixel whose surface a trace pixel's rays start from: the centre
// pixel of its downscale x downscale block (thesis 2.6).
ivec2 origin_pixel(ivec2 q) {
    return min(q * ssr.downscale + ssr.downscale / 2, ivec2(frame.viewport.xy) - 1);
}

void store_ray(ivec3 id, ReflectionRay ray, bool traced, vec4 hit, float fetches) {
    // One store per texture, the "no ray" zeros selected rather than stored in a branch of
    // their own (llvmpipe runs the stores of both sides: 1.3x the trace's setup).
    bool none = !traced || ray.dir == vec3(0.0);
    imageStore(o_hit, id, none ? vec4(0.0) : hit);
    imageStore(o_sample, id, none ? vec4(0.0) : vec4(ray.weight, ray.pdf, fetches, 1.0));
    imageStore(o_direction, id, none ? vec4(0.0) : vec4(ray.dir, 0.0));
}
