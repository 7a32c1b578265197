// How each object moved since the previous frame of a sequence, for the temporal passes that follow
// what moved (reproject, reproject_reflection, the resolve's ray reuse over time): this frame's
// transforms (scene_data's objects) against the previous frame's (motion.glsl's previous_model), the
// ones gbuffer.motion is made from (seed 002, 4.6.4). An object that did not move keeps the camera's
// own matrices, which the renderer forms in double precision: what stood still reprojects exactly
// as the camera alone reprojects it. Needs frame_uniforms, scene_data, motion.

bool object_moved(int o) { return o >= 0 && previous_model[o] != objects[o].model; }

// World now -> world in the previous frame, for a point of object o (this frame's inverse model:
// the transpose of the 4x4 inverse-transpose the scene data holds).
mat4 world_to_previous_world(int o) { return previous_model[o] * transpose(objects[o].normal_matrix); }

// This frame's view space -> the previous frame's, for a point of object o; `camera` is the camera's
// part, V_prev V^-1 (what it is for a point that stood still).
mat4 object_view_to_previous_view(mat4 camera, int o) {
    if (!object_moved(o)) return camera;
    return camera * frame.view * world_to_previous_world(o) * frame.inv_view;
}

// The previous frame's normal `n_prev` (its view space) in this frame's view space, for object o whose
// points go by `to_previous` (object_view_to_previous_view): normals go by the inverse transpose
// of the previous -> this frame map, the transpose of `to_previous`.
vec3 normal_from_previous(mat4 to_previous, vec3 n_prev) {
    return normalize(transpose(mat3(to_previous)) * n_prev);
}

// This frame's view-space normal `n` in the previous frame's view space.
vec3 normal_to_previous(mat4 to_previous, vec3 n) {
    return normalize(inverse(transpose(mat3(to_previous))) * n);
}
