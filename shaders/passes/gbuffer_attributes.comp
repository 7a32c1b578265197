#version 450 core
// gbuffer_attributes: every attribute of every sample the visibility buffer kept
// (passes/visibility_buffer.cpp), rebuilt from its triangle and the pixel's primary ray
// (lib/visibility_surface.glsl) and shaded by the peeling's own code (lib/gbuffer_shading.glsl),
// then stored by image stores: gbuffer.albedo, .normal, .material (and .emission, .specular where
// the frame has them), the same names, formats and layers as peeling writes. Burns and Hunt 2013's
// deferred attribute fetch, applied to every layer of the deep G-buffer (seed 000, 2.2).
// A material's textures are bound samplers (mipmapped, as the raster samples them), so a sample
// whose material has a texture is shaded in a dispatch of that material's own. Samples are binned:
// bin m < u_materials holds the samples of textured material m, bin u_materials those of every
// untextured material. With BIN_ALL 0 (a GPU) the classify stage shades the untextured samples
// itself; with BIN_ALL 1 (the CPU device) it bins them too, since llvmpipe runs both sides of a
// branch for every lane of a vector: shading inline would cost every texel, empty ones included,
// what shading a sample does, where a dispatch over a bin's list shades samples only.
// ATTRIBUTES_STAGE:
//   4 (triangles, run first): one invocation per triangle of every object (draw order): its
//     record, what all its samples share (view-space vertices and normals, lib/visibility_surface.glsl).
//   0 (classify): one invocation per pixel and layer (8x8 groups, z the layer): an empty sample
//     gets the clear values; a sample is binned (its rank in its bin by an atomic count) or shaded.
//     Each group marks its covered 8x8 tile and counts the layer's covered pixels
//     (lib/covered_tiles.glsl, layer_samples).
//   1 (scan): one group: each bin's first slot in the sorted list (an exclusive prefix sum of the
//     counts) and the indirect dispatch arguments of stages 2 and 3.
//   2 (scatter): one invocation per binned sample: into its bin's part of the sorted list.
//   3 (shade): one invocation per sample of bin u_bin, with its material's textures bound,
//     compiled for its kind (MATERIAL_TEXTURES, MATERIAL_AUTO_R).
// SINGLE_BIN 1 (no material has a texture, so every binned sample is in bin u_materials, whose
// segment starts the sorted list): the classify stage writes each sample's slot in the sorted list
// itself, and stage 2 is not run.
// Layer 0's reflective samples flag their 32x32 region for the classify pass, as peeling's shading
// pass does, and stage 5 (regions, run last: one invocation per region) lists the flagged ones.
#ifndef BIN_ALL
#define BIN_ALL 0
#endif
// TILE_LIST 1: the classify stage runs over a list of covered tiles (the CPU device, where the
// visibility buffer marked them: lib/visibility_tiles.glsl) instead of every tile of its layers;
// STORE_EMPTY 0: their layers were cleared before, so an empty texel is not stored again.
#ifndef TILE_LIST
#define TILE_LIST 0
#endif
#ifndef SINGLE_BIN
#define SINGLE_BIN 0
#endif
// LISTED_SAMPLES 1 (stage 3 only): the samples after layer 0 come listed by the selection of
// "visibility_lists" (passes/visibility_select.comp, LIST_SAMPLES), which knew each pixel's layers:
// no classify stage over their tiles, no scan.
#ifndef LISTED_SAMPLES
#define LISTED_SAMPLES 0
#endif
#ifndef STORE_EMPTY
#define STORE_EMPTY 1
#endif
#ifndef MOTION_VECTORS
#define MOTION_VECTORS 0
#endif
// VERTEX_COLORS 0: no vertex of the scene has a colour other than white (GpuScene::has_vertex_colors).
#ifndef VERTEX_COLORS
#define VERTEX_COLORS 1
#endif
#ifndef ATTRIBUTES_STAGE
#define ATTRIBUTES_STAGE 0
#endif
// TRIANGLE_RECORDS 1: stage 4 wrote every triangle's record, which its samples read; 0: each
// sample reads and transforms its triangle itself (a frame of few samples a triangle).
#ifndef TRIANGLE_RECORDS
#define TRIANGLE_RECORDS 1
#endif
// Textures sampled by the kind this program is compiled for; 0 in the classify stage.
#ifndef MATERIAL_TEXTURES
#define MATERIAL_TEXTURES 0
#endif

