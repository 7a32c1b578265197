#include "passes/depth_peel.h"

#include "render/pass_registry.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "passes/compute.h"
#include "passes/gbuffer_layout.h"

namespace ssr {

std::vector<ResourceDesc> DepthPeelPass::outputs(const RenderSettings& s) const {
    std::vector<ResourceDesc> out{gbuffer_depth_texture(s, GL_DEPTH_COMPONENT32F)};
    for (auto& d : gbuffer_base_textures(s)) out.push_back(std::move(d));
    // Layer i samples layer i-1's depth from this copy: sampling the array that is being
    // rendered into would be a feedback loop in GL's rules, even on another layer.
    out.push_back({"depth_peel.previous_depth", GL_DEPTH_COMPONENT32F, s.width, s.height, 0, 1});
    return out;
}

std::vector<ResourceDesc> DepthPeelPass::outputs(const RenderSettings& s, const FrameFacts& f) const {
    std::vector<ResourceDesc> out = outputs(s);
    const std::vector<ResourceDesc> attributes = gbuffer_attribute_textures(s, f);
    out.insert(out.end(), attributes.begin() + 3, attributes.end());  // after the base three, in outputs(s)
    return out;
}

TileBounds tile_bounds(const GLuint* flags, int grid_x, int grid_y) {
    TileBounds b{grid_x, grid_y, -1, -1};
    for (int ty = 0; ty < grid_y; ++ty)
        for (int tx = 0; tx < grid_x; ++tx)
            if (flags[size_t(ty * grid_x + tx)]) {
                b.x0 = std::min(b.x0, tx), b.x1 = std::max(b.x1, tx);
                b.y0 = std::min(b.y0, ty), b.y1 = std::max(b.y1, ty);
            }
    return b;
}

void TileBounds::scissor() const {
    glEnable(GL_SCISSOR_TEST);
    if (empty()) glScissor(0, 0, 0, 0);
    else glScissor(x0 * 8, y0 * 8, (x1 - x0 + 1) * 8, (y1 - y0 + 1) * 8);
}

StoreGrowth grow_fragment_store(FrameContext& ctx, const std::string& prefix, uint64_t& capacity_state,
                                uint64_t pixels, uint64_t max_fragments, const Buffer& counter,
                                const std::function<void(uint64_t)>& append_pass) {
    const auto append = [&](uint64_t c) {
        append_pass(c);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        GLuint counted = 0;
        glGetNamedBufferSubData(counter.id(), 0, sizeof(counted), &counted);
        return uint64_t(counted);
    };
    StoreGrowth g;
    uint64_t capacity = std::min(max_fragments, std::max<uint64_t>(capacity_state, 2 * pixels));
    {
        GpuScope timer(ctx.timer, prefix + ".append");
        g.fragments = append(capacity);
    }
    if (g.fragments > capacity) {
        if (g.fragments > max_fragments) return g;
        // 1/8 of slack, so that a frame with slightly more fragments does not redo again.
        capacity = std::min(max_fragments, g.fragments + g.fragments / 8);
        g.redone = true;
        GpuScope timer(ctx.timer, prefix + ".redo");
        g.fragments = append(capacity);
        if (g.fragments > capacity) return g;  // the geometry is the same: cannot happen
    }
    capacity_state = capacity;
    g.fits = true;
    return g;
}

void DepthPeelPass::attach_outputs(FrameContext& ctx, int layer) {
    fbo_.attach(GL_COLOR_ATTACHMENT0, ctx.resources.get("gbuffer.albedo"), 0, layer);
    fbo_.attach(GL_COLOR_ATTACHMENT1, ctx.resources.get("gbuffer.normal"), 0, layer);
    fbo_.attach(GL_COLOR_ATTACHMENT2, ctx.resources.get("gbuffer.material"), 0, layer);
    if (has_emission()) fbo_.attach(GL_COLOR_ATTACHMENT3, ctx.resources.get("gbuffer.emission"), 0, layer);
    if (has_specular()) fbo_.attach(specular_attachment(), ctx.resources.get("gbuffer.specular"), 0, layer);
    if (has_motion()) fbo_.attach(motion_attachment(), ctx.resources.get("gbuffer.motion"), 0, layer);
}

// A later frame without them must not keep this one's textures attached.
void DepthPeelPass::detach_optional_outputs() {
    for (int i = 3; i < colour_outputs(); ++i) glNamedFramebufferTexture(fbo_.id(), GLenum(GL_COLOR_ATTACHMENT0 + i), 0, 0);
}

void apply_peel_culling(const RenderSettings& s) {
    if (s.backface_culling) {
        glEnable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        glFrontFace(GL_CCW);
    } else {
        glDisable(GL_CULL_FACE);
    }
}

void begin_attachmentless_raster(FrameContext& ctx, Framebuffer& fbo) {
    const RenderSettings& s = ctx.settings;
    if (!fbo) {
        fbo = Framebuffer::create();
        glNamedFramebufferDrawBuffer(fbo.id(), GL_NONE);
    }
    glNamedFramebufferParameteri(fbo.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, s.width);
    glNamedFramebufferParameteri(fbo.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, s.height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.id());
    glViewport(0, 0, s.width, s.height);
    ctx.depth.apply_gl_state();  // the clip control: the window depths peeling gets
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    apply_peel_culling(s);
    ctx.gpu_scene.bind_geometry();
}

// The raster's textures, by name: the material textures GpuScene binds per draw, and the copy of
// the previous layer's depth the peel test reads, at the unit written here.
constexpr GLuint kPreviousDepthUnit = 3;
NamedUnits peel_units() {
    NamedUnits u;
    u.placed_textures = GpuScene::material_texture_units();
    u.placed_textures.emplace_back("depth_peel.previous_depth", kPreviousDepthUnit);
    return u;
}

void set_min_separation(const RenderSettings& s, Defines& defines) {
    if (s.min_separation > 0.0f) defines["MIN_SEPARATION"] = "1";
}

void set_min_separation(const RenderSettings& s, GLuint program) {
    if (s.min_separation > 0.0f)
        glProgramUniform1f(program, glGetUniformLocation(program, "u_min_separation"), s.min_separation);
}

std::map<int, GLuint> DepthPeelPass::shading_programs(FrameContext& ctx, const Defines& base) const {
    std::map<int, GLuint> programs;
    for (const DrawItem& d : ctx.gpu_scene.draws()) {
        const int kind = ctx.gpu_scene.material_features(d.material);
        if (programs.count(kind)) continue;
        Defines defines = base;
        defines["PEEL_DEPTH_ONLY"] = "0";
        defines["MATERIAL_TEXTURES"] = std::to_string(kind & GpuScene::kTextureFeatures);
        defines["MATERIAL_AUTO_R"] = kind & GpuScene::kAutoReflectivityFeature ? "1" : "0";
        programs[kind] = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, defines);
        peel_units().check(programs[kind], "passes/depth_peel.frag");
    }
    return programs;
}

