#version 450 core
// The compute floors beside the raster's (Renderer::raster_floor, shaders/tools/raster_floor.frag),
// one invocation per pixel of the frame:
//   FLOOR_STORES    image stores of the bytes one G-buffer layer holds (R32F depth, RGBA8 albedo,
//                   RGBA16F normal, RGBA8 material: 20 bytes a pixel), what a compute pass that
//                   writes every attribute of a layer (passes/gbuffer_attributes.comp) stores at least
//   FLOOR_CLEAR_ID  an R32UI target given "no sample" (lib/visibility.glsl's VISIBILITY_NONE)
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

uniform ivec2 u_size;

#if FLOOR_STORES
layout(binding = IMAGE_DEPTH, r32f) writeonly uniform image2D o_depth;
layout(binding = IMAGE_ALBEDO, rgba8) writeonly uniform image2D o_albedo;
layout(binding = IMAGE_NORMAL, rgba16f) writeonly uniform image2D o_normal;
layout(binding = IMAGE_MATERIAL, rgba8) writeonly uniform image2D o_material;
#else
layout(binding = IMAGE_ID, r32ui) writeonly uniform uimage2D o_id;
#endif

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= u_size.x || p.y >= u_size.y) return;
#if FLOOR_STORES
    // The same constants as the raster floor's colour outputs (raster_floor.frag, FLOOR_GBUFFER).
    imageStore(o_depth, p, vec4(0.5));
    imageStore(o_albedo, p, vec4(0.5, 0.5, 0.5, 1.0));
    imageStore(o_normal, p, vec4(0.0, 0.0, 1.0, 0.0));
    imageStore(o_material, p, vec4(0.0, 0.5, 0.5, 1.0));
#else
    imageStore(o_id, p, uvec4(0xffffffffu));
#endif
}
