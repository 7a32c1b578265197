// Which 8x8 tiles of each layer after the first of the visibility buffer hold a sample, on the CPU
// device (Renderer.visibility_tiles): its geometry pass marks them as it rasterises
// (passes/visibility_buffer.frag, MARK_TILES, and the lists' selection), so the next peeled layer
// rasterises their bounding box only and the attribute pass classifies the covered tiles only
// (llvmpipe bins and shades every pixel it is given, covered or not). A flag per tile, layer-major,
// rows of tiles (the covered tiles' layout, lib/covered_tiles.glsl).
// Needs frame_uniforms.
#define VISIBILITY_TILE_SIZE 8

layout(std430, binding = BUFFER_VISIBILITY_TILES) buffer VisibilityTiles { uint visibility_tile[]; };

ivec2 visibility_tile_grid() {
    return (ivec2(frame.viewport.xy) + VISIBILITY_TILE_SIZE - 1) / VISIBILITY_TILE_SIZE;
}

void mark_visibility_tile(ivec2 pixel, int layer) {
    ivec2 grid = visibility_tile_grid();
    ivec2 tile = pixel / VISIBILITY_TILE_SIZE;
    visibility_tile[(layer * grid.y + tile.y) * grid.x + tile.x] = 1u;
}
