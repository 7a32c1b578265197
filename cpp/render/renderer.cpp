#include "render/renderer.h"

#include <algorithm>
#include <thread>
#include <cmath>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <limits>
#include <glm/gtc/matrix_transform.hpp>
#include <set>
#if defined(__GLIBC__)
#include <malloc.h>  // malloc_trim
#endif

#include "core/errors.h"
#include "render/ssr_uniforms.h"

#ifndef GL_PACK_INVERT_MESA
#define GL_PACK_INVERT_MESA 0x8758  // GL_MESA_pack_invert, where the GL headers lack it
#endif

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SSR_HAVE_F16C_PATH 1
#else
#define SSR_HAVE_F16C_PATH 0
#endif

namespace ssr {

namespace {

#if SSR_HAVE_F16C_PATH
// Half floats to floats with the CPU's F16C conversion (exact, NaN and infinity kept): an
// RGBA16F texture downloaded as stored (into memory not zeroed first) and widened here took
// 0.52-0.53x the time of asking llvmpipe for GL_FLOAT at 640x360, 0.65-0.69x at 1920x1080
// (benchmarks/readback.py).
// Compiled for F16C alone and called only where the CPU has it.
__attribute__((target("avx,f16c"))) void widen_halves_f16c(const uint16_t* in, float* out, size_t n) {
    size_t i = 0;
    for (; i + 8 <= n; i += 8)
        _mm256_storeu_ps(out + i, _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i))));
    for (; i < n; ++i) out[i] = _cvtsh_ss(in[i]);
}

bool cpu_has_f16c() {
    static const bool has = __builtin_cpu_supports("avx") && __builtin_cpu_supports("f16c");
    return has;
}
#else
void widen_halves_f16c(const uint16_t*, float*, size_t) {}
bool cpu_has_f16c() { return false; }
#endif

// Bytes of memory the system can still give (Linux's MemAvailable), 0 where unknown. On
// llvmpipe textures live in this memory, and an allocation beyond it succeeds (overcommit)
// only for the process to be killed when the first pass writes the pages.
size_t system_memory_available() {
    std::FILE* f = std::fopen("/proc/meminfo", "r");
    if (!f) return 0;
    char line[256];
    unsigned long long kib = 0;
    while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "MemAvailable: %llu kB", &kib) == 1) break;
    std::fclose(f);
    return size_t(kib) * 1024;
}

std::string gib(size_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.2f GiB", double(bytes) / double(size_t(1) << 30));
    return text;
}

constexpr size_t kSceneCacheSize = 8;
constexpr size_t kPoolSize = 4;  // idle texture sets kept for reuse
constexpr size_t kMaxWarmedVariants = 1024;  // forgotten (and warmed again) beyond this
// The split-sum table (shaders/lib/specular_albedo.glsl): its size, texture unit and samples
// per cell (a Hammersley set of 4096 VNDF directions: the table is converged to ~1e-4).
constexpr int kSpecularAlbedoSize = 32;
constexpr int kSpecularAlbedoUnit = 13;
constexpr unsigned kSpecularAlbedoSamples = 4096;
// llvmpipe keeps textures in host memory from malloc; glibc keeps freed blocks in its heap,
// so memory of dropped frames stayed with the process (6.9 GB after 400 kept-then-dropped
// frames) until malloc_trim returns it, once this much was freed since the last trim.
constexpr size_t kTrimBytes = size_t(8) << 20;
}  // namespace

// The scene's light count compiled into every pass (up to 8; lib/lights.glsl), whose
// shading then reads every light once before any control flow: llvmpipe loads a storage-buffer
// value inside a loop one lane and one component at a time. Beyond 8 the loop reads the buffer.
static void add_light_count(Defines& defines, const Scene& scene) {
    if (scene.lights.size() <= 8) defines["LIGHT_COUNT"] = std::to_string(scene.lights.size());
}

std::shared_ptr<Renderer> Renderer::create(const std::string& device, const std::string& shader_dir,
                                           const std::string& input_fetch) {
    if (input_fetch != "auto" && input_fetch != "imageLoad" && input_fetch != "texelFetch")
        throw std::invalid_argument("Renderer.input_fetch must be 'auto', 'imageLoad' or 'texelFetch', got '" +
                                    input_fetch + "'");
    return std::shared_ptr<Renderer>(new Renderer(device, shader_dir, input_fetch));
}

Renderer::Renderer(const std::string& device, const std::string& shader_dir, const std::string& input_fetch)
    : ctx_(std::make_shared<EglContext>(parse_device_kind(device), parse_device_index(device))),
      shaders_(std::make_unique<ShaderLibrary>(shader_dir)) {
    // The reflection settings' block, declared once in settings_fields.def (lib/ssr_settings.glsl).
    shaders_->add_generated(kSsrSettingsGlslName, ssr_settings_glsl());
    CurrentContext current(*ctx_);
    frame_ubo_ = Buffer::create(sizeof(FrameUniforms));
    glCreateSamplers(1, &readback_sampler_);
    glSamplerParameteri(readback_sampler_, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glSamplerParameteri(readback_sampler_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glSamplerParameteri(readback_sampler_, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size_);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_array_layers_);
    GLint extensions = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &extensions);
    for (GLint i = 0; i < extensions; ++i) {
        const char* name = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)));
        if (name && std::strcmp(name, "GL_MESA_pack_invert") == 0) pack_invert_ = true;
    }
    // On the CPU device the passes read float textures by imageLoad (lib/input_fetch.glsl:
    // llvmpipe's texelFetch of a float format is a call to a generic sampling function; a chain of
    // dependent RG32F fetches ran 1.9x faster by imageLoad). GPUs keep texelFetch, the path measured
    // there. A pass binds up to kImageUnitsPerPass images, outputs and inputs together.
    GLint compute_images = 0, image_units = 0;
    glGetIntegerv(GL_MAX_COMPUTE_IMAGE_UNIFORMS, &compute_images);
    glGetIntegerv(GL_MAX_IMAGE_UNITS, &image_units);
    const bool images_enough = std::min(compute_images, image_units) >= kImageUnitsPerPass;
    if (input_fetch == "imageLoad" && !images_enough)
        throw std::invalid_argument("Renderer.input_fetch 'imageLoad' needs " + std::to_string(kImageUnitsPerPass) +
                                    " image units in a compute shader; this device offers " +
                                    std::to_string(std::min(compute_images, image_units)));
    fetch_by_image_ = input_fetch == "imageLoad" || (input_fetch == "auto" && ctx_->info().chosen == "cpu" && images_enough);
    check_gl(*ctx_, "renderer start-up");
}