void DepthPeelPass::execute(FrameContext& ctx) {
    defines_ = ctx.defines;
    if (ctx.facts.emission_texture) defines_["EMISSION_TEXTURE"] = "1";
    if (ctx.facts.specular_texture) defines_["SPECULAR_TEXTURE"] = "1";
    if (writes_motion(ctx.settings, ctx.facts)) defines_["MOTION_VECTORS"] = "1";
    peel_units().add_unit_defines(defines_);
    list_stats_ = ListStats{};
    prepare_tiles(ctx);
    if (ctx.settings.deep_gbuffer != DeepGBuffer::Lists || !lists(ctx)) {
        if (ctx.settings.deep_gbuffer == DeepGBuffer::Lists) list_stats_.fell_back = 1;  // beyond the budget: peeled, never truncated
        peel(ctx);
    }
    // With skip, the later per-layer passes (Hi-Z build, traces, pre-convolution,
    // pre-integration) work on the layers the construction filled only. Reading the counts
    // waits for it (the lighting pass does the same).
    if (ctx.settings.skip) {
        const std::vector<uint64_t> samples = layer_samples();
        int used = 0;
        while (used < int(samples.size()) && samples[size_t(used)] > 0) ++used;
        ctx.layers_used = used;
    }
}

// The covered-tile flags every construction sets (shaders/lib/covered_tiles.glsl), cleared, with
// the header the lighting pass's compaction counts into.
void DepthPeelPass::prepare_covered_tiles(FrameContext& ctx, Buffer& tiles_buffer) {
    const RenderSettings& s = ctx.settings;
    const int tiles = covered_tiles_per_layer(s) * s.layers;
    // Flags and list per layer, then layer 0's reflective regions: dispatch arguments, flags, list.
    const size_t regions = size_t(classify_regions(s));
    const size_t tile_bytes = sizeof(GLuint) * (4 + 2 * size_t(tiles) + 4 + 2 * regions);
    if (tiles_buffer.size() < tile_bytes) tiles_buffer = Buffer::create(tile_bytes);
    const GLuint header[4] = {0, 1, 1, 0};
    tiles_buffer.upload(header, sizeof(header));
    const GLuint zero_flag = 0;
    glClearNamedBufferSubData(tiles_buffer.id(), GL_R32UI, sizeof(header), sizeof(GLuint) * size_t(tiles),
                              GL_RED_INTEGER, GL_UNSIGNED_INT, &zero_flag);
    const GLuint region_header[4] = {0, 1, 1, 0};  // no region listed yet; a 1 x 1 dispatch layer
    glNamedBufferSubData(tiles_buffer.id(), GLintptr(classify_regions_offset(s)), sizeof(region_header),
                         region_header);
    glClearNamedBufferSubData(tiles_buffer.id(), GL_R32UI,
                              GLintptr(classify_regions_offset(s) + sizeof(region_header)), sizeof(GLuint) * regions,
                              GL_RED_INTEGER, GL_UNSIGNED_INT, &zero_flag);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCoveredTilesBinding, tiles_buffer.id());
    ctx.buffers.publish("covered_tiles", FrameBuffer{&tiles_buffer, kCoveredTilesBinding});
}

