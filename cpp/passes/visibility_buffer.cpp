#include "passes/visibility_buffer.h"

#include "render/pass_registry.h"

#include <algorithm>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "passes/gbuffer_layout.h"
#include "passes/compute.h"
#include "passes/depth_peel.h"

namespace ssr {

namespace {
// Storage-buffer bindings of lib/visibility_lists.glsl (cpp/render/buffer_bindings.def).
constexpr GLuint kFragmentsBinding = kVisibilityFragmentsBinding, kLinksBinding = kVisibilityLinksBinding,
                 kHeadsBinding = kVisibilityHeadsBinding, kCounterBinding = kVisibilityCounterBinding;
// Image units of gbuffer.visibility and gbuffer.depth in the compute passes that store them
// (visibility_select.comp, visibility_depth.comp), and the texture unit the raster's peel test
// reads the previous layer from (and visibility_depth.comp the layer's raster depth).
constexpr GLuint kVisibilityImage = 0, kDepthImage = 1, kPreviousDepthUnit = 3;
// With FETCH_BY_IMAGE: the image units the selection reads the lists' fragments, links and heads from.
constexpr GLuint kFragmentsImage = 2, kLinksImage = 3, kHeadsImage = 4;
// The selection's listed samples (lib/visibility_samples.glsl): the counts' storage binding (dispatch
// uvec4 and 16 layers' counts) and the list's image unit.
constexpr GLuint kSampleCountsBinding = kVisibilitySamplesBinding, kSamplesImage = 5;
constexpr size_t kSampleCountsBytes = 16 + 16 * sizeof(GLuint);

// Those units by name, with the material textures GpuScene binds per draw: every program of the
// pass declares its textures and images at these names' defines.
NamedUnits visibility_units() {
    NamedUnits u;
    u.placed_textures = GpuScene::material_texture_units();
    u.placed_textures.emplace_back("visibility_buffer.previous_depth", kPreviousDepthUnit);
    u.placed_textures.emplace_back("visibility_buffer.raster_depth", kPreviousDepthUnit);
    u.placed_images = {{"gbuffer.visibility", kVisibilityImage}, {"gbuffer.depth", kDepthImage},
                       {"visibility.list_fragments", kFragmentsImage}, {"visibility.list_links", kLinksImage},
                       {"visibility.list_heads", kHeadsImage}, {"visibility.samples", kSamplesImage}};
    return u;
}
GLuint visibility_program(FrameContext& ctx, const std::vector<std::string>& stages, Defines d) {
    const NamedUnits u = visibility_units();
    u.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program(stages, d);
    u.check(prog, stages.back());
    return prog;
}
}  // namespace

std::vector<ResourceDesc> VisibilityBufferPass::outputs(const RenderSettings& s) const {
    const int w = s.width, h = s.height, l = s.layers;
    // With the lists, the selection stores the kept depths by compute (passes/visibility_select.comp):
    // a colour format, which every later pass samples as it samples a depth format (.r). A depth
    // target would take one full-screen depth-only draw per layer through the raster outputs.
    const bool stored = builds_lists(s);
    std::vector<ResourceDesc> out = {
        gbuffer_depth_texture(s, GLenum(stored ? GL_R32F : GL_DEPTH_COMPONENT32F)),
        // Read by the attribute pass of the same frame only.
        {"gbuffer.visibility", GL_R32UI, w, h, l, 1, Lifetime::Scratch},
    };
    // Layer i samples layer i-1's depth from this copy: sampling the array being rendered into
    // would be a feedback loop in GL's rules, even on another layer ("visibility_lists" peels too,
    // beyond its budget).
    out.push_back({"visibility_buffer.previous_depth", GL_DEPTH_COMPONENT32F, w, h, 0, 1, Lifetime::Scratch});
    // The lists peeling a frame beyond their budget rasterise each layer's depth here, then store it.
    if (stored) out.push_back({"visibility_buffer.raster_depth", GL_DEPTH_COMPONENT32F, w, h, 0, 1, Lifetime::Scratch});
    return out;
}

void VisibilityBufferPass::check_device(const RenderSettings& s) const {
    if (s.deep_gbuffer == DeepGBuffer::VisibilityLists) DepthPeelPass::store_limit_bytes(s.deep_gbuffer_budget);
}

void VisibilityBufferPass::report(const RenderSettings& s, std::map<std::string, double>& stats) const {
    if (s.deep_gbuffer != DeepGBuffer::VisibilityLists) return;
    stats["deep_gbuffer_lists"] = double(list_stats_.lists);
    stats["deep_gbuffer_fell_back"] = double(list_stats_.fell_back);
    stats["deep_gbuffer_redone"] = double(list_stats_.redone);
    stats["deep_gbuffer_fragments"] = double(list_stats_.fragments);
    stats["deep_gbuffer_bytes"] = double(list_stats_.bytes);
    stats["deep_gbuffer_samples_listed"] = double(list_stats_.samples_listed);
}

void VisibilityBufferPass::execute(FrameContext& ctx) {
    list_stats_ = ListStats{};
    primitive_bits_ = primitive_bits(ctx.gpu_scene, ctx.settings.deep_gbuffer);
    const RenderSettings& s = ctx.settings;
    const size_t tile_bytes = sizeof(GLuint) * size_t(DepthPeelPass::covered_tiles_per_layer(s)) * size_t(s.layers);
    if (tiles_.size() < tile_bytes) tiles_ = Buffer::create(tile_bytes);
    if (marks_tiles(ctx)) {
        const GLuint zero = 0;
        glClearNamedBufferSubData(tiles_.id(), GL_R32UI, 0, GLsizeiptr(tile_bytes), GL_RED_INTEGER, GL_UNSIGNED_INT,
                                  &zero);
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTilesBinding, tiles_.id());
    ctx.buffers.publish("visibility_tiles", FrameBuffer{&tiles_, kTilesBinding});
    // Published with its list by the selection where it lists the samples; else none
    // (the attribute pass classifies them).
    ctx.buffers.publish("visibility_samples", FrameBuffer{});
    if (!builds_lists(s) || !lists(ctx)) {
        if (builds_lists(s)) list_stats_.fell_back = 1;  // never truncated
        peel(ctx);
    }
}

int VisibilityBufferPass::primitive_bits(const GpuScene& scene, DeepGBuffer construction) {
    const auto& draws = scene.draws();
    uint64_t largest = 1;
    for (const DrawItem& d : draws) largest = std::max<uint64_t>(largest, uint64_t(d.index_count) / 3);
    int bits = 0;
    while ((uint64_t(1) << bits) < largest) ++bits;
    // The largest id, (draws - 1) << bits | (2^bits - 1), must stay below VISIBILITY_NONE.
    if (bits >= 32 || (uint64_t(std::max<size_t>(draws.size(), 1)) << bits) > uint64_t(0xffffffffu))
        throw std::invalid_argument("Settings.deep_gbuffer '" + enum_name(construction) + "': the scene's " +
                                    std::to_string(draws.size()) + " objects and its largest mesh's " +
                                    std::to_string(largest) + " triangles do not fit the visibility buffer's 32-bit "
                                    "sample ids together: use 'peel' or 'lists'");
    return bits;
}

void VisibilityBufferPass::draw_scene(FrameContext& ctx, GLuint prog, GLuint alpha_prog) const {
    const auto& draws = ctx.gpu_scene.draws();
    GLuint current = 0;
    GLint loc_object = -1, loc_base = -1;
    for (size_t i = draws.size(); i-- > 0;) {
        const DrawItem& d = draws[i];
        const bool alpha = ctx.gpu_scene.alpha_tested(d.material);
        const GLuint want = alpha ? alpha_prog : prog;
        if (want != current) {
            glUseProgram(current = want);
            loc_object = glGetUniformLocation(current, "u_object");
            loc_base = glGetUniformLocation(current, "u_id_base");
        }
        glUniform1i(loc_object, d.object);
        glUniform1ui(loc_base, GLuint(d.object) << primitive_bits_);
        if (alpha) ctx.gpu_scene.bind_material_textures(d.material);
        glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
    }
}

void VisibilityBufferPass::peel(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    Texture& depth = ctx.resources.get("gbuffer.depth");
    Texture& visibility = ctx.resources.get("gbuffer.visibility");
    Texture& previous = ctx.resources.get("visibility_buffer.previous_depth");
    // gbuffer.depth stored by compute (the lists' R32F): each layer is rasterised into a depth
    // target of its own first.
    const bool stored = depth.format() == GL_R32F;
    Texture& raster = stored ? ctx.resources.get("visibility_buffer.raster_depth") : depth;
    const GLuint store = stored ? visibility_program(ctx, {"passes/visibility_depth.comp"}, ctx.defines) : 0;

    const std::vector<std::string> stages = {"passes/depth_peel.vert", "passes/visibility_buffer.frag"};
    Defines d = ctx.defines;
    set_min_separation(s, d);
    // The layers after the first mark their tiles: layer 0 is mostly covered, so the next layer
    // rasterises the whole frame and the attribute pass takes layer 0 whole, and its fragment shader,
    // free of side effects, keeps the early depth test.
    const bool mark = marks_tiles(ctx);
    GLuint programs[2][2] = {};  // [peel test][alpha test]
    for (int peel_test = 0; peel_test < 2; ++peel_test)
        for (int alpha = 0; alpha < 2; ++alpha) {
            if (alpha && !ctx.gpu_scene.has_alpha_tested()) continue;
            d["MARK_TILES"] = mark && peel_test ? "1" : "0";
            d["PEEL_TEST"] = std::to_string(peel_test);
            d["ALPHA_TEST"] = std::to_string(alpha);
            programs[peel_test][alpha] = visibility_program(ctx, stages, d);
            if (peel_test) set_min_separation(s, programs[peel_test][alpha]);
        }

    while (int(queries_.size()) < s.layers) {
        GLuint q = 0;
        glGenQueries(1, &q);
        queries_.push_back(q);
    }
    if (!fbo_) fbo_ = Framebuffer::create();
    glNamedFramebufferDrawBuffer(fbo_.id(), GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, s.width, s.height);
    ctx.depth.apply_gl_state();
    // Equal depths pass: with the draws in reverse order the first draw's fragment stays (see the header).
    glDepthFunc(ctx.depth.compare_or_equal());
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    apply_peel_culling(s);
    ctx.gpu_scene.bind_geometry();
    glBindTextureUnit(kPreviousDepthUnit, previous.id());
    const float clear_depth = ctx.depth.clear_depth();
    const int grid_x = (s.width + 7) / 8, grid_y = (s.height + 7) / 8;
    std::vector<GLuint> flags(size_t(grid_x) * size_t(grid_y));
    for (int layer = 0; layer < s.layers; ++layer) {
        GpuScope timer(ctx.timer, "visibility_buffer.layer" + std::to_string(layer));
        if (layer > 0)
            glCopyImageSubData(raster.id(), raster.target(), 0, 0, 0, stored ? 0 : layer - 1, previous.id(),
                               GL_TEXTURE_2D, 0, 0, 0, 0, s.width, s.height, 1);
        fbo_.attach(GL_DEPTH_ATTACHMENT, raster, 0, stored ? -1 : layer);
        fbo_.attach(GL_COLOR_ATTACHMENT0, visibility, 0, layer);
        if (layer == 0) fbo_.check_complete("visibility_buffer");
        // Only the depth is cleared: a triangle id counts where the depth test wrote a depth.
        glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &clear_depth);
        // Where tiles are marked, layer i > 1 rasterises only the bounding box of layer i-1's covered
        // tiles, where alone a fragment can lie behind it (as peeling does, passes/depth_peel.cpp).
        if (layer > 1 && mark) {
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            glGetNamedBufferSubData(tiles_.id(), GLintptr(sizeof(GLuint) * size_t(layer - 1) * flags.size()),
                                    GLsizeiptr(sizeof(GLuint) * flags.size()), flags.data());
            tile_bounds(flags.data(), grid_x, grid_y).scissor();
        }
        for (const auto& row : programs)
            for (GLuint p : row)
                if (p && mark) glProgramUniform1i(p, glGetUniformLocation(p, "u_layer"), layer);
        // Draw only if the previous layer covered something (its query counted samples).
        if (layer > 0) glBeginConditionalRender(queries_[size_t(layer - 1)], GL_QUERY_WAIT);
        glBeginQuery(GL_SAMPLES_PASSED, queries_[size_t(layer)]);
        draw_scene(ctx, programs[layer > 0][0], programs[layer > 0][1]);
        glEndQuery(GL_SAMPLES_PASSED);
        if (layer > 0) glEndConditionalRender();
        glDisable(GL_SCISSOR_TEST);
        if (stored) {  // the layer's depth (the clear value where the draw was skipped) into gbuffer.depth
            glUseProgram(store);
            glUniform1i(glGetUniformLocation(store, "u_layer"), layer);
            glBindTextureUnit(kPreviousDepthUnit, raster.id());
            bind_image_layered(kDepthImage, depth, GL_WRITE_ONLY);
            dispatch_2d(s.width, s.height, 1, 8, 8);
            glBindTextureUnit(kPreviousDepthUnit, previous.id());
        }
    }
    if (stored) glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                                GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_CULL_FACE);
    ctx.depth.apply_gl_state();
    // On the CPU device the attribute pass works on the layers that hold a sample only (reading
    // the queries waits for the raster, which llvmpipe runs at once anyway); a GPU is not stalled
    // for it: there the attribute pass covers every layer, the empty ones at the cost of their
    // clear values' stores.
    if (ctx.gl.info().chosen == "cpu") {
        int filled = 0;
        for (; filled < s.layers; ++filled) {
            GLuint64 n = 0;
            glGetQueryObjectui64v(queries_[size_t(filled)], GL_QUERY_RESULT, &n);
            if (n == 0) break;
        }
        ctx.layers_filled = filled;
    }
}

