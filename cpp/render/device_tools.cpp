// Device tools outside the frame chain: the trace passes' reflection sampling seen alone
// (shaders/tools/brdf_samples.comp), the roofline's microbenchmarks (shaders/tools/microbench.comp),
// the raster floors under the deep G-buffer (shaders/tools/raster_floor.*) and the split-sum table
// of the GGX directional albedo (shaders/tools/specular_albedo.comp).
#include "render/renderer.h"

#include "passes/visibility_buffer.h"

#include <algorithm>
#include <cctype>
#include <numeric>

#include "core/errors.h"
#include "passes/compute.h"

namespace ssr {

namespace {
// The split-sum table (shaders/lib/specular_albedo.glsl): its size and samples per cell (a
// Hammersley set of 4096 VNDF directions: the table is converged to ~1e-4); its texture unit is
// the frame-wide "specular_albedo" (passes/compute.h).
constexpr int kSpecularAlbedoSize = 32;
constexpr unsigned kSpecularAlbedoSamples = 4096;

// The tools' textures and images by name, at units written once here: each shader declares them
// at the names' defines (passes/compute.h, NamedUnits's placed units), and the program is held to
// them. specular_albedo.comp's table; microbench.comp's inputs, the init kernel's outputs, a
// kernel's output and its input as an image; raster_floor.comp's stores and id.
constexpr GLuint kTableImage = 0;
constexpr GLuint kSourceUnit = 0, kChainUnit = 1, kWideUnit = 2;
constexpr GLuint kInitSourceImage = 0, kInitChainImage = 1, kInitWideImage = 2, kOutImage = 0, kInImage = 1;
constexpr GLuint kFloorStoreImages[4] = {0, 1, 2, 3}, kFloorIdImage = 0;

GLuint tool_program(ShaderLibrary& lib, const std::string& shader, Defines d, const NamedUnits& u) {
    u.add_unit_defines(d);
    const GLuint prog = lib.program({shader}, d);
    u.check(prog, shader);
    return prog;
}
NamedUnits tool_units(std::vector<std::pair<std::string, GLuint>> textures,
                      std::vector<std::pair<std::string, GLuint>> images) {
    NamedUnits u;
    u.placed_textures = std::move(textures);
    u.placed_images = std::move(images);
    return u;
}
}  // namespace

void Renderer::bind_specular_albedo() {
    if (!specular_albedo_) {
        specular_albedo_ = Texture::create_2d(GL_RG32F, kSpecularAlbedoSize, kSpecularAlbedoSize, 1);
        specular_albedo_.set_filter(GL_LINEAR, GL_LINEAR);
        specular_albedo_.set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
        const GLuint prog = tool_program(*shaders_, "tools/specular_albedo.comp", {}, tool_units({}, {{"table", kTableImage}}));
        glUseProgram(prog);
        glUniform1ui(glGetUniformLocation(prog, "u_samples"), kSpecularAlbedoSamples);
        glBindImageTexture(kTableImage, specular_albedo_.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
        glDispatchCompute((kSpecularAlbedoSize + 7) / 8, (kSpecularAlbedoSize + 7) / 8, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        check_gl(*ctx_, "specular albedo table");
    }
    glBindTextureUnit(frame_texture_unit("specular_albedo"), specular_albedo_.id());
}

Readback Renderer::specular_albedo_table() {
    {
        CurrentContext current(*ctx_);
        bind_specular_albedo();
    }
    Readback r = read_texture(specular_albedo_, 0);
    // Keep the two channels.
    ReadbackData ab;
    ab.reserve(size_t(r.width) * size_t(r.height) * 2);
    // Readback puts the texture's last row first (row 0 = top of an image); the table keeps
    // its own order: row i is roughness i / (size - 1).
    for (int y = r.height - 1; y >= 0; --y)
        for (int x = 0; x < r.width; ++x) {
            const size_t i = size_t(y) * size_t(r.width) + size_t(x);
            ab.push_back(r.data[4 * i]);
            ab.push_back(r.data[4 * i + 1]);
        }
    r.data = std::move(ab);
    r.channels = 2;
    return r;
}

std::vector<float> Renderer::sample_reflections(const std::string& sampling, float alpha, const glm::vec3& view,
                                               int count, uint32_t seed, bool stratified) {
    if (count < 1 || count > (1 << 24)) throw std::invalid_argument("count must be in [1, 2^24]");
    if (!(alpha >= 0.0f && alpha <= 1.0f)) throw std::invalid_argument("alpha must be in [0, 1]");
    if (!(view.z > 0.0f)) throw std::invalid_argument("view must point above the surface (view.z > 0)");
    const Sampling method = parse_enum<Sampling>("sampling", sampling);
    CurrentContext current(*ctx_);
    const GLuint prog = shaders_->program({"tools/brdf_samples.comp"}, {});
    glUseProgram(prog);
    glUniform3f(glGetUniformLocation(prog, "u_view"), view.x, view.y, view.z);
    glUniform1f(glGetUniformLocation(prog, "u_alpha"), alpha);
    glUniform1i(glGetUniformLocation(prog, "u_method"), int(method));
    glUniform1ui(glGetUniformLocation(prog, "u_count"), GLuint(count));
    glUniform1ui(glGetUniformLocation(prog, "u_seed"), seed);
    glUniform1i(glGetUniformLocation(prog, "u_stratified"), stratified ? 1 : 0);
    const size_t bytes = size_t(count) * 8 * sizeof(float);
    Buffer out = Buffer::create(bytes);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kSamplesBinding, out.id());
    glDispatchCompute(GLuint((count + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<float> data(size_t(count) * 8);
    glGetNamedBufferSubData(out.id(), 0, GLsizeiptr(bytes), data.data());
    check_gl(*ctx_, "sample_reflections");
    return data;
}

std::vector<double> Renderer::microbenchmark(const std::string& kernel, int width, int height, int iterations,
                                             int repeats) {
    static const char* kernels[] = {"coherent", "dependent", "dependent_image", "store", "bandwidth", "copy",
                                    "copy_image"};
    if (std::find_if(std::begin(kernels), std::end(kernels), [&](const char* k) { return kernel == k; }) ==
        std::end(kernels))
        throw std::invalid_argument("microbenchmark kernel '" + kernel +
                                    "' unknown (coherent, dependent, dependent_image, store, bandwidth, copy, copy_image)");
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw std::invalid_argument("microbenchmark width and height must be in [1, 16384]");
    // Store and bandwidth kernels touch one layer per iteration: bounded to keep memory small.
    const int max_iterations = (kernel == "store" || kernel == "bandwidth") ? 16 : 4096;
    if (iterations < 1 || iterations > max_iterations)
        throw std::invalid_argument("microbenchmark iterations must be in [1, " + std::to_string(max_iterations) +
                                    "] for kernel '" + kernel + "'");
    if (repeats < 1 || repeats > 1000) throw std::invalid_argument("microbenchmark repeats must be in [1, 1000]");
    CurrentContext current(*ctx_);
    constexpr int kSourceLayers = 4;
    const bool layered = kernel == "store" || kernel == "bandwidth";
    Texture source = Texture::create_2d_array(GL_RGBA16F, width, height, kSourceLayers);
    Texture chain = Texture::create_2d(GL_RG32F, width, height);
    Texture wide = Texture::create_2d_array(GL_RGBA32F, width, height, kernel == "bandwidth" ? iterations : 1);
    Texture store = Texture::create_2d_array(GL_RGBA16F, width, height, layered ? iterations : 1);
    Texture sink = Texture::create_2d(GL_RGBA32F, width, height);
    const GLuint groups_x = GLuint((width + 7) / 8), groups_y = GLuint((height + 7) / 8);
    // Selects kernel `name` (define KERNEL_<NAME>) with its two uniforms.
    auto use = [&](const std::string& name, int its, int layers) {
        std::string define = "KERNEL_";
        for (char c : name) define += char(std::toupper(static_cast<unsigned char>(c)));
        const NamedUnits units = tool_units(
            {{"source", kSourceUnit}, {"chain", kChainUnit}, {"wide", kWideUnit}},
            {{"init.source", kInitSourceImage}, {"init.chain", kInitChainImage}, {"init.wide", kInitWideImage},
             {"store", kOutImage}, {"sink", kOutImage}, {"chain", kInImage}, {"source", kInImage}});
        const GLuint prog = tool_program(*shaders_, "tools/microbench.comp", {{define, "1"}}, units);
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_iterations"), its);
        glUniform1i(glGetUniformLocation(prog, "u_layers"), layers);
    };
    glBindTextureUnit(kSourceUnit, source.id());
    glBindTextureUnit(kChainUnit, chain.id());
    glBindTextureUnit(kWideUnit, wide.id());
    use("init", wide.layers(), kSourceLayers);
    glBindImageTexture(kInitSourceImage, source.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    glBindImageTexture(kInitChainImage, chain.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
    glBindImageTexture(kInitWideImage, wide.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(groups_x, groups_y, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    use(kernel, iterations, kernel == "store" ? iterations : kSourceLayers);
    if (kernel == "store")
        glBindImageTexture(kOutImage, store.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    else
        glBindImageTexture(kOutImage, sink.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    if (kernel == "dependent_image") glBindImageTexture(kInImage, chain.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RG32F);
    if (kernel == "copy_image") glBindImageTexture(kInImage, source.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
    std::vector<double> ms;
    GpuTimer timer;
    for (int i = -1; i < repeats; ++i) {  // i = -1: untimed (llvmpipe compiles at first dispatch)
        timer.begin_frame();
        if (i >= 0) timer.begin("run");
        glDispatchCompute(groups_x, groups_y, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        if (i >= 0) {
            timer.end("run");
            ms.push_back(timer.resolve()["run"]);
        } else {
            glFinish();
        }
    }
    check_gl(*ctx_, "microbenchmark");
    return ms;
}

namespace {
constexpr GLuint kFloorListEnd = 0xffffffffu;  // an empty list's head, "no sample" in an id target

// Milliseconds of each named interval of one repeat, appended to `out`.
void keep_times(GpuTimer& timer, std::map<std::string, std::vector<double>>& out) {
    for (const auto& [name, ms] : timer.resolve()) out[name].push_back(ms);
}
}  // namespace

std::map<std::string, std::vector<double>> Renderer::raster_floor(const Scene& scene, const Camera& camera,
                                                                  const RenderSettings& s, int repeats) {
    s.validate();
    camera.validate();
    if (repeats < 1 || repeats > 1000) throw std::invalid_argument("raster_floor repeats must be in [1, 1000]");
    CurrentContext current(*ctx_);
    check_gl(*ctx_, "raster_floor (an earlier call left a GL error)");
    const GpuScene& gs = gpu_scene(scene);
    const DepthConvention depth{s.depth_mode};
    const int w = s.width, h = s.height;
    const size_t pixels = size_t(w) * size_t(h);

    // The frame's constants as a render sets those the vertex shader reads (no jitter).
    FrameUniforms u{};
    u.view = camera.view();
    u.inv_view = glm::inverse(u.view);
    u.proj = camera.projection(depth, float(w) / float(h));
    u.inv_proj = glm::inverse(u.proj);
    u.viewport = glm::vec4(w, h, 1.0f / float(w), 1.0f / float(h));
    u.clip = glm::vec4(camera.near_plane, camera.far_plane, 1.0f, 0.0f);
    u.view_proj_unjittered = u.proj * u.view;
    u.previous_view_proj = u.view_proj_unjittered;
    frame_ubo_.upload(&u, sizeof(u));
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameUniformsBinding, frame_ubo_.id());

    // One program per floor: the G-buffer's own vertex shader, a fragment stage that only writes.
    const Defines common = common_defines(scene, gs, depth);
    auto raster_program = [&](const char* floor) {
        Defines d = common;
        d[floor] = "1";
        return shaders_->program({"passes/depth_peel.vert", "tools/raster_floor.frag"}, d);
    };
    const GLuint p_depth = raster_program("FLOOR_DEPTH"), p_gbuffer = raster_program("FLOOR_GBUFFER"),
                 p_id = raster_program("FLOOR_ID"), p_count = raster_program("FLOOR_COUNT"),
                 p_append = raster_program("FLOOR_APPEND"), p_list = raster_program("FLOOR_APPEND_LIST");
    const NamedUnits floor_units = tool_units({}, {{"depth", kFloorStoreImages[0]}, {"albedo", kFloorStoreImages[1]},
                                                   {"normal", kFloorStoreImages[2]}, {"material", kFloorStoreImages[3]},
                                                   {"id", kFloorIdImage}});
    const GLuint p_stores = tool_program(*shaders_, "tools/raster_floor.comp", {{"FLOOR_STORES", "1"}}, floor_units);
    const GLuint p_clear_id = tool_program(*shaders_, "tools/raster_floor.comp", {{"FLOOR_CLEAR_ID", "1"}}, floor_units);
    for (GLuint p : {p_stores, p_clear_id}) glProgramUniform2i(p, glGetUniformLocation(p, "u_size"), w, h);
    // The constructions' own compute clear (passes/clear_layers.comp), for each colour format.
    auto clear_program = [&](const char* qualifier) {
        const GLuint p = shaders_->program({"passes/clear_layers.comp"}, {{"IMAGE_FORMAT", qualifier},
                                                                          {"IMAGE_ARRAY", "0"},
                                                                          {"IMAGE_TARGET", std::to_string(kClearImageUnit)}});
        glProgramUniform2i(p, glGetUniformLocation(p, "u_size"), w, h);
        glProgramUniform1i(p, glGetUniformLocation(p, "u_first"), 0);
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        glProgramUniform4fv(p, glGetUniformLocation(p, "u_value"), 1, zero);
        return p;
    };
    const GLuint p_clear_rgba8 = clear_program("rgba8"), p_clear_rgba16f = clear_program("rgba16f");

    // The G-buffer's targets (passes/depth_peel.cpp's formats), the id target, and the compute
    // floor's targets (the same bytes; image stores take no depth or sRGB format).
    Texture t_depth = Texture::create_2d(GL_DEPTH_COMPONENT32F, w, h);
    Texture t_albedo = Texture::create_2d(GL_SRGB8_ALPHA8, w, h);
    Texture t_normal = Texture::create_2d(GL_RGBA16F, w, h);
    Texture t_material = Texture::create_2d(GL_RGBA8, w, h);
    Texture t_id = Texture::create_2d(GL_R32UI, w, h);
    Texture c_depth = Texture::create_2d(GL_R32F, w, h);
    Texture c_albedo = Texture::create_2d(GL_RGBA8, w, h);
    Texture c_normal = Texture::create_2d(GL_RGBA16F, w, h);
    Texture c_material = Texture::create_2d(GL_RGBA8, w, h);
    Framebuffer fb_depth = Framebuffer::create(), fb_gbuffer = Framebuffer::create(), fb_id = Framebuffer::create(),
                fb_empty = Framebuffer::create();
    fb_depth.attach(GL_DEPTH_ATTACHMENT, t_depth);
    glNamedFramebufferDrawBuffer(fb_depth.id(), GL_NONE);
    fb_depth.check_complete("raster_floor depth");
    fb_gbuffer.attach(GL_DEPTH_ATTACHMENT, t_depth);
    fb_gbuffer.attach(GL_COLOR_ATTACHMENT0, t_albedo);
    fb_gbuffer.attach(GL_COLOR_ATTACHMENT1, t_normal);
    fb_gbuffer.attach(GL_COLOR_ATTACHMENT2, t_material);
    const GLenum three[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glNamedFramebufferDrawBuffers(fb_gbuffer.id(), 3, three);
    fb_gbuffer.check_complete("raster_floor gbuffer");
    fb_id.attach(GL_DEPTH_ATTACHMENT, t_depth);
    fb_id.attach(GL_COLOR_ATTACHMENT0, t_id);
    glNamedFramebufferDrawBuffer(fb_id.id(), GL_COLOR_ATTACHMENT0);
    fb_id.check_complete("raster_floor id");
    // The append draws write storage buffers only: a framebuffer without attachments sizes the raster.
    glNamedFramebufferDrawBuffer(fb_empty.id(), GL_NONE);
    glNamedFramebufferParameteri(fb_empty.id(), GL_FRAMEBUFFER_DEFAULT_WIDTH, w);
    glNamedFramebufferParameteri(fb_empty.id(), GL_FRAMEBUFFER_DEFAULT_HEIGHT, h);

    const int bits = VisibilityBufferPass::primitive_bits(gs, DeepGBuffer::Visibility);
    gs.bind_geometry();
    glViewport(0, 0, w, h);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    apply_peel_culling(s);
    // Every object in the scene's order, opaque: an alpha-tested material's holes are the
    // material's work, not the raster's.
    auto draw = [&](GLuint prog) {
        glUseProgram(prog);
        const GLint loc_object = glGetUniformLocation(prog, "u_object"), loc_base = glGetUniformLocation(prog, "u_id_base");
        for (const DrawItem& d : gs.draws()) {
            glUniform1i(loc_object, d.object);
            glUniform1ui(loc_base, GLuint(d.object) << bits);
            glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                     reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
        }
    };
    // A depth-tested draw into `fb` (depth written, the frame's depth convention).
    auto depth_tested = [&](const Framebuffer& fb, GLuint prog, bool srgb) {
        glBindFramebuffer(GL_FRAMEBUFFER, fb.id());
        depth.apply_gl_state();
        glEnable(GL_DEPTH_TEST);
        glDepthMask(GL_TRUE);
        if (srgb) glEnable(GL_FRAMEBUFFER_SRGB);
        draw(prog);
        glDisable(GL_FRAMEBUFFER_SRGB);
    };
    // A draw without depth test into `fb_empty`: every fragment runs the shader.
    auto every_fragment = [&](GLuint prog) {
        glBindFramebuffer(GL_FRAMEBUFFER, fb_empty.id());
        depth.apply_gl_state();  // the clip control: the window depths the G-buffer gets
        glDisable(GL_DEPTH_TEST);
        draw(prog);
        glEnable(GL_DEPTH_TEST);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    };
    const float clear_depth = depth.clear_depth();
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    auto clear_gbuffer = [&] {
        glClearNamedFramebufferfv(fb_gbuffer.id(), GL_DEPTH, 0, &clear_depth);
        for (GLint i = 0; i < 3; ++i) glClearNamedFramebufferfv(fb_gbuffer.id(), GL_COLOR, i, zero);
    };
    const GLuint groups_x = GLuint((w + 7) / 8), groups_y = GLuint((h + 7) / 8);
    auto dispatch = [&](GLuint prog) {
        glUseProgram(prog);
        glDispatchCompute(groups_x, groups_y, 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    };
    const GLuint none = kFloorListEnd, zero_u = 0;

    // Untimed: every fragment counted per pixel, and the counts' prefix sum as each pixel's offset
    // into the append's array (the least memory an exact list of every fragment takes: 8 bytes each).
    std::map<std::string, std::vector<double>> out;
    Buffer counts = Buffer::create(sizeof(GLuint) * pixels);
    Buffer offsets = Buffer::create(sizeof(GLuint) * pixels);
    glClearNamedBufferData(counts.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero_u);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorCountsBinding, counts.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorOffsetsBinding, offsets.id());
    GLuint query = 0;
    glGenQueries(1, &query);
    struct DeleteQuery {
        GLuint q;
        ~DeleteQuery() { glDeleteQueries(1, &q); }
    } delete_query{query};
    auto samples_of = [&](auto&& run) {
        glBeginQuery(GL_SAMPLES_PASSED, query);
        run();
        glEndQuery(GL_SAMPLES_PASSED);
        GLuint64 n = 0;
        glGetQueryObjectui64v(query, GL_QUERY_RESULT, &n);
        return double(n);
    };
    out["count.fragments_rasterised"] = {samples_of([&] { every_fragment(p_count); })};
    std::vector<GLuint> per_pixel(pixels), offset(pixels);
    glGetNamedBufferSubData(counts.id(), 0, GLsizeiptr(sizeof(GLuint) * pixels), per_pixel.data());
    uint64_t fragments = 0;
    GLuint deepest = 0, covered = 0;
    for (size_t i = 0; i < pixels; ++i) {
        offset[i] = GLuint(fragments);
        fragments += per_pixel[i];
        deepest = std::max(deepest, per_pixel[i]);
        covered += per_pixel[i] > 0 ? 1u : 0u;
    }
    out["count.fragments"] = {double(fragments)};
    out["count.max_fragments_per_pixel"] = {double(deepest)};
    out["count.pixels_with_fragments"] = {double(covered)};
    out["count.triangles"] = {double(gs.triangle_count())};
    // The lists hold every fragment in one storage block (as the constructions' do): beyond the
    // device's largest, the append floors are left out (no "append" keys).
    const bool appends = fragments > 0 && fragments * 8 <= DepthPeelPass::store_limit_bytes(0) &&
                         fragments < uint64_t(kFloorListEnd);
    Buffer stored, links, heads, counter;
    if (appends) {
        offsets.upload(offset.data(), sizeof(GLuint) * pixels);
        stored = Buffer::create(size_t(fragments) * 8);
        links = Buffer::create(size_t(fragments) * 4);
        heads = Buffer::create(sizeof(GLuint) * pixels);
        counter = Buffer::create(sizeof(GLuint));
    }
    auto bind_array = [&] {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorCountsBinding, counts.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorOffsetsBinding, offsets.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorFragmentsBinding, stored.id());
    };
    auto bind_list = [&] {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorHeadsBinding, heads.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorLinksBinding, links.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorFragmentsBinding, stored.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFloorCounterBinding, counter.id());
    };

    // Untimed: the depth and the id draws' samples, and the pixels each covers.
    glClearNamedFramebufferfv(fb_depth.id(), GL_DEPTH, 0, &clear_depth);
    out["count.samples_depth"] = {samples_of([&] { depth_tested(fb_depth, p_depth, false); })};
    std::vector<float> depths(pixels);
    glGetTextureImage(t_depth.id(), 0, GL_DEPTH_COMPONENT, GL_FLOAT, GLsizei(sizeof(float) * pixels), depths.data());
    out["count.pixels_depth"] = {double(std::count_if(depths.begin(), depths.end(),
                                                      [&](float z) { return z != clear_depth; }))};
    glClearTexImage(t_id.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &none);
    glClearNamedFramebufferfv(fb_id.id(), GL_DEPTH, 0, &clear_depth);
    out["count.samples_id"] = {samples_of([&] { depth_tested(fb_id, p_id, false); })};
    std::vector<GLuint> ids(pixels);
    glGetTextureImage(t_id.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, GLsizei(sizeof(GLuint) * pixels), ids.data());
    out["count.pixels_id"] = {double(std::count_if(ids.begin(), ids.end(), [](GLuint i) { return i != kFloorListEnd; }))};

    const Texture* stores[4] = {&c_depth, &c_albedo, &c_normal, &c_material};  // raster_floor.comp's stores
    // Every floor in turn, each repeat; repeat -1 is untimed (llvmpipe compiles a variant at its
    // first draw or dispatch, and first writes into new textures cost more on some GPUs).
    // Each floor is timed alone, the device idle before it. On the CPU device each timestamp is
    // also given a scene of its own: llvmpipe bins a timestamp into every tile of the scene being
    // recorded and its rasteriser threads write it as they reach it, so that a timestamp sharing a
    // scene with the draws it should bracket records one tile's progress, not the draw's. The
    // first is waited for (a compute dispatch runs at once on the CPU, and would otherwise race
    // the rasteriser thread writing the timestamp); the last is flushed after the work, and
    // written once that is done. A GPU's timestamps are exact without them (a wait inside the
    // interval would count a round trip to the host there).
    const bool cpu_device = ctx_->info().chosen == "cpu";
    GpuTimer timer;
    for (int i = -1; i < repeats; ++i) {
        timer.begin_frame();
        auto timed = [&](const std::string& name, auto&& run) {
            glFinish();
            timer.begin(name);
            if (cpu_device) glFinish();
            run();
            if (cpu_device) glFlush();
            timer.end(name);
            if (cpu_device) glFlush();
        };
        timed("clear.depth", [&] { glClearNamedFramebufferfv(fb_depth.id(), GL_DEPTH, 0, &clear_depth); });
        timed("depth", [&] { depth_tested(fb_depth, p_depth, false); });
        timed("clear.gbuffer", clear_gbuffer);
        timed("gbuffer", [&] { depth_tested(fb_gbuffer, p_gbuffer, true); });
        glClearNamedFramebufferfv(fb_id.id(), GL_DEPTH, 0, &clear_depth);
        timed("id", [&] { depth_tested(fb_id, p_id, false); });
        timed("clear.id_texture", [&] {
            glClearTexImage(t_id.id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &none);
        });
        timed("clear.id_compute", [&] {
            glBindImageTexture(kFloorIdImage, t_id.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32UI);
            dispatch(p_clear_id);
        });
        if (appends) {
            timed("clear.counters", [&] {
                glClearNamedBufferData(counts.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero_u);
            });
            bind_array();
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            timed("append", [&] { every_fragment(p_append); });
            timed("clear.heads", [&] {
                glClearNamedBufferData(heads.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &none);
                glClearNamedBufferData(counter.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero_u);
            });
            bind_list();
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
            timed("append_list", [&] { every_fragment(p_list); });
        }
        timed("stores", [&] {
            for (int i = 0; i < 4; ++i) {
                const Texture& t = *stores[i];
                glBindImageTexture(kFloorStoreImages[i], t.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, t.format());
            }
            dispatch(p_stores);
        });
        // One dispatch per target, as passes/compute.h's clear_layers does.
        timed("clear.compute_colour", [&] {
            for (const Texture* t : {&c_albedo, &c_normal, &c_material}) {
                glBindImageTexture(kClearImageUnit, t->id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, t->format());
                dispatch(t->format() == GL_RGBA16F ? p_clear_rgba16f : p_clear_rgba8);
            }
        });
        if (i >= 0) {
            keep_times(timer, out);
        } else {
            timer.resolve();
            glFinish();
        }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_CULL_FACE);
    depth.apply_gl_state();
    // The append's own count of what it stored (every pixel's counter after the last repeat).
    if (appends) {
        glGetNamedBufferSubData(counts.id(), 0, GLsizeiptr(sizeof(GLuint) * pixels), per_pixel.data());
        out["count.fragments_appended"] = {double(std::accumulate(per_pixel.begin(), per_pixel.end(), uint64_t(0)))};
        GLuint slots = 0;
        glGetNamedBufferSubData(counter.id(), 0, sizeof(GLuint), &slots);
        out["count.fragments_listed"] = {double(slots)};
    }
    check_gl(*ctx_, "raster_floor");
    return out;
}

}  // namespace ssr