#include "../lib/frame_uniforms.glsl"
#include "../lib/depth_convention.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/visibility.glsl"

// How the scene's data is read per sample. Unlike a draw, whose object and material are uniform,
// every invocation reads its own triangle's: on a GPU from the storage buffers; with FETCH_BY_IMAGE
// (the CPU device, lib/input_fetch.glsl) through image buffers of the same data, which llvmpipe
// reads inline, where a storage-buffer read at a per-invocation address is a loop over the lanes.
#if FETCH_BY_IMAGE
layout(binding = IMAGE_SCENE_VERTEX_DATA, rg32f) readonly uniform imageBuffer u_vertex_data;     // GpuVertex floats, in pairs
layout(binding = IMAGE_SCENE_INDEX_DATA, r32ui) readonly uniform uimageBuffer u_index_data;
layout(binding = IMAGE_SCENE_OBJECT_DATA, rgba32f) readonly uniform imageBuffer u_object_data;   // GpuObject, 9 texels
layout(binding = IMAGE_SCENE_MATERIAL_DATA, rgba32f) readonly uniform imageBuffer u_material_data; // GpuMaterial, 22 texels
layout(binding = IMAGE_GBUFFER_VISIBILITY, r32ui) readonly uniform uimage2DArray u_visibility;    // gbuffer.visibility
#define VISIBILITY_VERTEX2(i) imageLoad(u_vertex_data, int(i) / 2).rg
#define VISIBILITY_INDEX(i) imageLoad(u_index_data, int(i)).r
ObjectData load_object(int i) {
    ObjectData o;
    int b = 9 * i;
    o.model = mat4(imageLoad(u_object_data, b), imageLoad(u_object_data, b + 1), imageLoad(u_object_data, b + 2),
                   imageLoad(u_object_data, b + 3));
    o.normal_matrix = mat4(imageLoad(u_object_data, b + 4), imageLoad(u_object_data, b + 5),
                           imageLoad(u_object_data, b + 6), imageLoad(u_object_data, b + 7));
    o.material = floatBitsToInt(imageLoad(u_object_data, b + 8));
    return o;
}
MaterialData load_material(int i) {
    MaterialData m;
    int b = 22 * i;
    m.base_color = imageLoad(u_material_data, b);
    m.params = imageLoad(u_material_data, b + 1);
    m.emissive = imageLoad(u_material_data, b + 2);
    m.flags = floatBitsToInt(imageLoad(u_material_data, b + 3));
    m.images = floatBitsToInt(imageLoad(u_material_data, b + 4));
    m.wraps = floatBitsToInt(imageLoad(u_material_data, b + 5));
    m.dielectric_f0 = imageLoad(u_material_data, b + 6);
    for (int k = 0; k < 12; ++k) m.uv_transform[k] = imageLoad(u_material_data, b + 7 + k);
    m.specular_images = floatBitsToInt(imageLoad(u_material_data, b + 19));
    m.specular_wraps = floatBitsToInt(imageLoad(u_material_data, b + 20));
    m.specular_f0 = imageLoad(u_material_data, b + 21);
    return m;
}
uint sample_id(ivec3 t) { return imageLoad(u_visibility, t).r; }
ivec4 load_object_entry(int i) { return floatBitsToInt(imageLoad(u_object_data, 9 * i + 8)); }
// The triangles' records: written by stage 4, read by stages 0 and 3.
layout(binding = IMAGE_ATTRIBUTES_RECORDS, rgba32f) uniform imageBuffer u_records;
#define VISIBILITY_RECORD(i) imageLoad(u_records, int(i))
void store_record(int i, vec4 r) { imageStore(u_records, i, r); }
#else
#include "../lib/scene_geometry.glsl"
layout(binding = TEXTURE_GBUFFER_VISIBILITY) uniform usampler2DArray u_visibility;  // gbuffer.visibility
#define VISIBILITY_VERTEX2(i) vec2(vertex_data[i], vertex_data[(i) + 1u])
#define VISIBILITY_INDEX(i) index_data[i]
ObjectData load_object(int i) { return objects[i]; }
MaterialData load_material(int i) { return materials[i]; }
uint sample_id(ivec3 t) { return texelFetch(u_visibility, t, 0).r; }
ivec4 load_object_entry(int i) { return objects[i].material; }
layout(std430, binding = BUFFER_VISIBILITY_RECORDS) buffer VisibilityRecords { vec4 records[]; };
#define VISIBILITY_RECORD(i) records[i]
void store_record(int i, vec4 r) { records[i] = r; }
#endif