bool VisibilityBufferPass::lists(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    const uint64_t pixels = uint64_t(s.width) * uint64_t(s.height);
    const uint64_t block = DepthPeelPass::store_limit_bytes(0);
    const uint64_t limit_bytes = DepthPeelPass::store_limit_bytes(s.deep_gbuffer_budget);
    // Every buffer is one storage block: the fragments' (8 bytes each) is the largest.
    const uint64_t max_fragments = std::min(limit_bytes / kFragmentBytes, block / 8);
    if (max_fragments == 0) return false;
    if (heads_.size() < sizeof(GLuint) * pixels) heads_ = Buffer::create(sizeof(GLuint) * pixels);
    if (!counter_) counter_ = Buffer::create(4 * sizeof(GLuint));

    // The counter counts past the capacity: the store grows to the counted fragments.
    const StoreGrowth grown = grow_fragment_store(ctx, "visibility_buffer", capacity_, pixels, max_fragments,
                                                  counter_, [&](uint64_t capacity) { append(ctx, capacity); });
    list_stats_.redone = grown.redone ? 1 : 0;
    list_stats_.fragments = grown.fragments;
    if (!grown.fits) return false;
    list_stats_.lists = 1;
    list_stats_.bytes = fragments_.size() + links_.size() + heads_.size() + counter_.size();

    Texture& depth = ctx.resources.get("gbuffer.depth");
    Texture& visibility = ctx.resources.get("gbuffer.visibility");
    // The lists through image buffers on the device that reads them faster so, where the store fits
    // its texel-buffer limit (visibility_select.comp).
    GLint texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &texels);
    const bool by_image = ctx.fetch_by_image() && capacity_ <= uint64_t(texels) && pixels <= uint64_t(texels);
    std::optional<BufferView> fragments_view, links_view, heads_view;
    if (by_image) {
        fragments_view.emplace(fragments_, GL_RG32UI);
        links_view.emplace(links_, GL_R32UI);
        heads_view.emplace(heads_, GL_R32UI);
    }
    // On the CPU device, with more than one layer and without textured materials (whose samples
    // the attribute pass bins by material), the selection also lists every kept sample for the
    // attribute pass (lib/visibility_samples.glsl): it knows each pixel's layers, where the attribute pass would
    // classify every texel to find them, and on this device shade the empty lanes of a vector too.
    // At one layer the listing costs the selection more than it saves
    // (python benchmarks/timing/deep_gbuffer.py --device cpu).
    bool textured = false;
    for (const DrawItem& d : ctx.gpu_scene.draws())
        textured = textured || (ctx.gpu_scene.material_features(d.material) & GpuScene::kTextureFeatures) != 0;
    const uint64_t samples = pixels * uint64_t(s.layers);
    const bool list_samples = by_image && marks_tiles(ctx) && !textured && s.layers > 1 && samples <= uint64_t(texels);
    std::optional<BufferView> samples_view;
    if (list_samples) {
        if (samples_.size() < samples * 2 * sizeof(GLuint)) {  // (sample, id)
            samples_.reset();
            samples_ = Buffer::create(samples * 2 * sizeof(GLuint));
        }
        if (!sample_counts_) sample_counts_ = Buffer::create(kSampleCountsBytes);
        GLuint header[kSampleCountsBytes / sizeof(GLuint)] = {0, 1, 1, 0};  // no group yet, y = z = 1
        sample_counts_.upload(header, sizeof(header));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kSampleCountsBinding, sample_counts_.id());
        samples_view.emplace(samples_, GL_RG32UI);
        glBindImageTexture(kSamplesImage, samples_view->id, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32UI);
        ctx.buffers.publish("visibility_samples", FrameBuffer{&samples_, kSampleCountsBinding, &sample_counts_, 0});
        list_stats_.samples_listed = 1;
        list_stats_.bytes += samples_.size() + sample_counts_.size();
    }
    Defines select_defines = ctx.defines;
    select_defines["FETCH_BY_IMAGE"] = by_image ? "1" : "0";
    select_defines["LAYERS"] = std::to_string(s.layers);
    select_defines["MARK_TILES"] = marks_tiles(ctx) ? "1" : "0";
    select_defines["LIST_SAMPLES"] = list_samples ? "1" : "0";
    // Where clears are by compute the selection stores the empty layers' depths itself (that store
    // is the clear); elsewhere the array is cleared first and only the kept depths are stored.
    select_defines["STORE_EMPTY_DEPTH"] = ctx.clear_by_compute ? "1" : "0";
    if (!ctx.clear_by_compute) {
        const float clear = ctx.depth.clear_depth();
        clear_layers(ctx, depth, 0, &clear);
    }
    set_min_separation(s, select_defines);
    const GLuint select = visibility_program(ctx, {"passes/visibility_select.comp"}, select_defines);
    set_min_separation(s, select);
    glProgramUniform1i(select, glGetUniformLocation(select, "u_primitive_bits"), primitive_bits_);
    {
        GpuScope timer(ctx.timer, "visibility_buffer.select");
        glUseProgram(select);
        bind_image_layered(kVisibilityImage, visibility, GL_WRITE_ONLY);
        bind_image_layered(kDepthImage, depth, GL_WRITE_ONLY);
        if (by_image) {
            glBindImageTexture(kFragmentsImage, fragments_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RG32UI);
            glBindImageTexture(kLinksImage, links_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
            glBindImageTexture(kHeadsImage, heads_view->id, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32UI);
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        dispatch_2d(s.width, s.height, 1, 8, 8);
    }
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    // The most layers any pixel holds: the attribute pass classifies those only (the selection
    // stored the clear values of the others).
    GLuint counts[4] = {};
    glGetNamedBufferSubData(counter_.id(), 0, sizeof(counts), counts);
    ctx.layers_filled = std::min<int>(int(counts[2]), s.layers);
    return true;
}

// The geometry pass of the lists: every fragment of every draw appended to its pixel's list; no
// depth test and no attachment (the framebuffer only gives the raster its size).
void VisibilityBufferPass::append(FrameContext& ctx, uint64_t capacity) {
    const RenderSettings& s = ctx.settings;
    const uint64_t pixels = uint64_t(s.width) * uint64_t(s.height);
    if (fragments_.size() < capacity * 8) {
        fragments_.reset();  // the old store goes before the new one is allocated
        links_.reset();
        fragments_ = Buffer::create(capacity * 8);
        links_ = Buffer::create(capacity * 4);
    }
    clear_uints(ctx, heads_, 0, size_t(pixels), 0xffffffffu);  // every list empty
    const GLuint counter[4] = {0, GLuint(capacity), 0, 0};
    counter_.upload(counter, sizeof(counter));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFragmentsBinding, fragments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLinksBinding, links_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kHeadsBinding, heads_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCounterBinding, counter_.id());
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    const std::vector<std::string> stages = {"passes/depth_peel.vert", "passes/visibility_buffer.frag"};
    Defines d = ctx.defines;
    d["VISIBILITY_APPEND"] = "1";
    d["ALPHA_TEST"] = "0";
    d["MARK_TILES"] = "0";  // the selection marks them
    const GLuint prog = visibility_program(ctx, stages, d);
    GLuint alpha_prog = 0;
    if (ctx.gpu_scene.has_alpha_tested()) {
        d["ALPHA_TEST"] = "1";
        alpha_prog = visibility_program(ctx, stages, d);
    }
    for (GLuint p : {prog, alpha_prog})
        if (p) glProgramUniform1ui(p, glGetUniformLocation(p, "u_list_capacity"), GLuint(capacity));
    begin_attachmentless_raster(ctx, empty_fbo_);
    draw_scene(ctx, prog, alpha_prog);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void VisibilityBufferPass::release() {
    tiles_.reset();
    fragments_.reset();
    links_.reset();
    heads_.reset();
    counter_.reset();
    samples_.reset();
    sample_counts_.reset();
    capacity_ = 0;
    empty_fbo_.reset();
    if (!queries_.empty()) glDeleteQueries(GLsizei(queries_.size()), queries_.data());
    queries_.clear();
    fbo_.reset();
}

SSR_REGISTER_PASS(VisibilityBufferPass());

}  // namespace ssr