Renderer::~Renderer() {
    // Every GL object of the renderer dies in its own context: current for the destructor's
    // body and for the members' destructors that follow it (destroy_gl_objects).
    try {
        CurrentContext current(*ctx_);
        destroy_gl_objects();
    } catch (...) {
        // The context is current on another thread (not possible while Python holds the GIL
        // for every call): the objects are left to the context's own destruction.
    }
}

void Renderer::destroy_gl_objects() {
    if (readback_sampler_) glDeleteSamplers(1, &readback_sampler_);
    readback_sampler_ = 0;
    scenes_.clear();
    pool_.clear();
    scratch_ = FrameResources();
    frame_ubo_.reset();
    ssr_ubo_.reset();
    lights_ssbo_.reset();
    readback_ssbo_.reset();
    readback_staging_.reset();
    specular_albedo_.reset();
    timer_.reset();
    shaders_->release();
    shadow_map_.release();
    depth_peel_.release();
    fallback_probes_shadowed_.release();
    fallback_probes_unshadowed_.release();
}

const GpuScene& Renderer::gpu_scene(const Scene& scene) {
    for (auto it = scenes_.begin(); it != scenes_.end(); ++it) {
        if (it->id == scene.id()) {
            if (it->gpu->revision() != scene.revision()) {
                it->gpu = std::make_unique<GpuScene>(scene, &bvh_builds_);
                ++scene_uploads_;
            }
            scenes_.splice(scenes_.begin(), scenes_, it);
            return *scenes_.front().gpu;
        }
    }
    scenes_.push_front(CachedScene{scene.id(), std::make_unique<GpuScene>(scene, &bvh_builds_)});
    ++scene_uploads_;
    if (scenes_.size() > kSceneCacheSize) scenes_.pop_back();
    return *scenes_.front().gpu;
}

std::shared_ptr<FrameResources> Renderer::acquire(const std::vector<ResourceDesc>& descs) {
    // A texture set no Frame holds any more (use_count 1: only the pool) is reused as is
    // when its descriptions match.
    for (auto& r : pool_)
        if (r.use_count() == 1 && r->descs() == descs) return r;
    pool_.erase(std::remove_if(pool_.begin(), pool_.end(),
                               [&](const auto& r) {
                                   if (r.use_count() != 1) return false;
                                   freed_since_trim_ += r->bytes();
                                   return true;
                               }),
                pool_.end());
    auto fresh = std::make_shared<FrameResources>();
    fresh->allocate(descs);
    pool_.push_back(fresh);
    return fresh;
}

// The frame as a chain of passes. Passes a frame does not need are left out: no shadow map
// without a shadow caster, no tracing without a reflective surface or with method "off",
// no Hi-Z pyramid for the linear tracer (unless the cone needs it), no pre-convolution or
// pre-integrated visibility for stochastic glossy reflections.
std::vector<RenderPass*> Renderer::build_chain(const RenderSettings& s, const FrameFacts& facts) const {
    std::vector<RenderPass*> chain;
    for (RenderPass* p : passes_)
        if (p->runs(s, facts)) chain.push_back(p);
    return chain;
}

FrameFacts Renderer::facts(const Scene& scene, const GpuScene& gs, const RenderSettings& s) const {
    FrameFacts f;
    f.shadows = ShadowMapPass::fit(scene, gs.bounds(), s).enabled;
    f.reflections = s.method != TraceMethod::Off && gs.has_reflective_surfaces();
    f.fetch_by_image = fetch_by_image_;
    return f;
}

// What makes two frames share their first-use costs: the passes, their textures' formats and
// sizes, and the common shader defines (render() adds the scene: its buffers' first use).
std::string Renderer::variant_key(const std::vector<RenderPass*>& chain, const std::vector<ResourceDesc>& descs,
                                  const Defines& defines) {
    std::string key;
    for (RenderPass* p : chain) key += p->name() + ";";
    for (const auto& d : descs)
        key += d.name + ":" + std::to_string(d.format) + "," + std::to_string(d.width) + "x" + std::to_string(d.height) +
               "x" + std::to_string(d.layers) + "/" + std::to_string(d.levels) + ";";
    for (const auto& [k, v] : defines) key += k + "=" + v + ";";
    return key;
}