// The covered tiles, and one samples query per layer.
void DepthPeelPass::prepare_tiles(FrameContext& ctx) {
    prepare_covered_tiles(ctx, tiles_);
    while (int(queries_.size()) < ctx.settings.layers) {
        GLuint q = 0;
        glGenQueries(1, &q);
        queries_.push_back(q);
    }
    used_queries_ = ctx.settings.layers;
}

void DepthPeelPass::peel(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    Texture& depth = ctx.resources.get("gbuffer.depth");
    Texture& previous = ctx.resources.get("depth_peel.previous_depth");

    // Each layer is drawn twice. The depth pass rasterises the layer's depth with a
    // shader that only peels (one fetch; nothing for layer 0); the shading pass then evaluates the
    // material only where the depth test finds the depth the depth pass kept (GL_EQUAL, early
    // tests). One shader doing both ran the whole material for every fragment the peel discards
    // or the depth test rejects afterwards: llvmpipe tests depth late in a shader that may discard,
    // and deeper layers cost as much as layer 0 whatever they cover. Both programs share the
    // vertex shader, whose `invariant gl_Position` makes the two depths bit-identical.
    Defines peel_defines = defines_;
    peel_defines["PEEL_DEPTH_ONLY"] = "1";
    peel_defines["PEEL_TEST"] = "0";
    const GLuint depth_first = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, peel_defines);
    peel_defines["PEEL_TEST"] = "1";
    set_min_separation(s, peel_defines);
    const GLuint depth_peeled = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, peel_defines);
    set_min_separation(s, depth_peeled);
    // Alpha-tested materials' depth pass samples the base colour's alpha and discards the holes
    // (compiled only when the scene has such a material: a discard costs the others early tests).
    GLuint depth_first_alpha = 0, depth_peeled_alpha = 0;
    if (ctx.gpu_scene.has_alpha_tested()) {
        peel_defines["PEEL_ALPHA_TEST"] = "1";
        peel_defines["PEEL_TEST"] = "0";
        depth_first_alpha = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, peel_defines);
        peel_defines["PEEL_TEST"] = "1";
        depth_peeled_alpha = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, peel_defines);
    }
    if (depth_peeled_alpha) set_min_separation(s, depth_peeled_alpha);
    for (GLuint p : {depth_first, depth_peeled, depth_first_alpha, depth_peeled_alpha})
        if (p) peel_units().check(p, "passes/depth_peel.frag");
    // The shading pass per material kind (GpuScene::material_features).
    const std::map<int, GLuint> shade = shading_programs(ctx, defines_);

    if (!fbo_) fbo_ = Framebuffer::create();
    const int outputs = colour_outputs();
    const GLenum draw_buffers[6] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                    GL_COLOR_ATTACHMENT3, GL_COLOR_ATTACHMENT4, GL_COLOR_ATTACHMENT5};
    glNamedFramebufferDrawBuffers(fbo_.id(), outputs, draw_buffers);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, s.width, s.height);
    ctx.depth.apply_gl_state();
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    // gbuffer.albedo is sRGB storage: encode on write (and texel fetches decode on read).
    glEnable(GL_FRAMEBUFFER_SRGB);
    apply_peel_culling(s);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);  // the clears below obey the write masks
    ctx.gpu_scene.bind_geometry();
    glBindTextureUnit(kPreviousDepthUnit, previous.id());

    const float zero[4] = {0, 0, 0, 0};
    const float clear_depth = ctx.depth.clear_depth();
    // The colour layers keep framebuffer clears even where the other passes clear by image
    // stores (FrameContext::clear_by_compute): on an NVIDIA H200 the first image store into a
    // new render-target texture cost 25-140 ms (a frame's new textures at 1920x1080,
    // benchmarks/timing/peel_profile.py --fresh), where the framebuffer clears cost under 1 ms per layer.
    const bool scissor_deeper = ctx.gl.info().chosen == "cpu";
    const int grid_x = (s.width + 7) / 8, grid_y = (s.height + 7) / 8;
    std::vector<GLuint> flags(size_t(grid_x) * size_t(grid_y));
    glDisable(GL_SCISSOR_TEST);
    for (int layer = 0; layer < s.layers; ++layer) {
        GpuScope timer(ctx.timer, name() + ".layer" + std::to_string(layer));
        // The parts of every layer, summed over the layers (depth_peel.setup/depth/shade): where
        // a layer's time goes on a device, without a profiler.
        std::optional<GpuScope> part(std::in_place, ctx.timer, name() + ".setup");
        if (layer > 0)
            glCopyImageSubData(depth.id(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, layer - 1, previous.id(), GL_TEXTURE_2D, 0, 0,
                               0, 0, s.width, s.height, 1);
        fbo_.attach(GL_DEPTH_ATTACHMENT, depth, 0, layer);
        attach_outputs(ctx, layer);
        if (layer == 0) fbo_.check_complete("depth_peel");
        for (int i = 0; i < outputs; ++i) glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, i, zero);
        glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &clear_depth);
        // On the CPU device, layer i > 0 rasterises only the bounding box of layer i-1's covered
        // tiles (where alone a fragment can be behind it): llvmpipe bins and runs the peel test
        // for every fragment of every triangle, so a nearly empty deep layer cost as much as the
        // first. Exact (a scissor, after the clears). Reading the flags waits for layer i-1; a GPU
        // would stall on that, so it rasterises the whole frame.
        if (layer > 0 && scissor_deeper) {
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            glGetNamedBufferSubData(tiles_.id(), GLintptr(sizeof(GLuint) * (4 + size_t(layer - 1) * flags.size())),
                                    GLsizeiptr(sizeof(GLuint) * flags.size()), flags.data());
            tile_bounds(flags.data(), grid_x, grid_y).scissor();
        }
        // Draw only if the previous layer covered something (its query counted samples).
        if (layer > 0) glBeginConditionalRender(queries_[size_t(layer - 1)], GL_QUERY_WAIT);
        // Depth pass: the samples it counts are the depth-test-passing fragments of the layer.
        part.emplace(ctx.timer, name() + ".depth");
        const GLuint depth_prog = layer > 0 ? depth_peeled : depth_first;
        const GLuint depth_alpha_prog = layer > 0 ? depth_peeled_alpha : depth_first_alpha;
        glUseProgram(depth_prog);
        const GLint loc_depth_object = glGetUniformLocation(depth_prog, "u_object");
        const GLint loc_alpha_object = depth_alpha_prog ? glGetUniformLocation(depth_alpha_prog, "u_object") : -1;
        // No colour attachment drawn at all (a colour mask alone left llvmpipe a colour stage).
        glNamedFramebufferDrawBuffer(fbo_.id(), GL_NONE);
        glDepthMask(GL_TRUE);
        ctx.depth.apply_gl_state();
        glBeginQuery(GL_SAMPLES_PASSED, queries_[size_t(layer)]);
        ctx.gpu_scene.draw_depth(depth_prog, loc_depth_object, depth_alpha_prog, loc_alpha_object);
        glEndQuery(GL_SAMPLES_PASSED);
        // Shading pass: only fragments at the kept depth. Of objects meeting at exactly equal
        // depth the last drawn one's colour stays, where the depth test alone kept the first:
        // the draws go in reverse order, so the same object wins (triangles within one draw
        // still go in order).
        part.emplace(ctx.timer, name() + ".shade");
        glNamedFramebufferDrawBuffers(fbo_.id(), outputs, draw_buffers);
        glDepthMask(GL_FALSE);
        glDepthFunc(GL_EQUAL);
        const auto& draws = ctx.gpu_scene.draws();
        GLuint current = 0;
        GLint loc_object = -1;
        for (auto it = draws.rbegin(); it != draws.rend(); ++it) {
            const DrawItem& d = *it;
            const int kind = ctx.gpu_scene.material_features(d.material);
            if (shade.at(kind) != current) {
                current = shade.at(kind);
                glUseProgram(current);
                loc_object = glGetUniformLocation(current, "u_object");
                glUniform1i(glGetUniformLocation(current, "u_layer"), layer);
            }
            glUniform1i(loc_object, d.object);
            if (kind & GpuScene::kTextureFeatures) ctx.gpu_scene.bind_material_textures(d.material);
            glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                     reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
        }
        if (layer > 0) glEndConditionalRender();
        glDisable(GL_SCISSOR_TEST);
        glDepthMask(GL_TRUE);
        ctx.depth.apply_gl_state();
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_CULL_FACE);
    glDisable(GL_FRAMEBUFFER_SRGB);
    detach_optional_outputs();
}

