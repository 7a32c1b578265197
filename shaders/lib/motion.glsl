// Screen-space motion vectors (Settings.motion_vectors, gbuffer.motion): where a surface point was
// in the previous frame of a sequence, relative to where it is now, in pixels (seed 002, 4.6.4: a
// velocity buffer reprojects what moved, where the camera's matrices alone reproject what stood
// still). Both positions come from the same object-space point through each frame's own object and
// camera transforms without the TAA jitter, so a point that did not move under a camera that did
// not move has exactly 0. The previous frame's object transforms are storage buffer
// kPreviousModelsBinding (the renderer writes this frame's where the sequence has none).
// Needs frame_uniforms, scene_data.
layout(std430, binding = BUFFER_PREVIOUS_MODELS) readonly buffer PreviousModels { mat4 previous_model[]; };

vec2 clip_to_pixel(vec4 clip) {
    return (clip.xy / clip.w * 0.5 + 0.5) * frame.viewport.xy;
}

// Object `object`'s point `p` (object space): this frame's clip position and the previous frame's.
vec4 motion_clip(ObjectData o, vec3 p) { return frame.view_proj_unjittered * (o.model * vec4(p, 1.0)); }
vec4 motion_previous_clip(int object, vec3 p) {
    return frame.previous_view_proj * (previous_model[object] * vec4(p, 1.0));
}

// Whether object `object` and the camera kept their transforms (TAA's jitter aside) since the
// previous frame. Its motion is then 0 by this test, not by subtracting two evaluations of one
// product: a GPU's compiler may round them differently (fused or not), which leaves motion of
// about 1e-6 px on points that stood still.
bool motion_still(ObjectData o, int object) {
    return frame.previous_view_proj == frame.view_proj_unjittered && previous_model[object] == o.model;
}

// gbuffer.motion's texel: previous pixel position minus this one.
vec4 motion_texel(vec4 clip, vec4 previous_clip) {
    return vec4(clip_to_pixel(previous_clip) - clip_to_pixel(clip), 0.0, 0.0);
}