void Renderer::bind_specular_albedo() {
    if (!specular_albedo_) {
        specular_albedo_ = Texture::create_2d(GL_RG32F, kSpecularAlbedoSize, kSpecularAlbedoSize, 1);
        specular_albedo_.set_filter(GL_LINEAR, GL_LINEAR);
        specular_albedo_.set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
        const GLuint prog = shaders_->program({"tools/specular_albedo.comp"}, {});
        glUseProgram(prog);
        glUniform1ui(glGetUniformLocation(prog, "u_samples"), kSpecularAlbedoSamples);
        glBindImageTexture(0, specular_albedo_.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
        glDispatchCompute((kSpecularAlbedoSize + 7) / 8, (kSpecularAlbedoSize + 7) / 8, 1);
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        check_gl(*ctx_, "specular albedo table");
    }
    glBindTextureUnit(kSpecularAlbedoUnit, specular_albedo_.id());
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

void Renderer::upload_lights(const Scene& scene, const glm::mat4& view, int shadow_light) {
    std::vector<GpuLight> lights;
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& l = scene.lights[i];
        GpuLight g{};
        g.position_type = glm::vec4(glm::vec3(view * glm::vec4(l.position, 1.0f)),
                                    l.type == Light::Type::Directional ? 0.0f : (l.type == Light::Type::Spot ? 2.0f : 1.0f));
        g.direction_shadow = glm::vec4(glm::mat3(view) * glm::normalize(l.direction),
                                       (int(i) == shadow_light) ? 1.0f : 0.0f);
        g.radiance = glm::vec4(l.color * l.intensity, 0.0f);
        // KHR_lights_punctual's recommended spot falloff: clamp(cos * scale + offset, 0, 1)^2.
        g.cone = glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);
        if (l.type == Light::Type::Spot) {
            const float scale = 1.0f / std::max(0.001f, std::cos(l.inner_cone) - std::cos(l.outer_cone));
            g.cone.x = scale;
            g.cone.y = -std::cos(l.outer_cone) * scale;
        }
        if (l.type != Light::Type::Directional && l.range > 0.0f) g.cone.z = 1.0f / (l.range * l.range);
        lights.push_back(g);
    }
    const size_t light_bytes = std::max<size_t>(lights.size() * sizeof(GpuLight), sizeof(GpuLight));
    if (lights_ssbo_.size() < light_bytes) lights_ssbo_ = Buffer::create(light_bytes);
    if (!lights.empty()) lights_ssbo_.upload(lights.data(), lights.size() * sizeof(GpuLight));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLightsBinding, lights_ssbo_.id());
}

// The sub-pixel jitter of frame `index` of a sequence, in pixels within [-0.5, 0.5)^2.
// clamped: the Halton (2, 3) sequence, points 1, 2, ... (point 0 is the origin); thesis: the
// thesis's two alternating jitters (seed 000, 2.5: even frames share one, odd frames the other),
// a quarter pixel along the diagonal either way.
glm::vec2 Renderer::taa_jitter(TaaMode mode, int index) {
    if (mode == TaaMode::Thesis) return (index % 2 == 0) ? glm::vec2(0.25f, 0.25f) : glm::vec2(-0.25f, -0.25f);
    auto radical_inverse = [](unsigned i, unsigned base) {
        double f = 1.0, r = 0.0;
        while (i > 0) {
            f /= base;
            r += f * (i % base);
            i /= base;
        }
        return r;
    };
    const unsigned i = unsigned(index % 1024) + 1;
    return glm::vec2(float(radical_inverse(i, 2) - 0.5), float(radical_inverse(i, 3) - 0.5));
}

std::vector<Renderer::ChainEntry> Renderer::chain(const Scene& scene, const RenderSettings& s) {
    s.validate();
    CurrentContext current(*ctx_);
    const GpuScene& gs = gpu_scene(scene);
    std::vector<ChainEntry> out;
    for (RenderPass* p : build_chain(s, facts(scene, gs, s))) {
        ChainEntry e{p->name(), p->inputs(), {}};
        for (const auto& d : p->outputs(s)) e.outputs.push_back(d.name);
        out.push_back(std::move(e));
    }
    return out;
}