#if ATTRIBUTES_STAGE == 1
layout(local_size_x = 256) in;
#elif ATTRIBUTES_STAGE >= 4
layout(local_size_x = 64) in;
#elif ATTRIBUTES_STAGE == 0
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
#else
layout(local_size_x = 64) in;
#endif

// Per bin: the indirect dispatch of its stage 3 (x groups, y 1, z 1; w its samples), and its first
// slot in the sorted list.
struct MaterialBin {
    uvec4 dispatch;
    uvec4 segment;  // x: first slot in `sorted`
};
layout(std430, binding = BUFFER_ATTRIBUTE_BINS) coherent buffer AttributeBins {
    uvec4 scatter_dispatch;   // stage 2's indirect dispatch (x groups, y, z 1); w: samples binned
    uint layer_samples[16];   // covered pixels of each layer (Frame.layer_samples)
    MaterialBin bins[];
};
layout(std430, binding = BUFFER_BINNED_SAMPLES) buffer BinnedSamples { uvec2 binned[]; };  // (sample, rank in its bin)
layout(std430, binding = BUFFER_SORTED_SAMPLES) buffer SortedSamples { uint sorted[]; };   // by bin
uniform int u_materials;  // the scene's materials: bin u_materials holds the untextured ones' samples

// A bin's sample count and first slot, and the sorted list, as the classify and shade stages reach
// them: with FETCH_BY_IMAGE (the CPU device) through image buffers over the same storage
// (passes/gbuffer_attributes.cpp), since llvmpipe runs every storage-buffer access as a loop over
// the lanes, even where all invocations read one address.
#if FETCH_BY_IMAGE && (ATTRIBUTES_STAGE == 0 || ATTRIBUTES_STAGE == 3)
layout(binding = IMAGE_ATTRIBUTES_BINS, r32ui) uniform uimageBuffer u_bin_words;  // AttributeBins, a uint a texel
#if LISTED_SAMPLES
// The samples the selection listed (lib/visibility_samples.glsl, "visibility_lists" on the CPU
// device): its header at IMAGE_ATTRIBUTES_BINS (the count in word 3), its list of (sample, id)
// at IMAGE_ATTRIBUTES_LISTED,
// shaded as one bin.
layout(binding = IMAGE_ATTRIBUTES_LISTED, rg32ui) readonly uniform uimageBuffer u_listed;
uint bin_samples(int b) { return imageLoad(u_bin_words, 3).r; }
uint bin_first(int b) { return 0u; }
#else
layout(binding = IMAGE_ATTRIBUTES_SORTED, r32ui) uniform uimageBuffer u_sorted;  // SortedSamples
// Word k of bin b's MaterialBin, after the header's scatter_dispatch and layer_samples (20 words).
int bin_word(int b, int k) { return 20 + 8 * b + k; }
uint bin_samples(int b) { return imageLoad(u_bin_words, bin_word(b, 3)).r; }
uint bin_first(int b) { return imageLoad(u_bin_words, bin_word(b, 4)).r; }
#endif
#if !LISTED_SAMPLES
uint sorted_sample(uint i) { return imageLoad(u_sorted, int(i)).r; }
void sort_sample(uint slot, uint s) { imageStore(u_sorted, int(slot), uvec4(s)); }
#endif
#else
uint bin_samples(int b) { return bins[b].dispatch.w; }
uint bin_first(int b) { return bins[b].segment.x; }
uint sorted_sample(uint i) { return sorted[i]; }
void sort_sample(uint slot, uint s) { sorted[slot] = s; }
#endif