// The store's largest size on this device for a budget of `budget_mib` (0: the device's own
// limit): a budget the device cannot hold is the user's error, raised before any allocation.
uint64_t DepthPeelPass::store_limit_bytes(int budget_mib) {
    GLint64 block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &block);
    const uint64_t device = uint64_t(std::max<GLint64>(block, 0));
    if (budget_mib <= 0) return device;
    const uint64_t budget = uint64_t(budget_mib) << 20;
    if (budget > device)
        throw std::invalid_argument("Settings.deep_gbuffer_budget = " + std::to_string(budget_mib) +
                                    " MiB is beyond this device's largest storage buffer (GL_MAX_SHADER_STORAGE_"
                                    "BLOCK_SIZE, " + std::to_string(device >> 20) + " MiB): lower it, or 0 for the "
                                    "device's limit");
    return budget;
}

bool DepthPeelPass::lists(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    const uint64_t pixels = uint64_t(s.width) * uint64_t(s.height);
    const uint64_t limit_bytes = store_limit_bytes(s.deep_gbuffer_budget);
    const uint64_t max_fragments = limit_bytes / fragment_bytes();
    // The selection's slots are one storage buffer too: beyond the device's block, peel.
    const uint64_t kept_bytes = sizeof(GLuint) * pixels * uint64_t(s.layers);
    if (kept_bytes > store_limit_bytes(0) || max_fragments == 0) return false;
    if (heads_.size() < sizeof(GLuint) * pixels) heads_ = Buffer::create(sizeof(GLuint) * pixels);
    if (kept_.size() < kept_bytes) kept_ = Buffer::create(kept_bytes);
    if (!counter_) counter_ = Buffer::create((4 + 16) * sizeof(GLuint));  // header, pixels per layer (<= 16)

    // The counter counts past the capacity: the store grows to the counted fragments.
    const StoreGrowth grown = grow_fragment_store(ctx, name(), capacity_, pixels, max_fragments,
                                                  counter_, [&](uint64_t capacity) { append(ctx, capacity); });
    list_stats_.redone = grown.redone ? 1 : 0;
    list_stats_.fragments = grown.fragments;
    if (!grown.fits) return false;
    list_stats_.lists = 1;
    list_stats_.bytes = store_.size() + heads_.size() + kept_.size() + counter_.size();

    Defines select_defines = defines_;
    select_defines["LAYERS"] = std::to_string(s.layers);
    set_min_separation(s, select_defines);
    const GLuint select = ctx.shaders.program({"passes/deep_gbuffer_select.comp"}, select_defines);
    set_min_separation(s, select);
    {
        GpuScope timer(ctx.timer, name() + ".select");
        glUseProgram(select);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kKeptFragmentsBinding, kept_.id());
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        glDispatchCompute(GLuint((s.width + 7) / 8), GLuint((s.height + 7) / 8), 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
    // The most layers any pixel holds: deeper layers are only cleared (peeling's empty layers);
    // and the pixels each layer covers (Frame.layer_samples).
    GLuint counted[4 + 16] = {};
    glGetNamedBufferSubData(counter_.id(), 0, sizeof(counted), counted);
    const int filled = std::min<int>(int(counted[2]), s.layers);
    list_samples_.assign(counted + 4, counted + 4 + s.layers);

    Texture& depth = ctx.resources.get("gbuffer.depth");
    const GLuint write = ctx.shaders.program({"passes/deep_gbuffer_write.vert", "passes/deep_gbuffer_write.frag"},
                                             defines_);
    GpuScope timer(ctx.timer, name() + ".write");
    if (!fbo_) fbo_ = Framebuffer::create();
    if (!empty_vao_) glCreateVertexArrays(1, &empty_vao_);
    const int outputs = colour_outputs();
    const GLenum draw_buffers[6] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                    GL_COLOR_ATTACHMENT3, GL_COLOR_ATTACHMENT4, GL_COLOR_ATTACHMENT5};
    glNamedFramebufferDrawBuffers(fbo_.id(), outputs, draw_buffers);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, s.width, s.height);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glEnable(GL_FRAMEBUFFER_SRGB);  // as peeling's shading pass: the same conversion of the same floats
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    ctx.depth.apply_gl_state();
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glBindVertexArray(empty_vao_);
    glUseProgram(write);
    const GLint loc_layer = glGetUniformLocation(write, "u_layer");
    const float zero[4] = {0, 0, 0, 0};
    const float clear_depth = ctx.depth.clear_depth();
    // Each layer is written over the bounding box of its covered 8x8 tiles only (the selection
    // marked them), the rest cleared: deep layers often cover a small part of the image.
    const int grid_x = (s.width + 7) / 8, grid_y = (s.height + 7) / 8;
    std::vector<GLuint> flags(size_t(grid_x) * size_t(grid_y) * size_t(std::max(filled, 1)));
    if (filled > 0)
        glGetNamedBufferSubData(tiles_.id(), GLintptr(sizeof(GLuint) * 4), GLsizeiptr(sizeof(GLuint) * flags.size()),
                                flags.data());
    for (int layer = 0; layer < s.layers; ++layer) {
        fbo_.attach(GL_DEPTH_ATTACHMENT, depth, 0, layer);
        attach_outputs(ctx, layer);
        if (layer == 0) fbo_.check_complete((name() + ".write").c_str());
        if (layer < filled) {
            const TileBounds box =
                tile_bounds(flags.data() + size_t(layer) * size_t(grid_x) * size_t(grid_y), grid_x, grid_y);
            if (!box.whole(grid_x, grid_y)) {
                for (int i = 0; i < outputs; ++i) glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, i, zero);
                glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &clear_depth);
                box.scissor();
            }
            // Every texel within is written (the clear values where the layer has no fragment).
            glDepthFunc(GL_ALWAYS);  // every kept fragment's depth is written as stored
            glUniform1i(loc_layer, layer);
            glDrawArrays(GL_TRIANGLES, 0, 3);
            glDisable(GL_SCISSOR_TEST);
        } else {
            for (int i = 0; i < outputs; ++i) glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, i, zero);
            glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &clear_depth);
        }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_FRAMEBUFFER_SRGB);
    detach_optional_outputs();
    ctx.depth.apply_gl_state();
    ctx.gpu_scene.bind_geometry();
    return true;
}