std::shared_ptr<Frame> Renderer::render(const Scene& scene, const Camera& camera, const RenderSettings& s,
                                        Sequence* sequence) {
    const auto wall_start = std::chrono::steady_clock::now();
    s.validate();
    camera.validate();
    CurrentContext current(*ctx_);
    check_gl(*ctx_, "render (an earlier call left a GL error)");

    const GpuScene& gs = gpu_scene(scene);
    check_gl(*ctx_, "scene upload");
    const DepthConvention depth{s.depth_mode};
    const ShadowSetup shadow = ShadowMapPass::fit(scene, gs.bounds(), s);
    shadow_map_.set_setup(shadow);

    // Frame constants.
    FrameUniforms u{};
    const float aspect = float(s.width) / float(s.height);
    u.view = camera.view();
    u.inv_view = glm::inverse(u.view);
    u.proj = camera.projection(depth, aspect);
    const glm::mat4 unjittered_proj = u.proj;
    // TAA's sub-pixel jitter (seed 000, 2.5): a shift of the whole projection by a fraction of a
    // pixel, a different one each frame of a sequence (frame 0 outside one).
    const glm::vec2 jitter_px = s.taa == TaaMode::Off ? glm::vec2(0.0f) : taa_jitter(s.taa, sequence ? sequence->frames : 0);
    // ndc.x = P00 x / d - P[2][0] (d the positive view depth): subtracting 2 j / W shifts the image by +j pixels.
    u.proj[2][0] -= 2.0f * jitter_px.x / float(s.width);
    u.proj[2][1] -= 2.0f * jitter_px.y / float(s.height);
    u.inv_proj = glm::inverse(u.proj);
    const glm::mat4 to_unit = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f)) * glm::scale(glm::mat4(1.0f), glm::vec3(0.5f));
    u.view_to_shadow = to_unit * shadow.light_view_proj * u.inv_view;
    u.viewport = glm::vec4(s.width, s.height, 1.0f / float(s.width), 1.0f / float(s.height));
    u.clip = glm::vec4(camera.near_plane, camera.far_plane, float(s.layers), float(scene.lights.size()));
    u.ambient = glm::vec4(scene.ambient, 0.0f);
    u.shadow = glm::vec4(shadow.enabled ? 1.0f : 0.0f, shadow.texel_world_size, s.shadow_normal_offset,
                         float(s.shadow_pcf_radius));
    const Environment& env = scene.environment;
    u.env_params = glm::vec4(float(int(env.type)), env.intensity, 0.0f, 0.0f);
    u.env_color = glm::vec4(env.color, 0.0f);
    u.env_zenith = glm::vec4(env.sky_zenith, 0.0f);
    u.env_horizon = glm::vec4(env.sky_horizon, 0.0f);
    u.env_ground = glm::vec4(env.ground, 0.0f);
    frame_ubo_.upload(&u, sizeof(u));
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameUniformsBinding, frame_ubo_.id());

    upload_lights(scene, u.view, shadow.enabled ? shadow.light : -1);

    // Reflection settings as the shaders see them.
    const SsrUniforms su = ssr_uniforms(s);
    if (!ssr_ubo_) ssr_ubo_ = Buffer::create(sizeof(SsrUniforms));
    ssr_ubo_.upload(&su, sizeof(su));
    glBindBufferBase(GL_UNIFORM_BUFFER, kSsrSettingsBinding, ssr_ubo_.id());
    if (gs.environment_map()) glBindTextureUnit(15, gs.environment_map());
    bind_specular_albedo();
    gs.bind_geometry();  // the scene's objects and materials, for every pass that reads them

    // The chain, its resources, and a check that every input is written before it is read.
    const std::vector<RenderPass*> chain = build_chain(s, facts(scene, gs, s));
    std::vector<ResourceDesc> descs;
    std::set<std::string> written;
    for (RenderPass* p : chain) {
        for (const auto& in : p->inputs())
            if (!written.count(in))
                throw GLError("pass " + p->name() + " reads '" + in + "', which no earlier pass writes");
        for (const auto& d : p->outputs(s)) {
            descs.push_back(d);
            written.insert(d.name);
        }
    }
    // Every texture within the device's limits before any is allocated (GL would only answer
    // GL_INVALID_VALUE): the message names the texture and the settings that size it.
    for (const auto& d : descs) {
        if (d.width > max_texture_size_ || d.height > max_texture_size_) {
            const std::string limit = "this device's GL_MAX_TEXTURE_SIZE (" + std::to_string(max_texture_size_) + ")";
            if (d.name == "shadow_map")
                throw std::invalid_argument("Settings.shadow_map_size = " + std::to_string(d.width) + " is beyond " +
                                            limit);
            throw std::invalid_argument(
                "Settings.width x Settings.height = " + std::to_string(s.width) + " x " + std::to_string(s.height) +
                " needs the texture '" + d.name + "' of " + std::to_string(d.width) + " x " + std::to_string(d.height) +
                " texels, beyond " + limit + ": render a smaller image");
        }
        if (d.layers > max_array_layers_)
            throw std::invalid_argument("the texture '" + d.name + "' needs " + std::to_string(d.layers) +
                                        " layers, beyond this device's GL_MAX_ARRAY_TEXTURE_LAYERS (" +
                                        std::to_string(max_array_layers_) + "): lower Settings.layers or rays_per_pixel");
    }
    // Each pass's limits of this device (a buffer it would allocate), refused before anything is.
    for (const RenderPass* p : chain) p->check_device(s);
    // On the CPU device the textures take system memory: a frame that cannot fit is refused
    // here rather than killed by the OS mid-frame (idle texture sets and scratch can be reused).
    // Asked of the system only beyond 256 MiB of new textures, not on every ordinary frame.
    size_t needed = 0;
    for (const auto& d : descs) needed += texture_bytes(d);
    const std::string sized_by = "Settings (" + std::to_string(s.width) + " x " + std::to_string(s.height) +
                                 ", layers " + std::to_string(s.layers) + ", rays_per_pixel " +
                                 std::to_string(s.rays_per_pixel) + ")";
    if (ctx_->info().chosen == "cpu") {
        size_t reusable = scratch_.bytes();
        for (const auto& r : pool_)
            if (r.use_count() == 1) reusable += r->bytes();
        const size_t available = needed > reusable + (size_t(256) << 20) ? system_memory_available() : 0;
        if (available > 0 && needed > available + reusable)
            throw std::invalid_argument(sized_by + " need " + gib(needed) + " of textures, more than the " +
                                        gib(available + reusable) +
                                        " of memory available to the CPU device: render a smaller image or "
                                        "fewer layers or rays");
    }
    // Scratch textures (shadow map, Hi-Z) live once per renderer; the frame gets the rest.
    std::vector<ResourceDesc> own, scratch;
    for (const auto& d : descs) (is_scratch(d.name) ? scratch : own).push_back(d);
    auto resources = acquire(own);
    scratch_.add(scratch);
    const uint64_t serial = next_serial_++;
    for (const auto& d : scratch) scratch_owner_.erase(d.name);  // until the chain has written them
    resources->attach_scratch(&scratch_);
    struct Detach {
        FrameResources& r;
        ~Detach() { r.attach_scratch(nullptr); }
    } detach{*resources};
    check_gl(*ctx_, ("frame allocation (" + sized_by + ": " + gib(needed) + " of textures)").c_str());

    Defines defines;
    depth.add_defines(defines);
    defines["ENVIRONMENT_MAP"] = gs.environment_map() ? "1" : "0";
    // The scene's environment type compiled into every pass (lib/environment.glsl):
    // llvmpipe runs both sides of a branch, so a run-time choice paid for every kind.
    defines["ENVIRONMENT_TYPE"] = std::to_string(int(scene.environment.type));
    defines["FETCH_BY_IMAGE"] = fetch_by_image_ ? "1" : "0";
    add_light_count(defines, scene);
    FrameContext fc{*ctx_, *shaders_, timer_, s, scene, gs, camera, depth, u, *resources, defines};
    fc.clear_by_compute = clear_by_compute();
    if (sequence && sequence->usable(s, scene.id(), scene.revision()) && sequence->previous != resources) {
        fc.history = sequence->previous.get();
        fc.history_uniforms = &sequence->previous_uniforms;
        fc.history_unjittered_proj = sequence->previous_unjittered_proj;
    }
    fc.jitter_px = jitter_px;
    auto frame = std::make_shared<Frame>(ctx_, weak_from_this(), resources);
    // Timings never include first-use costs. The first run of a variant (this chain, these
    // defines and texture sizes, this scene) compiles its programs, and drivers such as llvmpipe compile
    // shader variants at their first dispatch or draw; so a variant not seen before runs the
    // chain once untimed and the frame reports the second run. A timed run that still had to
    // compile a program (a pass choosing a define from the settings) is also run again.
    const std::string variant = variant_key(chain, descs, defines) + "scene:" + std::to_string(scene.id()) + "/" +
                                std::to_string(scene.revision());
    bool warm = warmed_variants_.count(variant) != 0;
    // Each pass's own checks of the user's input, before any pass runs.
    for (RenderPass* p : chain) p->check(scene, gs, s);
    auto first_uses = [&chain] {
        uint64_t n = 0;
        for (const RenderPass* p : chain) n += p->first_uses();
        return n;
    };
    for (int run = 0;; ++run) {
        const size_t programs_before = shaders_->cached_programs();
        const uint64_t first_uses_before = first_uses();
        timer_.begin_frame();
        frame->passes.clear();
        fc.layers_used = -1;
        for (RenderPass* p : chain) {
            {
                GpuScope t(timer_, p->name());
                p->execute(fc);
            }
            check_gl(*ctx_, p->name().c_str());
            frame->passes.push_back(p->name());
        }
        // Work a pass caches across frames (a probe capture) is a first-use cost too.
        const bool compiled = shaders_->cached_programs() != programs_before || first_uses() != first_uses_before;
        if ((warm && !compiled) || run >= 2) break;
        warm = true;
        if (warmed_variants_.size() >= kMaxWarmedVariants) warmed_variants_.clear();
        warmed_variants_.insert(variant);
        ++frame->warmup_runs;
    }
    frame->timings = timer_.resolve();
    // The deep G-buffer's construction, whatever built it (Settings.deep_gbuffer): the depth_peel
    // pass's time; its parts are depth_peel.layer<i> (peeling) or deep_gbuffer.<part> (lists).
    frame->timings["deep_gbuffer"] = frame->timings["depth_peel"];
    frame->layer_samples = depth_peel_.layer_samples();
    for (const RenderPass* p : chain) p->report(s, frame->stats);
    frame->stats["passes_run"] = double(chain.size());
    // The layers that hold a surface somewhere (the samples each peel wrote, counted by the GPU):
    // peeling stops drawing after the first empty one (depth_peel.cpp).
    int layers_used = 0;
    while (layers_used < int(frame->layer_samples.size()) && frame->layer_samples[size_t(layers_used)] > 0) ++layers_used;
    frame->stats["layers_used"] = double(layers_used);
    double total = 0.0;
    for (const auto& name : frame->passes) total += frame->timings[name];
    frame->timings["total"] = total;
    frame->settings = s;
    frame->camera = camera;
    frame->uniforms = u;
    frame->ssr = su;
    frame->scene_id = scene.id();
    frame->scene_revision = scene.revision();
    frame->shadow_light = shadow.enabled ? shadow.light : -1;
    frame->serial = serial;
    for (const auto& d : scratch) scratch_owner_[d.name] = serial;
    frame->wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start).count();
    // The frame becomes its sequence's history only now, after every run of the chain: the
    // untimed first-use run and the timed run read the same history and write the same result.
    if (sequence) {
        sequence->previous = resources;
        sequence->previous_uniforms = u;
        sequence->previous_unjittered_proj = unjittered_proj;
        sequence->previous_settings = s;
        sequence->scene_id = scene.id();
        sequence->scene_revision = scene.revision();
        ++sequence->frames;
    }
    recycle();
    return frame;
}