#if ATTRIBUTES_STAGE != 1
layout(binding = TEXTURE_GBUFFER_DEPTH) uniform sampler2DArray u_depth;  // gbuffer.depth

// Whether material m has a texture slot (GpuScene::kTextureFeatures): its samples are shaded by
// its own dispatch.
bool material_textured(MaterialData m) {
    return m.flags.x != 0 || m.flags.y != 0 || m.flags.z != 0 || m.images.w >= 0 || m.specular_images.x >= 0 ||
           m.specular_images.y >= 0;
}
// The bin of a sample of material m.
int sample_bin(int m) { return material_textured(load_material(m)) ? m : u_materials; }
#endif

#if ATTRIBUTES_STAGE == 0 || ATTRIBUTES_STAGE == 3 || ATTRIBUTES_STAGE == 4
#include "../lib/visibility_surface.glsl"
#endif

#if ATTRIBUTES_STAGE == 0 || ATTRIBUTES_STAGE == 3 || ATTRIBUTES_STAGE == 5
#if FETCH_BY_IMAGE
// The covered tiles' buffer as a uint a texel, after its 4-word header (lib/covered_tiles.glsl):
// the reflective regions are flagged per sample and listed per region.
layout(binding = IMAGE_COVERED_TILES, r32ui) coherent uniform uimageBuffer u_covered_tiles;
#define COVERED_TILE_LOAD(i) imageLoad(u_covered_tiles, 4 + int(i)).r
#define COVERED_TILE_EXCHANGE(i, v) imageAtomicExchange(u_covered_tiles, 4 + int(i), v)
#define COVERED_TILE_ADD(i, v) imageAtomicAdd(u_covered_tiles, 4 + int(i), v)
#define COVERED_TILE_STORE(i, v) imageStore(u_covered_tiles, 4 + int(i), uvec4(v))
#endif
#include "../lib/covered_tiles.glsl"
#endif

#if ATTRIBUTES_STAGE == 0 || ATTRIBUTES_STAGE == 3
#include "../lib/gbuffer.glsl"
#include "../lib/normal_mapping.glsl"
#include "../lib/material.glsl"
#include "../lib/specular_albedo.glsl"

#if MATERIAL_TEXTURES
layout(binding = TEXTURE_MATERIAL_BASE_COLOR) uniform sampler2D u_base_color_texture;          // sRGB
layout(binding = TEXTURE_MATERIAL_METALLIC_ROUGHNESS) uniform sampler2D u_metallic_roughness_texture;  // G roughness, B metallic
layout(binding = TEXTURE_MATERIAL_NORMAL_MAP) uniform sampler2D u_normal_texture;              // tangent space
#if EMISSION_TEXTURE
layout(binding = TEXTURE_MATERIAL_EMISSIVE) uniform sampler2D u_emissive_texture;  // sRGB
#endif
#if SPECULAR_TEXTURE
layout(binding = TEXTURE_MATERIAL_SPECULAR) uniform sampler2D u_specular_texture;        // A
layout(binding = TEXTURE_MATERIAL_SPECULAR_COLOR) uniform sampler2D u_specular_color_texture;  // sRGB
#endif
#endif
layout(binding = TEXTURE_SPECULAR_ALBEDO) uniform sampler2D u_specular_albedo;  // (A, B) split-sum table
#include "../lib/gbuffer_shading.glsl"

