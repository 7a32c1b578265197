// Cells of a Hi-Z pyramid whose levels halve with floor (GL's mip sizes), odd sizes included
// (seed 002, 4.4.1 and 4.5.1): the last cell of a row or column at every level reaches the
// image edge, so a level-0 pixel x lies in cell min(x >> level, size(level) - 1).
// The including shader defines `ivec2 hiz_level_size(int level)`.

ivec2 hiz_level_size(int level);

ivec2 hiz_cell(vec2 pixel, int level) {
    return min(ivec2(floor(pixel)) >> level, hiz_level_size(level) - 1);
}

// Level-0 pixel bounds [lo, hi) of a cell.
void hiz_cell_bounds(ivec2 cell, int level, out vec2 lo, out vec2 hi) {
    ivec2 size = hiz_level_size(level);
    ivec2 h = (cell + 1) << level;
    if (cell.x == size.x - 1) h.x = hiz_level_size(0).x;
    if (cell.y == size.y - 1) h.y = hiz_level_size(0).y;
    lo = vec2(cell << level);
    hi = vec2(h);
}

// Ray parameter where the screen ray o + v t leaves `cell`.
float hiz_cell_exit(vec2 o, vec2 v, ivec2 cell, int level) {
    vec2 lo, hi;
    hiz_cell_bounds(cell, level, lo, hi);
    float tx = v.x > 0.0 ? (hi.x - o.x) / v.x : v.x < 0.0 ? (lo.x - o.x) / v.x : 1e30;
    float ty = v.y > 0.0 ? (hi.y - o.y) / v.y : v.y < 0.0 ? (lo.y - o.y) / v.y : 1e30;
    return min(tx, ty);
}