bool Renderer::is_scratch(const std::string& name) {
    // Read by later passes of the same frame only. Python may still read them right after the
    // render (tests look at the pyramid), and the reference pass re-renders the shadow map.
    return name == "shadow_map" || name == "hiz" || name == "hiz_trace";
}

const Texture* Renderer::scratch_of(const std::string& name, uint64_t serial) const {
    auto it = scratch_owner_.find(name);
    if (it == scratch_owner_.end() || it->second != serial || !scratch_.owns(name)) return nullptr;
    return &scratch_.get(name);
}

std::vector<std::string> Renderer::scratch_names_of(uint64_t serial) const {
    std::vector<std::string> names;
    for (const auto& [name, owner] : scratch_owner_)
        if (owner == serial && scratch_.owns(name)) names.push_back(name);
    return names;
}

void Renderer::recycle(bool force) {
    CurrentContext current(*ctx_);
    size_t idle = 0;
    pool_.erase(std::remove_if(pool_.begin(), pool_.end(),
                               [&](const auto& r) {
                                   if (r.use_count() != 1 || ++idle <= kPoolSize) return false;
                                   freed_since_trim_ += r->bytes();
                                   return true;
                               }),
                pool_.end());
#if defined(__GLIBC__)
    if (freed_since_trim_ >= kTrimBytes || (force && freed_since_trim_ > 0)) {
        malloc_trim(0);
        freed_since_trim_ = 0;
    }
#endif
}

size_t Renderer::gpu_bytes() const {
    size_t total = scratch_.bytes();
    for (const auto& r : pool_) total += r->bytes();
    return total;
}

void Renderer::check_errors() {
    CurrentContext current(*ctx_);
    check_gl(*ctx_, "(between calls)");
}

