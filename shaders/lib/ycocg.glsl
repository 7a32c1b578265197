// YCoCg colour space (Malvar & Sullivan 2003): luma and two chroma axes, in which a
// neighbourhood's colour box is tighter than in RGB (Karis 2014, Salvi 2016). Pure functions.
vec3 rgb_to_ycocg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 ycocg_to_rgb(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}