// The geometry pass of the lists: every fragment of every draw, shaded by the peeling's shading
// code, appended to its pixel's list; no depth test and no attachment (the framebuffer only
// gives the raster its size).
void DepthPeelPass::append(FrameContext& ctx, uint64_t capacity) {
    const RenderSettings& s = ctx.settings;
    const uint64_t pixels = uint64_t(s.width) * uint64_t(s.height);
    if (store_.size() < capacity * fragment_bytes()) {
        store_.reset();  // the old store goes before the new one is allocated
        store_ = Buffer::create(capacity * fragment_bytes());
    }
    clear_uints(ctx, heads_, 0, size_t(pixels), 0xffffffffu);  // every list empty
    GLuint counter[4 + 16] = {0, GLuint(capacity), 0, 0};
    counter_.upload(counter, sizeof(counter));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFragmentStoreBinding, store_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFragmentCounterBinding, counter_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFragmentHeadsBinding, heads_.id());
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    Defines append = defines_;
    append["DEEP_GBUFFER_APPEND"] = "1";
    const std::map<int, GLuint> shade = shading_programs(ctx, append);
    begin_attachmentless_raster(ctx, empty_fbo_);
    const auto& draws = ctx.gpu_scene.draws();
    GLuint current = 0;
    GLint loc_object = -1, loc_draw = -1;
    for (size_t i = 0; i < draws.size(); ++i) {
        const DrawItem& d = draws[i];
        const int kind = ctx.gpu_scene.material_features(d.material);
        if (shade.at(kind) != current) {
            current = shade.at(kind);
            glUseProgram(current);
            loc_object = glGetUniformLocation(current, "u_object");
            loc_draw = glGetUniformLocation(current, "u_draw");
        }
        glUniform1i(loc_object, d.object);
        glUniform1i(loc_draw, GLint(i));
        if (kind & GpuScene::kTextureFeatures) ctx.gpu_scene.bind_material_textures(d.material);
        glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
    }
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void DepthPeelPass::release() {
    store_.reset();
    counter_.reset();
    heads_.reset();
    kept_.reset();
    capacity_ = 0;
    if (empty_vao_) glDeleteVertexArrays(1, &empty_vao_);
    empty_vao_ = 0;
    empty_fbo_.reset();
    tiles_.reset();
    if (!queries_.empty()) glDeleteQueries(GLsizei(queries_.size()), queries_.data());
    queries_.clear();
    used_queries_ = 0;
    fbo_.reset();
}

std::vector<uint64_t> DepthPeelPass::layer_samples() {
    if (list_stats_.lists) return list_samples_;  // the selection counted the covered pixels
    std::vector<uint64_t> out;
    for (int i = 0; i < used_queries_; ++i) {
        GLuint64 n = 0;
        glGetQueryObjectui64v(queries_[size_t(i)], GL_QUERY_RESULT, &n);
        out.push_back(n);
    }
    return out;
}

SSR_REGISTER_PASS(DepthPeelPass());

}  // namespace ssr