std::map<std::string, double> Renderer::reference(const Scene& scene, Frame& frame, bool per_ray, int rays,
                                                  uint32_t seed, Sampling sampling, bool viewer_is_ray,
                                                  bool traced_shadows, const std::string& tracer,
                                                  std::function<bool(int, int)> progress) {
    if (tracer != "auto" && tracer != "embree" && tracer != "glsl" && tracer != "cpu")
        throw std::invalid_argument("reference: tracer must be 'auto', 'cpu', 'embree' or 'glsl', got '" + tracer + "'");
    if (tracer == "cpu" && per_ray)
        throw std::invalid_argument("reference: tracer 'cpu' traces the converged reference only, not the per-ray one");
    if (tracer == "cpu" && frame.shadow_light >= 0 && !traced_shadows)
        throw std::invalid_argument("reference: tracer 'cpu' traces its shadows (shadows='traced'); "
                                    "the shadow map's filtering is the GLSL tracer's only");
    if (frame.scene_id != scene.id() || frame.scene_revision != scene.revision())
        throw std::invalid_argument("reference: this is not the scene the frame was rendered from (or it changed since)");
    if (per_ray && !frame.has("rays.direction"))
        throw std::invalid_argument("reference: a per-ray reference needs a frame that traced rays");
    if (!per_ray && (rays < 1 || rays > 65536)) throw std::invalid_argument("reference: rays must be in [1, 65536]");
    CurrentContext current(*ctx_);
    check_gl(*ctx_, "reference (an earlier call left a GL error)");
    GpuScene& gs = const_cast<GpuScene&>(gpu_scene(scene));
    const RenderSettings& s = frame.settings;

    frame_ubo_.upload(&frame.uniforms, sizeof(FrameUniforms));
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameUniformsBinding, frame_ubo_.id());
    upload_lights(scene, frame.uniforms.view, frame.shadow_light);
    SsrUniforms su = frame.ssr;
    if (!per_ray) {  // the converged reference draws its own rays and traces every reflective pixel
        su.sampling = int(sampling);
        su.rays_per_pixel = rays;
        su.roughness_cutoff = 1.0f;
        su.seed = seed;
        su.hammersley = 1;
        su.noise = int(Noise::Pcg);
    }
    if (!ssr_ubo_) ssr_ubo_ = Buffer::create(sizeof(SsrUniforms));
    ssr_ubo_.upload(&su, sizeof(su));
    glBindBufferBase(GL_UNIFORM_BUFFER, kSsrSettingsBinding, ssr_ubo_.id());
    if (gs.environment_map()) glBindTextureUnit(15, gs.environment_map());
    bind_specular_albedo();

    const bool shadows = frame.shadow_light >= 0;
    if (shadows && !traced_shadows && !scratch_of("shadow_map", frame.serial)) {
        // The shared shadow map holds a later frame's (or none): render this frame's again. The
        // scene is the frame's own (same revision, checked above) and the fit depends only on
        // the scene and the settings, so the map is the one the frame was lit with.
        const ShadowSetup setup = ShadowMapPass::fit(scene, gs.bounds(), s);
        scratch_.add(shadow_map_.outputs(s));
        shadow_map_.set_setup(setup);
        const DepthConvention dc{s.depth_mode};
        Defines d;
        dc.add_defines(d);
        FrameContext sfc{*ctx_, *shaders_, timer_, s, scene, gs, frame.camera, dc, frame.uniforms, scratch_, d};
        sfc.clear_by_compute = clear_by_compute();
        shadow_map_.execute(sfc);
        check_gl(*ctx_, "shadow_map (again, for the reference)");
        scratch_owner_["shadow_map"] = frame.serial;
    }
    frame.resources().attach_scratch(&scratch_);
    struct Detach {
        FrameResources& r;
        ~Detach() { r.attach_scratch(nullptr); }
    } detach{frame.resources()};
    ReferencePass pass(per_ray, shadows, traced_shadows, rays, viewer_is_ray);
    // "auto" is the GLSL traversal on every device for now: on llvmpipe the wavefront's replayed
    // GLSL (the pixel's set-up and the hit's shading run again in every phase,
    // docs/reference_tracers.md) costs about what Embree saves over the GLSL traversal (measured
    // within the shared machine's noise of it at 160x90, 64 rays); on a GPU the traversal is
    // faster than a round trip through the CPU.
    const bool embree = !per_ray && tracer == "embree";
    // "auto" on the CPU device: Embree and the C++ port of the shading (passes/reference_cpu.h),
    // measured faster than both GLSL paths there (docs/reference_tracers.md); on a GPU the GLSL.
    const bool cpu = !per_ray && (tracer == "cpu" || (tracer == "auto" && ctx_->info().chosen == "cpu" &&
                                                      (!shadows || traced_shadows)));
    pass.set_progress(std::move(progress));
    CompositePass composite(true, "reference.reflection", "reference.color", "reference.direct");
    std::vector<RenderPass*> chain = {&pass};
    if (!per_ray) chain.push_back(&composite);
    for (RenderPass* p : chain) frame.resources().add(p->outputs(s));
    DepthConvention depth{s.depth_mode};
    Defines defines;
    depth.add_defines(defines);
    defines["ENVIRONMENT_MAP"] = gs.environment_map() ? "1" : "0";
    // The scene's environment type compiled into every pass (lib/environment.glsl):
    // llvmpipe runs both sides of a branch, so a run-time choice paid for every kind.
    defines["ENVIRONMENT_TYPE"] = std::to_string(int(scene.environment.type));
    defines["FETCH_BY_IMAGE"] = fetch_by_image_ ? "1" : "0";
    add_light_count(defines, scene);
    FrameContext fc{*ctx_, *shaders_, timer_, s, scene, gs, frame.camera, depth, frame.uniforms, frame.resources(),
                    defines};
    fc.clear_by_compute = clear_by_compute();
    gs.bind_geometry();
    gs.bind_ray_tracing(scene);
    if (embree) pass.set_tracer(&gs.embree_tracer());
    if (cpu) pass.set_cpu_tracer(&gs.embree_tracer(), int(scene.environment.type), gs.environment_map());
    // Compile before timing (timings never include compilation).
    pass.program(fc);
    if (!per_ray) shaders_->program({"passes/composite.comp"}, composite.program_defines(fc));
    check_gl(*ctx_, "reference set-up");
    timer_.begin_frame();
    for (RenderPass* p : chain) {
        for (const auto& in : p->inputs())
            if (!frame.resources().has(in))
                throw GLError("pass " + p->name() + " reads '" + in + "', which the frame lacks");
        {
            GpuScope t(timer_, p->name());
            p->execute(fc);
        }
        check_gl(*ctx_, p->name().c_str());
        if (!pass.completed()) {
            timer_.resolve();
            throw std::runtime_error("reference: stopped before its last ray; its textures are incomplete");
        }
    }
    std::map<std::string, double> times = timer_.resolve();
    for (const auto& [name, value] : pass.stage_ms()) times[name] = value;
    return times;
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
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, out.id());
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
        const GLuint prog = shaders_->program({"tools/microbench.comp"}, {{define, "1"}});
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "u_iterations"), its);
        glUniform1i(glGetUniformLocation(prog, "u_layers"), layers);
    };
    glBindTextureUnit(0, source.id());
    glBindTextureUnit(1, chain.id());
    glBindTextureUnit(2, wide.id());
    use("init", wide.layers(), kSourceLayers);
    glBindImageTexture(0, source.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    glBindImageTexture(1, chain.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
    glBindImageTexture(2, wide.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute(groups_x, groups_y, 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    use(kernel, iterations, kernel == "store" ? iterations : kSourceLayers);
    if (kernel == "store")
        glBindImageTexture(0, store.id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    else
        glBindImageTexture(0, sink.id(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    if (kernel == "dependent_image") glBindImageTexture(1, chain.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RG32F);
    if (kernel == "copy_image") glBindImageTexture(1, source.id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA16F);
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

unsigned Renderer::compile(const std::vector<std::string>& stages, const Defines& defines) {
    CurrentContext current(*ctx_);
    const unsigned prog = shaders_->program(stages, defines);
    check_gl(*ctx_, "shader compile");
    return prog;
}

void Renderer::set_readback_path(const std::string& path) {
    if (path != "auto" && path != "download" && path != "staged")
        throw std::invalid_argument("Renderer.readback_path must be 'auto', 'download' or 'staged', got '" + path + "'");
    readback_path_ = path;
}

void Renderer::set_clear_path(const std::string& path) {
    if (path != "auto" && path != "gl" && path != "compute")
        throw std::invalid_argument("Renderer.clear_path must be 'auto', 'gl' or 'compute', got '" + path + "'");
    clear_path_ = path;
}

bool Renderer::clear_by_compute() const {
    if (clear_path_ == "auto") return ctx_->info().chosen != "cpu";
    return clear_path_ == "compute";
}

bool Renderer::readback_staged() const {
    if (readback_path_ == "auto") return ctx_->info().chosen != "cpu";
    return readback_path_ == "staged";
}

namespace {
// memcpy in up to 8 threads of at least 4 MiB each: one core's copy of a 1920x1080 RGBA32F
// image (33 MB) takes several ms, longer than the transfer.
void parallel_copy(float* dst, const char* src, size_t bytes) {
    const size_t chunk_min = size_t(4) << 20;
    const size_t threads = std::min<size_t>({8, std::max(1u, std::thread::hardware_concurrency()),
                                             std::max<size_t>(1, bytes / chunk_min)});
    char* out = reinterpret_cast<char*>(dst);
    if (threads <= 1) {
        std::memcpy(out, src, bytes);
        return;
    }
    const size_t chunk = (bytes / threads + 63) & ~size_t(63);
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) {
        const size_t begin = std::min(bytes, t * chunk), end = std::min(bytes, (t + 1) * chunk);
        if (begin < end) pool.emplace_back([=] { std::memcpy(out + begin, src + begin, end - begin); });
    }
    std::memcpy(out, src, std::min(bytes, chunk));
    for (auto& th : pool) th.join();
}
}  // namespace

Readback Renderer::read_texture(const Texture& tex, int level) {
    CurrentContext current(*ctx_);
    if (level < 0 || level >= tex.levels())
        throw std::invalid_argument("mip level " + std::to_string(level) + " out of range (texture has " +
                                    std::to_string(tex.levels()) + ")");
    Readback out;
    out.width = std::max(tex.width() >> level, 1);
    out.height = std::max(tex.height() >> level, 1);
    out.layers = tex.target() == GL_TEXTURE_2D_ARRAY ? tex.layers() : 1;
    const size_t bytes = size_t(out.width) * size_t(out.height) * size_t(out.layers) * 4 * sizeof(float);
    const GLenum f = tex.format();
    const size_t row = size_t(out.width) * 4;  // floats
    const size_t layer_floats = row * size_t(out.height);
    const bool float_format =
        f == GL_RGBA32F || f == GL_RGBA16F || f == GL_RG32F || f == GL_RG16F || f == GL_R32F || f == GL_R16F;
    if (!readback_staged() && float_format && layer_floats * sizeof(float) <= size_t(std::numeric_limits<GLsizei>::max())) {
        // Float formats, whose GL_RGBA/GL_FLOAT download is exactly what a texelFetch returns
        // (halves widen exactly; absent channels read 0, 0, 1): downloaded as stored, a layer
        // at a time (GL sizes are 32-bit), no copy pass (on llvmpipe the copy pass
        // was most of a readback). Rows come top first from the driver where it has
        // GL_MESA_pack_invert (llvmpipe: the colour's readback 0.54-0.55x at 1920x1080, 0.7-0.8x
        // at 640x360, benchmarks/readback.py), else they are swapped on the CPU. Normalised, sRGB
        // and depth formats are decoded by readback.comp's fetch.
        out.data.resize(layer_floats * size_t(out.layers));
        // Shader image stores reach glGetTextureSubImage only after this barrier (GL 4.5, 7.13.2).
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        // Where the driver has GL_MESA_pack_invert (Mesa), it writes the rows top first itself.
        if (pack_invert_) glPixelStorei(GL_PACK_INVERT_MESA, GL_TRUE);
        // RGBA16F: downloaded as halves and widened on the CPU where it has F16C.
        const bool halves = f == GL_RGBA16F && cpu_has_f16c();
        std::vector<uint16_t, UninitialisedAllocator<uint16_t>> half_layer(halves ? layer_floats : 0);
        for (int l = 0; l < out.layers; ++l) {
            float* layer = out.data.data() + size_t(l) * layer_floats;
            if (halves) {
                glGetTextureSubImage(tex.id(), level, 0, 0, l, out.width, out.height, 1, GL_RGBA, GL_HALF_FLOAT,
                                     GLsizei(layer_floats * sizeof(uint16_t)), half_layer.data());
                widen_halves_f16c(half_layer.data(), layer, layer_floats);
            } else {
                glGetTextureSubImage(tex.id(), level, 0, 0, l, out.width, out.height, 1, GL_RGBA, GL_FLOAT,
                                     GLsizei(layer_floats * sizeof(float)), layer);
            }
            if (pack_invert_) continue;
            for (int y = 0; y < out.height / 2; ++y)
                std::swap_ranges(layer + size_t(y) * row, layer + size_t(y + 1) * row,
                                 layer + size_t(out.height - 1 - y) * row);
        }
        if (pack_invert_) glPixelStorei(GL_PACK_INVERT_MESA, GL_FALSE);
        check_gl(*ctx_, "readback");
        ++readbacks_;
        readback_bytes_ += bytes;
        return out;
    }
    if (readback_ssbo_.size() < bytes) readback_ssbo_ = Buffer::create(bytes);
    const bool staged = readback_staged();
    Defines d;
    d["READ_ARRAY"] = tex.target() == GL_TEXTURE_2D_ARRAY ? "1" : "0";
    const GLuint prog = shaders_->program({"passes/readback.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_level"), level);
    glUniform2i(glGetUniformLocation(prog, "u_size"), out.width, out.height);
    glBindTextureUnit(0, tex.id());
    glBindSampler(0, readback_sampler_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, readback_ssbo_.id());
    glDispatchCompute(GLuint((out.width + 7) / 8), GLuint((out.height + 7) / 8), GLuint(out.layers));
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindSampler(0, 0);
    out.data.resize(bytes / sizeof(float));
    if (staged) {
        // A GPU's glGetBufferSubData goes through the driver's own staging copy into pageable
        // memory; here the copy engine writes into pinned client memory and the CPU copies
        // from it in parallel, once the fence has passed.
        if (readback_staging_.size() < bytes) {
            readback_staging_.reset();
            readback_staging_ = Buffer::create_readable(bytes);
        }
        glCopyNamedBufferSubData(readback_ssbo_.id(), readback_staging_.id(), 0, 0, GLsizeiptr(bytes));
        glMemoryBarrier(GL_CLIENT_MAPPED_BUFFER_BARRIER_BIT);
        GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        GLenum waited = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000ull);
        while (waited == GL_TIMEOUT_EXPIRED) waited = glClientWaitSync(fence, 0, 1000000000ull);
        glDeleteSync(fence);
        if (waited == GL_WAIT_FAILED) throw GLError("readback: waiting for the GPU failed");
        parallel_copy(out.data.data(), static_cast<const char*>(readback_staging_.mapped()), bytes);
    } else {
        glGetNamedBufferSubData(readback_ssbo_.id(), 0, GLsizeiptr(bytes), out.data.data());
    }
    check_gl(*ctx_, "readback");
    ++readbacks_;
    readback_bytes_ += bytes;
    return out;
}

// ------------------------------------------------------------------------------------------

Frame::Frame(std::shared_ptr<EglContext> ctx, std::weak_ptr<Renderer> renderer, std::shared_ptr<FrameResources> res)
    : ctx_(std::move(ctx)), renderer_(std::move(renderer)), resources_(std::move(res)) {}

Frame::~Frame() {
    // The textures may be freed now (when the renderer is gone): in their own context.
    try {
        CurrentContext current(*ctx_);
        resources_.reset();
        if (auto r = renderer_.lock()) r->recycle();
    } catch (...) {
    }
}

void Frame::release() {
    if (!resources_) return;
    CurrentContext current(*ctx_);
    resources_.reset();
    if (auto r = renderer_.lock()) r->recycle(true);
}

FrameResources& Frame::resources() {
    if (!resources_) throw std::invalid_argument("this frame was released (Frame.release()); its textures are gone");
    return *resources_;
}

bool Frame::has(const std::string& name) const {
    if (!resources_) return false;
    if (resources_->owns(name)) return true;
    auto r = renderer_.lock();
    return r && r->scratch_of(name, serial) != nullptr;
}

Readback Frame::read(const std::string& name, int level) {
    if (!resources_)
        throw std::invalid_argument("cannot read '" + name + "': this frame was released (Frame.release()); read "
                                    "what you need before releasing it");
    auto r = renderer_.lock();
    if (!r) throw GLError("the Renderer that made this frame has been closed; read what you need before closing it");
    if (resources_->owns(name)) return r->read_texture(resources_->get(name), level);
    if (const Texture* t = r->scratch_of(name, serial)) return r->read_texture(*t, level);
    if (Renderer::is_scratch(name))
        throw std::invalid_argument("'" + name + "' is per-renderer scratch shared by all frames, and a later render "
                                    "has overwritten it (or this frame did not make one): read it right after "
                                    "rendering the frame");
    std::string known;
    for (const auto& n : texture_names()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("frame has no texture '" + name + "' (it has: " + known + ")");
}

std::vector<std::string> Frame::texture_names() const {
    std::vector<std::string> names;
    if (!resources_) return names;
    for (const auto& d : resources_->descs()) names.push_back(d.name);
    if (auto r = renderer_.lock())
        for (const auto& n : r->scratch_names_of(serial)) names.push_back(n);
    return names;
}

}  // namespace ssr