// gbuffer.albedo is sRGB storage, which no image format names: it is bound through an RGBA8 view
// and encoded here with the sRGB transfer function (IEC 61966-2-1) the framebuffer applies.
#if MOTION_VECTORS
#include "../lib/motion.glsl"
// gbuffer.motion (Settings.motion_vectors): after the scene's images where they are bound.
layout(binding = IMAGE_GBUFFER_MOTION, rg32f) writeonly uniform image2DArray o_motion;
#endif
layout(binding = IMAGE_GBUFFER_ALBEDO, rgba8) writeonly uniform image2DArray o_albedo_metallic;
layout(binding = IMAGE_GBUFFER_NORMAL, rgba16f) writeonly uniform image2DArray o_normal_roughness;
layout(binding = IMAGE_GBUFFER_MATERIAL, rgba8) writeonly uniform image2DArray o_material;
#if EMISSION_TEXTURE
layout(binding = IMAGE_GBUFFER_EMISSION, rgba16f) writeonly uniform image2DArray o_emission;
#endif
#if SPECULAR_TEXTURE
layout(binding = IMAGE_GBUFFER_SPECULAR, rgba16f) writeonly uniform image2DArray o_specular;
#endif

vec3 linear_to_srgb(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void store_texel(ivec3 t, vec4 albedo_metallic, vec4 normal_roughness, vec4 material, vec4 emission, vec4 specular) {
    imageStore(o_albedo_metallic, t, vec4(linear_to_srgb(albedo_metallic.rgb), albedo_metallic.a));
    imageStore(o_normal_roughness, t, normal_roughness);
    imageStore(o_material, t, material);
#if EMISSION_TEXTURE
    imageStore(o_emission, t, emission);
#endif
#if SPECULAR_TEXTURE
    imageStore(o_specular, t, specular);
#endif
}

// The window position of pixel p's centre on the plane of a triangle, and the surface there.
struct PlanePoint {
    vec3 b;         // barycentrics
    vec3 position;  // view space
};
PlanePoint plane_point(VisibilityTriangle tri, ivec2 p) {
    PlanePoint q;
    q.b = visibility_barycentrics(tri, visibility_ray(vec2(p) + 0.5));
    q.position = visibility_interpolate(q.b, tri.p0, tri.p1, tri.p2);
    return q;
}

// Shades the sample kept at texel t (its id `id`) and stores its attributes.
void shade_sample(ivec3 t, uint id) {
    int object = visibility_object(id), triangle = visibility_primitive(id);
    ivec4 entry = load_object_entry(object);
#if !TRIANGLE_RECORDS || MATERIAL_TEXTURES || VERTEX_COLORS || MOTION_VECTORS
    // What no record holds, from the triangle's vertices.
    ObjectData o = load_object(object);
    uint v0 = visibility_vertex(entry, triangle, 0), v1 = visibility_vertex(entry, triangle, 1),
         v2 = visibility_vertex(entry, triangle, 2);
#endif
    vec3 n0, n1, n2;
#if TRIANGLE_RECORDS
    VisibilityTriangle tri = visibility_read_record(entry.w + triangle, n0, n1, n2);
#else
    VisibilityTriangle tri = visibility_triangle(o, triangle);
    n0 = visibility_vertex_normal(o, v0);
    n1 = visibility_vertex_normal(o, v1);
    n2 = visibility_vertex_normal(o, v2);
#endif
    PlanePoint here = plane_point(tri, t.xy);
    GBufferSurface s;
    s.view_position = here.position;
    s.view_normal = visibility_interpolate(here.b, n0, n1, n2);
#if MATERIAL_TEXTURES || VERTEX_COLORS
    VisibilityVertex a0 = visibility_vertex_attributes(o, v0), a1 = visibility_vertex_attributes(o, v1),
                     a2 = visibility_vertex_attributes(o, v2);
#endif
#if MATERIAL_TEXTURES
    s.uv = visibility_interpolate(here.b, a0.uv, a1.uv, a2.uv);
    s.view_tangent = visibility_interpolate(here.b, a0.tangent, a1.tangent, a2.tangent);
#else
    s.uv = s.view_tangent = vec4(0.0);  // read by the texture paths only
#endif
#if VERTEX_COLORS
    s.color = visibility_interpolate(here.b, a0.color, a1.color, a2.color);
#else
    s.color = vec4(1.0);  // every vertex white: the same factor, without reading the colours
#endif
#if MATERIAL_TEXTURES
    // The differences a fragment shader's derivatives take over the pixel's 2x2 quad (quads at
    // even window coordinates): along x in the pixel's row, along y in its column.
    ivec2 q = t.xy & ~1;
    ivec2 px = ivec2(q.x + 1 - (t.x - q.x), t.y), py = ivec2(t.x, q.y + 1 - (t.y - q.y));
    PlanePoint nx = plane_point(tri, px), ny = plane_point(tri, py);
    float sx = t.x == q.x ? 1.0 : -1.0, sy = t.y == q.y ? 1.0 : -1.0;  // here is the quad's first or second
    s.duv_dx = sx * (visibility_interpolate(nx.b, a0.uv, a1.uv, a2.uv) - s.uv);
    s.duv_dy = sy * (visibility_interpolate(ny.b, a0.uv, a1.uv, a2.uv) - s.uv);
    s.dpos_dx = sx * (nx.position - here.position);
    s.dpos_dy = sy * (ny.position - here.position);
#else
    s.duv_dx = s.duv_dy = vec4(0.0);
    s.dpos_dx = s.dpos_dy = vec3(0.0);
#endif
    s.front_facing = visibility_front_facing(tri);
    s.object = object;
    // The geometry pass kept the sample (its alpha test there decided any hole), so it is shaded
    // whatever this sample's alpha says.
    GBufferTexel texel = gbuffer_shade(s, load_material(entry.x));
    vec4 albedo_metallic, normal_roughness, material;
    gbuffer_encode(texel.g, albedo_metallic, normal_roughness, material);
    store_texel(t, albedo_metallic, normal_roughness, material, texel.emission, texel.specular);
#if MOTION_VECTORS
    // The sample's object-space point, through both frames' transforms.
    vec3 q = visibility_interpolate(here.b, visibility_object_position(v0), visibility_object_position(v1),
                                    visibility_object_position(v2));
    imageStore(o_motion, t, motion_still(o, object) ? vec4(0.0)
                                                    : motion_texel(motion_clip(o, q), motion_previous_clip(object, q)));
#endif
    if (t.z == 0 && texel.g.reflectivity > 0.0) mark_reflective_region(t.xy);  // listed by stage 5
}
#endif

#if ATTRIBUTES_STAGE == 0
#if TILE_LIST
// The covered 8x8 tiles to classify, one a work group: layer << 24 | tile (rows of tiles).
#if FETCH_BY_IMAGE
layout(binding = IMAGE_ATTRIBUTES_TILE_LIST, r32ui) readonly uniform uimageBuffer u_tile_list;
uint tile_entry(uint i) { return imageLoad(u_tile_list, int(i)).r; }
#else
layout(std430, binding = BUFFER_TILE_LIST) readonly buffer TileList { uint tile_list[]; };
uint tile_entry(uint i) { return tile_list[i]; }
#endif
#endif

shared uint group_covered;

void main() {
    ivec2 size = ivec2(frame.viewport.xy);
#if TILE_LIST
    uint entry = tile_entry(gl_WorkGroupID.x);
    ivec2 grid = covered_tile_grid();
    ivec2 tile = ivec2(int(entry & 0xffffffu) % grid.x, int(entry & 0xffffffu) / grid.x);
    ivec3 t = ivec3(tile * 8 + ivec2(gl_LocalInvocationID.xy), int(entry >> 24));
#else
    ivec2 tile = ivec2(gl_WorkGroupID.xy);
    ivec3 t = ivec3(gl_GlobalInvocationID.xy, int(gl_WorkGroupID.z));
#endif
    if (gl_LocalInvocationIndex == 0u) group_covered = 0u;
    barrier();
    if (t.x < size.x && t.y < size.y) {
        float depth = texelFetch(u_depth, t, 0).r;
        // A texel the layer's depth test never wrote holds the clear value: no sample (whatever
        // the triangle target holds there).
        if (is_farther(DEPTH_CLEAR, depth)) {
            atomicAdd(group_covered, 1u);
            uint id = sample_id(t);
            // One bin: no material to look up (every sample is in bin u_materials).
            int bin = SINGLE_BIN != 0 ? u_materials : sample_bin(load_object(visibility_object(id)).material.x);
            if (BIN_ALL != 0 || bin < u_materials) {
                uint rank = atomicAdd(bins[bin].dispatch.w, 1u);
#if SINGLE_BIN
                sort_sample(rank, sample_index(t.xy, t.z));
#else
                uint slot = atomicAdd(scatter_dispatch.w, 1u);
                binned[slot] = uvec2(sample_index(t.xy, t.z), rank);
#endif
            } else {
                shade_sample(t, id);
            }
        } else if (STORE_EMPTY != 0) {
            store_texel(t, vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
#if MOTION_VECTORS
            imageStore(o_motion, t, vec4(0.0));
#endif
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0u && group_covered > 0u) {
        ivec2 grid = covered_tile_grid();
        covered_tile[(t.z * grid.y + tile.y) * grid.x + tile.x] = 1u;
        atomicAdd(layer_samples[t.z], group_covered);
    }
}
#elif ATTRIBUTES_STAGE == 1
shared uint chunk_sum[256];

void main() {
    uint lane = gl_LocalInvocationIndex;
    uint count = uint(u_materials) + 1u;
    uint per = (count + 255u) / 256u;
    uint first = lane * per, last = min(first + per, count);
    uint sum = 0u;
    for (uint m = first; m < last; ++m) sum += bins[m].dispatch.w;
    chunk_sum[lane] = sum;
    barrier();
    if (lane == 0u) {
        uint running = 0u;
        for (uint i = 0u; i < 256u; ++i) {
            uint c = chunk_sum[i];
            chunk_sum[i] = running;
            running += c;
        }
        scatter_dispatch.xyz = uvec3((running + 63u) / 64u, 1u, 1u);
    }
    barrier();
    uint offset = chunk_sum[lane];
    for (uint m = first; m < last; ++m) {
        uint n = bins[m].dispatch.w;
        bins[m].segment.x = offset;
        bins[m].dispatch.xyz = uvec3((n + 63u) / 64u, 1u, 1u);
        offset += n;
    }
}
#elif ATTRIBUTES_STAGE == 2
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= scatter_dispatch.w) return;
    uvec2 e = binned[i];
    int bin = sample_bin(load_object(visibility_object(sample_id(sample_texel(e.x)))).material.x);
    sorted[bins[bin].segment.x + e.y] = e.x;
}
#elif ATTRIBUTES_STAGE == 4
uniform int u_objects;  // the scene's objects (draws)
uniform int u_record_count;  // their triangles: a record each
uniform int u_first_record;  // this dispatch's first

void main() {
    int i = u_first_record + int(gl_GlobalInvocationID.x);
    if (i >= u_record_count) return;
    // The object whose triangles hold record i: the last whose first triangle is at or before i
    // (the first triangles ascend in draw order; an object without triangles shares the next one's).
    int lo = 0, hi = u_objects - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (load_object_entry(mid).w <= i) lo = mid;
        else hi = mid - 1;
    }
    ObjectData o = load_object(lo);
    int triangle = i - o.material.w;
    vec4 r[VISIBILITY_RECORD_TEXELS];
    visibility_record_texels(visibility_triangle(o, triangle),
                             visibility_vertex_normal(o, visibility_vertex(o.material, triangle, 0)),
                             visibility_vertex_normal(o, visibility_vertex(o.material, triangle, 1)),
                             visibility_vertex_normal(o, visibility_vertex(o.material, triangle, 2)), r);
    for (int k = 0; k < VISIBILITY_RECORD_TEXELS; ++k) store_record(VISIBILITY_RECORD_TEXELS * i + k, r[k]);
}
#elif ATTRIBUTES_STAGE == 5
void main() { list_reflective_region(gl_GlobalInvocationID.x); }
#else
uniform int u_bin;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= bin_samples(u_bin)) return;
#if LISTED_SAMPLES
    uvec2 e = imageLoad(u_listed, int(i)).xy;  // (sample, id)
    shade_sample(sample_texel(e.x), e.y);
#else
    ivec3 t = sample_texel(sorted_sample(bin_first(u_bin) + i));
    shade_sample(t, sample_id(t));
#endif
}
#endif
