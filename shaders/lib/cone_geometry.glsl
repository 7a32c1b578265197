// The screen-space cone of seed 002, 4.4.5: a cone of half-angle theta seen along the screen
// segment from the ray's origin to its hit is an isosceles triangle whose height (the
// "adjacent" side) is the segment's length; circles inscribed in ever smaller triangles
// toward the origin are where the cone samples. Pure functions of lengths in pixels.

// The base of the isosceles triangle of height `adjacent` and half-angle theta (eq. 4.2).
float isosceles_opposite(float adjacent, float theta) {
    return 2.0 * tan(min(theta, 1.5)) * adjacent;
}

// Radius of the circle touching all three sides of the isosceles triangle with base a and
// height h: r = a (sqrt(a^2 + 4 h^2) - a) / (4 h).
float isosceles_inradius(float a, float h) {
    return h > 0.0 ? a * (sqrt(a * a + 4.0 * h * h) - a) / (4.0 * h) : 0.0;
}

// The next, smaller triangle: its apex stays at the origin and its far side touches the near
// side of the current circle.
float isosceles_next_adjacent(float adjacent, float inradius) {
    return adjacent - 2.0 * inradius;
}
