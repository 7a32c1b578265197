// What a pixel that receives no rays reflects: the environment for a surface rougher than the
// cutoff (seed 003's threshold, seed 004's fallback hierarchy), nothing where no surface
// reflects. Shared by the resolve and the classify pass, which writes it for the rough
// pixels when the resolve runs over its lists. Needs frame_uniforms, gbuffer,
// environment.
vec3 non_receiver_reflection(GSample g, vec3 v) {
    return g.covered && g.reflectivity > 0.0
               ? environment_radiance(normalize(mat3(frame.inv_view) * reflect(-v, g.normal)))
               : vec3(0.0);
}
