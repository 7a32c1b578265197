#include "passes/gbuffer_attributes.h"

#include "render/pass_registry.h"

#include <algorithm>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "passes/gbuffer_layout.h"
#include "passes/compute.h"
#include "passes/depth_peel.h"
#include "passes/visibility_buffer.h"

namespace ssr {

namespace {
// Storage-buffer bindings of passes/gbuffer_attributes.comp (cpp/render/buffer_bindings.def).
constexpr GLuint kBinsBinding = kAttributeBinsBinding, kBinnedBinding = kBinnedSamplesBinding,
                 kSortedBinding = kSortedSamplesBinding, kRecordsBinding = kVisibilityRecordsBinding;
// A triangle's record (lib/visibility_surface.glsl): 5 vec4.
constexpr size_t kRecordTexels = 5, kRecordBytes = kRecordTexels * 16;
// Records a dispatch of stage 4 writes at most: 64 a group, the fewest groups GL guarantees in x.
constexpr size_t kRecordsPerDispatch = 64 * 65535;
// The records are kept where the frame has at least this many texels a triangle (width x height x
// the filled layers: the samples, at most): on llvmpipe a record costs about what reading its
// triangle per sample costs four samples (benchmarks/timing/deep_gbuffer.py: gbuffer_attributes.triangles
// against .shade on 2CylinderEngine), so a scene of many triangles in a small image reads its
// triangles per sample instead.
constexpr uint64_t kTexelsPerRecord = 4;
// Its AttributeBins header: stage 2's dispatch (uvec4), then 16 layers' sample counts; then a
// MaterialBin (two uvec4) per material.
constexpr size_t kBinsHeaderBytes = 16 + 16 * sizeof(GLuint), kBinBytes = 32;
constexpr int kMaxLayers = 16;
// The texture units the shader reads gbuffer.depth and gbuffer.visibility from (units 0-6 hold a
// material's textures, 13 the specular-albedo table).
constexpr GLuint kDepthUnit = 7, kVisibilityUnit = 8;
// With FETCH_BY_IMAGE: the image units of the scene's vertex, index, object and material data and
// of gbuffer.visibility (after the outputs' 0-4).
constexpr GLuint kVertexImage = 5, kIndexImage = 6, kObjectImage = 7, kMaterialImage = 8, kVisibilityImage = 9;
// With FETCH_BY_IMAGE: the image units of the bins (a uint a texel) and of the sorted samples.
constexpr GLuint kBinsImage = 11, kSortedImage = 12, kTileListImage = 13, kRecordsImage = 14, kCoveredTilesImage = 15;
// gbuffer.motion's image unit (Settings.motion_vectors): after the outputs, or after those inputs.
constexpr GLuint kMotionImage = 5, kMotionImageByImage = 10;
// The outputs' image units.
constexpr GLuint kAlbedoImage = 0, kNormalImage = 1, kMaterialOutImage = 2, kEmissionImage = 3, kSpecularImage = 4;

// Those units by name (the shader declares every texture and image at its name's define), with
// the material textures GpuScene binds per draw. The listed and the sorted samples share a unit:
// no stage declares both.
NamedUnits attribute_units(bool by_image) {
    NamedUnits u;
    u.placed_textures = GpuScene::material_texture_units();
    u.placed_textures.emplace_back("gbuffer.depth", kDepthUnit);
    u.placed_textures.emplace_back("gbuffer.visibility", kVisibilityUnit);
    u.placed_images = {{"gbuffer.albedo", kAlbedoImage},         {"gbuffer.normal", kNormalImage},
                       {"gbuffer.material", kMaterialOutImage},  {"gbuffer.emission", kEmissionImage},
                       {"gbuffer.specular", kSpecularImage},     {"scene.vertex_data", kVertexImage},
                       {"scene.index_data", kIndexImage},        {"scene.object_data", kObjectImage},
                       {"scene.material_data", kMaterialImage},  {"gbuffer.visibility", kVisibilityImage},
                       {"attributes.bins", kBinsImage},          {"attributes.listed", kSortedImage},
                       {"attributes.sorted", kSortedImage},      {"attributes.tile_list", kTileListImage},
                       {"attributes.records", kRecordsImage},    {"covered_tiles", kCoveredTilesImage},
                       {"gbuffer.motion", by_image ? kMotionImageByImage : kMotionImage}};
    return u;
}

}  // namespace

std::vector<ResourceDesc> GBufferAttributesPass::outputs(const RenderSettings& s) const {
    return gbuffer_base_textures(s);
}

std::vector<ResourceDesc> GBufferAttributesPass::outputs(const RenderSettings& s, const FrameFacts& f) const {
    return gbuffer_attribute_textures(s, f);
}

void GBufferAttributesPass::execute(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    const GpuScene& gs = ctx.gpu_scene;
    if (s.layers > kMaxLayers) throw std::invalid_argument("gbuffer_attributes: at most 16 layers");
    DepthPeelPass::prepare_covered_tiles(ctx, tiles_);
    layers_ = s.layers;
    samples_read_ = false;
    const uint64_t pixels = uint64_t(s.width) * uint64_t(s.height);
    // The layers holding a sample (the geometry pass says so where it knows without a stall).
    const int filled = ctx.layers_filled >= 0 ? std::min(ctx.layers_filled, s.layers) : s.layers;
    if (pixels * uint64_t(std::max(filled, 1)) > uint64_t(std::numeric_limits<GLuint>::max()))
        throw std::invalid_argument("Settings.deep_gbuffer '" + enum_name(s.deep_gbuffer) +
                                    "': width x height x layers beyond 2^32 samples");

    // The materials: which have textures (their samples are binned), and whether an untextured one
    // takes its reflectivity from its lobe (MATERIAL_AUTO_R of the first dispatch).
    std::set<int> textured;
    bool auto_untextured = false;
    for (const DrawItem& d : gs.draws()) {
        const int kind = gs.material_features(d.material);
        if (kind & GpuScene::kTextureFeatures) textured.insert(d.material);
        else if (kind & GpuScene::kAutoReflectivityFeature) auto_untextured = true;
    }
    const size_t materials = ctx.scene.materials.size();
    // On the CPU device the geometry pass marked each layer's covered tiles: layer 0 (mostly
    // covered) is classified whole and its untextured samples shaded where found, the deeper layers
    // over their covered tiles only, every sample binned (BIN_ALL; bin `materials` holds the
    // untextured materials' samples; shaders/passes/gbuffer_attributes.comp says why). A GPU
    // classifies every layer whole and shades the untextured samples where found.
    const bool tile_lists = VisibilityBufferPass::marks_tiles(ctx);
    // Every kept sample, where the selection of "visibility_lists" listed them with their counts
    // (lib/visibility_samples.glsl): shaded from that list, without classifying any texel.
    const FrameBuffer& listed = ctx.buffers.get("visibility_samples");
    GLint texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &texels);
    // The triangles' records, where the samples are likely to outnumber them enough to pay for them.
    const size_t records =
        pixels * uint64_t(std::max(filled, 1)) >= kTexelsPerRecord * uint64_t(gs.triangle_count()) ? gs.triangle_count() : 0;
    records_used_ = records;
    const bool scene_by_image = ctx.fetch_by_image() && gs.vertex_buffer().size() / 8 <= size_t(texels) &&
                                gs.index_buffer().size() / 4 <= size_t(texels) &&
                                records * kRecordTexels <= size_t(texels);
    const bool listed_samples = tile_lists && listed.data != nullptr && textured.empty() && scene_by_image;
    std::vector<GLuint> deep_tiles;  // layer << 24 | tile, of the layers after the first
    int filled_tiles = filled;
    if (tile_lists && !listed_samples) {
        const int per_layer = DepthPeelPass::covered_tiles_per_layer(s);
        std::vector<GLuint> flags(size_t(per_layer) * size_t(s.layers));
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(ctx.buffers.get("visibility_tiles").data->id(), 0,
                                GLsizeiptr(sizeof(GLuint) * flags.size()), flags.data());
        // Layer 0 is classified whole where it holds anything (its tiles are not marked).
        filled_tiles = filled > 0 ? 1 : 0;
        for (int layer = 1; layer < s.layers; ++layer) {
            bool any = false;
            for (int i = 0; i < per_layer; ++i)
                if (flags[size_t(layer) * size_t(per_layer) + size_t(i)]) {
                    any = true;
                    deep_tiles.push_back(GLuint(layer) << 24 | GLuint(i));
                }
            if (any) filled_tiles = layer + 1;
        }
    }
    const bool bin_all = tile_lists && !deep_tiles.empty();
    const size_t bins_bytes = kBinsHeaderBytes + kBinBytes * (materials + 1);
    if (bins_.size() < bins_bytes) bins_ = Buffer::create(bins_bytes);
    const GLuint zero = 0;
    glClearNamedBufferSubData(bins_.id(), GL_R32UI, 0, GLsizeiptr(bins_bytes), GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBinsBinding, bins_.id());
    const bool binning = bin_all || !textured.empty();
    if (binning) {
        const uint64_t samples = pixels * uint64_t(std::max(filled, 1));
        if (sorted_.size() < samples * 4) {
            sorted_.reset();
            sorted_ = Buffer::create(samples * 4);
        }
        // The (sample, rank) pairs stage 2 scatters: not needed where the samples are classified
        // straight into place (SINGLE_BIN).
        if (!textured.empty() && binned_.size() < samples * 8) {
            binned_.reset();
            binned_ = Buffer::create(samples * 8);
        }
        if (binned_) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBinnedBinding, binned_.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kSortedBinding, sorted_.id());
    }

    Texture& albedo = ctx.resources.get("gbuffer.albedo");
    Texture& normal = ctx.resources.get("gbuffer.normal");
    Texture& material = ctx.resources.get("gbuffer.material");
    Texture* emission = ctx.facts.emission_texture ? &ctx.resources.get("gbuffer.emission") : nullptr;
    Texture* specular = ctx.facts.specular_texture ? &ctx.resources.get("gbuffer.specular") : nullptr;
    // gbuffer.albedo's sRGB storage through an RGBA8 view: image stores take no sRGB format (the
    // shader encodes). A new view each frame: the pooled texture behind a name may change.
    GLuint albedo_view = 0;
    glGenTextures(1, &albedo_view);
    glTextureView(albedo_view, GL_TEXTURE_2D_ARRAY, albedo.id(), GL_RGBA8, 0, 1, 0, GLuint(s.layers));
    struct DeleteView {
        GLuint id;
        ~DeleteView() { glDeleteTextures(1, &id); }
    } delete_view{albedo_view};
    // The outputs' image units; bound again after a clear, which by compute binds kClearImageUnit itself.
    auto bind_outputs = [&] {
        glBindImageTexture(kAlbedoImage, albedo_view, 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA8);
        bind_image_layered(kNormalImage, normal, GL_WRITE_ONLY);
        bind_image_layered(kMaterialOutImage, material, GL_WRITE_ONLY);
        if (emission) bind_image_layered(kEmissionImage, *emission, GL_WRITE_ONLY);
        if (specular) bind_image_layered(kSpecularImage, *specular, GL_WRITE_ONLY);
    };
    bind_outputs();
    Texture* motion = writes_motion(s, ctx.facts) ? &ctx.resources.get("gbuffer.motion") : nullptr;
    glBindTextureUnit(kDepthUnit, ctx.resources.get("gbuffer.depth").id());
    glBindTextureUnit(kVisibilityUnit, ctx.resources.get("gbuffer.visibility").id());
    // The scene's data per sample (shaders/passes/gbuffer_attributes.comp): through image buffers on
    // the device that reads them faster so (FETCH_BY_IMAGE), where they fit its texel-buffer limit.
    const bool by_image = scene_by_image && sorted_.size() / 4 <= size_t(texels);
    // Every triangle's record, written by stage 4 before any sample reads it.
    const size_t record_bytes = std::max<size_t>(records, 1) * kRecordBytes;
    if (records_.size() < record_bytes) {
        records_.reset();
        records_ = Buffer::create(record_bytes);
    }
    std::optional<BufferView> vertex_view, index_view, object_view, material_view, bins_view, sorted_view,
        records_view, tiles_view;
    if (by_image) {
        vertex_view.emplace(gs.vertex_buffer(), GL_RG32F);  // floats in pairs (lib/visibility_surface.glsl)
        index_view.emplace(gs.index_buffer(), GL_R32UI);
        object_view.emplace(gs.object_buffer(), GL_RGBA32F);
        material_view.emplace(gs.material_buffer(), GL_RGBA32F);
        glBindImageTexture(kVertexImage, vertex_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RG32F);
        glBindImageTexture(kIndexImage, index_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
        glBindImageTexture(kObjectImage, object_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        glBindImageTexture(kMaterialImage, material_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
        bind_image_layered(kVisibilityImage, ctx.resources.get("gbuffer.visibility"), GL_READ_ONLY);
        records_view.emplace(records_, GL_RGBA32F);
        glBindImageTexture(kRecordsImage, records_view->id, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
        tiles_view.emplace(tiles_, GL_R32UI);
        glBindImageTexture(kCoveredTilesImage, tiles_view->id, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
        if (binning) {
            bins_view.emplace(bins_, GL_R32UI);
            sorted_view.emplace(sorted_, GL_R32UI);
            glBindImageTexture(kBinsImage, bins_view->id, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
            glBindImageTexture(kSortedImage, sorted_view->id, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
        }
    } else {
        gs.bind_vertex_data();
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRecordsBinding, records_.id());
    }
    if (motion) bind_image_layered(by_image ? kMotionImageByImage : kMotionImage, *motion, GL_WRITE_ONLY);
    const int bits = VisibilityBufferPass::primitive_bits(gs, s.deep_gbuffer);

    Defines base = ctx.defines;
    base["FETCH_BY_IMAGE"] = by_image ? "1" : "0";
    base["BIN_ALL"] = bin_all ? "1" : "0";
    // Without textured materials every binned sample is in one bin: classified straight into place.
    const bool single_bin = textured.empty();
    base["SINGLE_BIN"] = single_bin ? "1" : "0";
    base["MOTION_VECTORS"] = motion ? "1" : "0";
    base["VERTEX_COLORS"] = gs.has_vertex_colors() ? "1" : "0";
    base["TRIANGLE_RECORDS"] = records > 0 ? "1" : "0";
    if (ctx.facts.emission_texture) base["EMISSION_TEXTURE"] = "1";
    if (ctx.facts.specular_texture) base["SPECULAR_TEXTURE"] = "1";
    auto program = [&](int stage, int kind, bool tile_list = false, bool listed_list = false) {
        Defines d = base;
        d["LISTED_SAMPLES"] = listed_list ? "1" : "0";
        d["TILE_LIST"] = tile_list ? "1" : "0";
        d["STORE_EMPTY"] = tile_list ? "0" : "1";
        if (stage == 0 && !tile_list) d["BIN_ALL"] = "0";
        d["ATTRIBUTES_STAGE"] = std::to_string(stage);
        d["MATERIAL_TEXTURES"] = std::to_string(kind & GpuScene::kTextureFeatures);
        d["MATERIAL_AUTO_R"] = kind & GpuScene::kAutoReflectivityFeature ? "1" : "0";
        const NamedUnits units = attribute_units(by_image);
        units.add_unit_defines(d);
        const GLuint prog = ctx.shaders.program({"passes/gbuffer_attributes.comp"}, d);
        units.check(prog, "passes/gbuffer_attributes.comp");
        glProgramUniform1i(prog, glGetUniformLocation(prog, "u_primitive_bits"), bits);
        glProgramUniform1i(prog, glGetUniformLocation(prog, "u_materials"), GLint(materials));
        return prog;
    };
    if (records > 0) {
        GpuScope timer(ctx.timer, "gbuffer_attributes.triangles");
        const GLuint prog = program(4, 0);
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_objects"), GLint(gs.draws().size()));
        const GLint first_loc = glGetUniformLocation(prog, "u_first_record");
        glUniform1i(glGetUniformLocation(prog, "u_record_count"), GLint(records));
        for (size_t first = 0; first < records; first += kRecordsPerDispatch) {
            glUniform1i(first_loc, GLint(first));
            glDispatchCompute(GLuint((std::min(records - first, kRecordsPerDispatch) + 63) / 64), 1, 1);
        }
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    {
        GpuScope timer(ctx.timer, "gbuffer_attributes.classify");
        const float clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        if (listed_samples) {
            // Every layer cleared, then what the classification would have found taken from the
            // selection: the covered tiles (its marks, in the covered tiles' layout) and each
            // layer's sample count; the listed samples are shaded below.
            for (Texture* t : {&albedo, &normal, &material, emission, specular, motion})
                if (t) clear_layers(ctx, *t, 0, clear);
            bind_outputs();
            if (filled > 0) {
                const size_t per_layer = size_t(DepthPeelPass::covered_tiles_per_layer(s)) * sizeof(GLuint);
                glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
                glCopyNamedBufferSubData(ctx.buffers.get("visibility_tiles").data->id(), tiles_.id(), 0,
                                         GLintptr(4 * sizeof(GLuint)), GLsizeiptr(per_layer * size_t(filled)));
                glCopyNamedBufferSubData(listed.args->id(), bins_.id(), GLintptr(4 * sizeof(GLuint)),
                                         GLintptr(4 * sizeof(GLuint)), GLsizeiptr(sizeof(GLuint) * size_t(filled)));
            }
        } else if (tile_lists) {
            // Layer 0 whole; the deeper layers cleared, then their covered tiles classified.
            if (filled_tiles > 0) {
                glUseProgram(program(0, auto_untextured ? GpuScene::kAutoReflectivityFeature : 0));
                dispatch_2d(s.width, s.height, 1, 8, 8);
            }
            for (Texture* t : {&albedo, &normal, &material, emission, specular, motion})
                if (t) clear_layers(ctx, *t, filled_tiles > 0 ? 1 : 0, clear);
            bind_outputs();
            if (!deep_tiles.empty()) {
                const size_t bytes = deep_tiles.size() * sizeof(GLuint);
                if (tile_list_.size() < bytes) tile_list_ = Buffer::create(bytes);
                tile_list_.upload(deep_tiles.data(), bytes);
                glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTileListBinding, tile_list_.id());
                std::optional<BufferView> tile_list_view;
                if (by_image) {
                    tile_list_view.emplace(tile_list_, GL_R32UI);
                    glBindImageTexture(kTileListImage, tile_list_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
                }
                glUseProgram(program(0, 0, true));
                glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
                glDispatchCompute(GLuint(deep_tiles.size()), 1, 1);
                glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
            }
        } else {
            if (filled > 0) {
                glUseProgram(program(0, auto_untextured ? GpuScene::kAutoReflectivityFeature : 0));
                dispatch_2d(s.width, s.height, filled, 8, 8);
            }
            // The layers after the filled ones hold no sample: the clear values peeling gives them.
            for (Texture* t : {&albedo, &normal, &material, emission, specular, motion})
                if (t) clear_layers(ctx, *t, filled, clear);
            bind_outputs();
        }
    }
    if (listed_samples && filled > 0) {
        GpuScope timer(ctx.timer, "gbuffer_attributes.shade");
        BufferView counts_view(*listed.args, GL_R32UI), list_view(*listed.data, GL_RG32UI);  // (sample, id)
        glBindImageTexture(kBinsImage, counts_view.id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
        glBindImageTexture(kSortedImage, list_view.id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RG32UI);
        const GLuint prog = program(3, auto_untextured ? GpuScene::kAutoReflectivityFeature : 0, false, true);
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_bin"), int(materials));
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, listed.args->id());
        glDispatchComputeIndirect(listed.args_offset);
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    }
    if (binning && filled_tiles > 0) {
        {
            GpuScope timer(ctx.timer, "gbuffer_attributes.bin");
            glUseProgram(program(1, 0));
            glDispatchCompute(1, 1, 1);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
            if (!single_bin) {
                glUseProgram(program(2, 0));
                glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, bins_.id());
                glDispatchComputeIndirect(0);
                glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
            }
        }
        GpuScope timer(ctx.timer, "gbuffer_attributes.shade");
        // Each bin's samples: the untextured materials' (binned on the CPU device only), then each
        // textured material's with its textures bound.
        auto shade_bin = [&](int bin, int kind) {
            const GLuint prog = program(3, kind);
            glUseProgram(prog);
            glUniform1i(glGetUniformLocation(prog, "u_bin"), bin);
            glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, bins_.id());
            glDispatchComputeIndirect(GLintptr(kBinsHeaderBytes + kBinBytes * size_t(bin)));
        };
        if (bin_all) shade_bin(int(materials), auto_untextured ? GpuScene::kAutoReflectivityFeature : 0);
        for (int m : textured) {
            gs.bind_material_textures(m);
            shade_bin(m, gs.material_features(m));
        }
        glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    }
    if (filled > 0) {
        // The reflective regions the shading flagged, listed for the classify pass: one invocation
        // per region (shaders/passes/gbuffer_attributes.comp, stage 5).
        GpuScope timer(ctx.timer, "gbuffer_attributes.regions");
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        glUseProgram(program(5, 0));
        const GLuint regions = GLuint(DepthPeelPass::classify_regions(s));
        glDispatchCompute((regions + 63) / 64, 1, 1);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                    GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    // With skip, the later per-layer passes work on the layers holding a surface only. Reading the
    // counts waits for this pass (peeling's queries do the same).
    if (s.skip) {
        const std::vector<uint64_t> counts = layer_samples();
        int used = 0;
        while (used < int(counts.size()) && counts[size_t(used)] > 0) ++used;
        ctx.layers_used = used;
    }
}

void GBufferAttributesPass::report(const RenderSettings&, std::map<std::string, double>& stats) const {
    stats["gbuffer_attributes_triangle_records"] = double(records_used_);
}

std::vector<uint64_t> GBufferAttributesPass::layer_samples() {
    if (!samples_read_) {
        GLuint counts[kMaxLayers] = {};
        if (bins_ && layers_ > 0)
            glGetNamedBufferSubData(bins_.id(), 16, GLsizeiptr(sizeof(GLuint) * size_t(layers_)), counts);
        samples_.assign(counts, counts + layers_);
        samples_read_ = true;
    }
    return samples_;
}

void GBufferAttributesPass::release() {
    tiles_.reset();
    tile_list_.reset();
    bins_.reset();
    binned_.reset();
    sorted_.reset();
    records_.reset();
    records_used_ = 0;
    layers_ = 0;
    samples_.clear();
    samples_read_ = false;
}

SSR_REGISTER_PASS(GBufferAttributesPass());

}  // namespace ssr
