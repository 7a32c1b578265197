// Robust secondary-ray origins (Waechter and Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems, ch. 6, 2019). A hit point interpolated from a
// triangle's vertices is off the plane by a few ulps of its coordinates; moving each
// coordinate a fixed number of ulps along the geometric normal puts the origin on the
// normal's side whatever the scene's scale, with no scene-dependent epsilon. Near the world
// origin, where ulps vanish, a small fixed offset takes over.

const float RAY_OFFSET_ORIGIN = 1.0 / 32.0;      // below this |coordinate|: the fixed offset
const float RAY_OFFSET_FLOAT_SCALE = 1.0 / 65536.0;
const float RAY_OFFSET_INT_SCALE = 256.0;         // ulps per unit of the normal

// p: a point on a surface (world space); n: the geometric normal on the side the new ray leaves.
vec3 offset_ray_origin(vec3 p, vec3 n) {
    ivec3 of_i = ivec3(RAY_OFFSET_INT_SCALE * n);
    vec3 p_i = vec3(intBitsToFloat(floatBitsToInt(p.x) + (p.x < 0.0 ? -of_i.x : of_i.x)),
                    intBitsToFloat(floatBitsToInt(p.y) + (p.y < 0.0 ? -of_i.y : of_i.y)),
                    intBitsToFloat(floatBitsToInt(p.z) + (p.z < 0.0 ? -of_i.z : of_i.z)));
    return vec3(abs(p.x) < RAY_OFFSET_ORIGIN ? p.x + RAY_OFFSET_FLOAT_SCALE * n.x : p_i.x,
                abs(p.y) < RAY_OFFSET_ORIGIN ? p.y + RAY_OFFSET_FLOAT_SCALE * n.y : p_i.y,
                abs(p.z) < RAY_OFFSET_ORIGIN ? p.z + RAY_OFFSET_FLOAT_SCALE * n.z : p_i.z);
}
