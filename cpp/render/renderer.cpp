// The renderer's set-up, its scenes, the chain built from the pass registry, the frame's lights
// and jitter. The render loop is render_loop.cpp, resource planning resource_plan.cpp, read-back
// readback.cpp, the device tools device_tools.cpp, the user passes' registry user_pass_registry.cpp.
#include "render/renderer.h"
#include "render/auto_choice.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>

#include "core/errors.h"
#include "passes/compute.h"

namespace ssr {

namespace {
constexpr size_t kSceneCacheSize = 8;
}  // namespace


// The defines every pass of a frame of `scene` compiles with.
Defines Renderer::common_defines(const Scene& scene, const GpuScene& gs, const DepthConvention& depth) const {
    Defines defines;
    depth.add_defines(defines);
    defines["ENVIRONMENT_MAP"] = gs.environment_map() ? "1" : "0";
    // The scene's environment type compiled into every pass (lib/environment.glsl):
    // llvmpipe runs both sides of a branch, so a run-time choice paid for every kind.
    defines["ENVIRONMENT_TYPE"] = std::to_string(int(scene.environment.type));
    defines["FETCH_BY_IMAGE"] = fetch_by_image_ ? "1" : "0";
    // The units bound for the whole frame, by name (TEXTURE_ENVIRONMENT_MAP, ...; passes/compute.h).
    for (const auto& u : frame_texture_units()) defines[NamedUnits::define("TEXTURE_", u.first)] = std::to_string(u.second);
    // The scene's light count compiled into every pass (up to 8; lib/lights.glsl), whose
    // shading then reads every light once before any control flow: llvmpipe loads a storage-buffer
    // value inside a loop one lane and one component at a time. Beyond 8 the loop reads the buffer.
    if (scene.lights.size() <= 8) defines["LIGHT_COUNT"] = std::to_string(scene.lights.size());
    return defines;
}

std::shared_ptr<Renderer> Renderer::create(const std::string& device, const std::string& shader_dir,
                                           const std::string& input_fetch) {
    check_choice("Renderer.input_fetch", input_fetch, kInputFetches);  // before a context is made
    return std::shared_ptr<Renderer>(new Renderer(device, shader_dir, input_fetch));
}

Renderer::Renderer(const std::string& device, const std::string& shader_dir, const std::string& input_fetch)
    : ctx_(std::make_shared<EglContext>(parse_device_kind(device), parse_device_index(device))),
      shaders_(std::make_unique<ShaderLibrary>(shader_dir)),
      owned_passes_(make_registered_passes()) {
    for (const auto& p : owned_passes_) {
        passes_.push_back(p.get());
        if (p->name() == "shadow_map") shadow_map_ = dynamic_cast<ShadowMapPass*>(p.get());
    }
    if (!shadow_map_) throw std::logic_error("no registered pass 'shadow_map' (passes/shadow_map.cpp)");
    // The registry in the order of the union of every technique's declarations: the order a user
    // pass's stage and reads are checked against when it registers.
    {
        FrameFacts every;
        every.reflections = every.shadows = every.emission_texture = every.specular_texture = true;
        every.shadow_maps = every.shadow_cubes = 1;
        const std::vector<RenderSettings> variants = placement_variants();
        const std::vector<RenderPass*> all = passes_;
        passes_ = order_chain(all, [&](size_t i) {
            PassDeclaration u;
            auto add = [](std::vector<std::string>& to, const std::vector<std::string>& from) {
                for (const auto& x : from)
                    if (std::find(to.begin(), to.end(), x) == to.end()) to.push_back(x);
            };
            for (const RenderSettings& v : variants) {
                if (!all[i]->runs(v, every)) continue;
                const PassDeclaration d = declaration(*all[i], v, every);
                add(u.reads, d.reads), add(u.writes, d.writes), add(u.rewrites, d.rewrites);
                add(u.buffer_reads, d.buffer_reads), add(u.buffer_writes, d.buffer_writes);
            }
            return u;
        }, false, true);
    }
    // The reflection settings' block, declared once in settings_fields.def (lib/ssr_settings.glsl).
    shaders_->add_generated(kSsrSettingsGlslName, ssr_settings_glsl());
    // The records shared with the host, declared once in gpu_structs.def (lib/frame_uniforms.glsl,
    // lib/lights.glsl, lib/scene_data.glsl).
    for (const GpuStructGlsl& g : gpu_struct_glsl()) shaders_->add_generated(g.file, g.text);
    // Every interface block's binding point, declared once in buffer_bindings.def: its defines
    // ahead of every program, and the table each linked program is checked against.
    {
        std::map<std::string, ShaderLibrary::BlockBinding> table;
        for (const BufferBinding& b : buffer_bindings()) table[b.block] = {b.storage, b.binding, b.define};
        shaders_->set_block_bindings(buffer_bindings_glsl(), std::move(table));
    }
    CurrentContext current(*ctx_);
    frame_ubo_ = Buffer::create(sizeof(FrameUniforms));
    glCreateSamplers(1, &readback_sampler_);
    glSamplerParameteri(readback_sampler_, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glSamplerParameteri(readback_sampler_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glSamplerParameteri(readback_sampler_, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_texture_size_);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_array_layers_);
    glGetIntegerv(GL_MAX_CUBE_MAP_TEXTURE_SIZE, &max_cube_size_);
    GLint extensions = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &extensions);
    for (GLint i = 0; i < extensions; ++i) {
        const char* name = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)));
        if (name && std::strcmp(name, "GL_MESA_pack_invert") == 0) pack_invert_ = true;
    }
    // On the CPU device the passes read float textures by imageLoad ('auto': render/auto_choice.h),
    // where the device offers the image units: a pass binds up to kImageUnitsPerPass images, outputs
    // and inputs together.
    GLint compute_images = 0, image_units = 0;
    glGetIntegerv(GL_MAX_COMPUTE_IMAGE_UNIFORMS, &compute_images);
    glGetIntegerv(GL_MAX_IMAGE_UNITS, &image_units);
    const bool images_enough = std::min(compute_images, image_units) >= kImageUnitsPerPass;
    if (input_fetch == "imageLoad" && !images_enough)
        throw std::invalid_argument("Renderer.input_fetch 'imageLoad' needs " + std::to_string(kImageUnitsPerPass) +
                                    " image units in a compute shader; this device offers " +
                                    std::to_string(std::min(compute_images, image_units)));
    fetch_by_image_ = input_fetch == "imageLoad" ||
                      (input_fetch == "auto" && auto_fetch_by_image(ctx_->info().chosen == "cpu", images_enough));
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
    previous_models_.reset();
    readback_ssbo_.reset();
    readback_staging_.reset();
    specular_albedo_.reset();
    timer_.reset();
    shaders_->release();
    for (auto& p : owned_passes_) p->release();
    for (auto& u : user_passes_) u->release();
}

const GpuScene& Renderer::gpu_scene(const Scene& scene) {
    for (auto it = scenes_.begin(); it != scenes_.end(); ++it) {
        if (it->id == scene.id()) {
            if (it->gpu->revision() != scene.revision()) {
                // Moved objects, edited materials, lights: their entries only. New geometry,
                // images or objects: a new copy.
                const bool updated = it->gpu->update(scene);
                if (updated) {
                    ++scene_updates_;
                } else {
                    it->gpu.reset();  // its GL objects go before the new copy's are made
                    it->gpu = std::make_unique<GpuScene>(scene, &scene_work_);
                    ++scene_uploads_;
                }
            }
            scenes_.splice(scenes_.begin(), scenes_, it);
            return *scenes_.front().gpu;
        }
    }
    scenes_.push_front(CachedScene{scene.id(), std::make_unique<GpuScene>(scene, &scene_work_)});
    ++scene_uploads_;
    if (scenes_.size() > kSceneCacheSize) scenes_.pop_back();
    return *scenes_.front().gpu;
}

// The frame as a chain of passes. Passes a frame does not need are left out: no shadow map
// without a shadow caster, no tracing without a reflective surface or with method "off",
// no Hi-Z pyramid for the linear tracer (unless the cone needs it), no pre-convolution or
// pre-integrated visibility for stochastic glossy reflections.
std::vector<RenderPass*> Renderer::build_chain(const RenderSettings& s, const FrameFacts& facts) const {
    const std::vector<UserPass*> chosen = check_user_settings(s);
    std::vector<RenderPass*> chain = ordered_chain(passes_, chosen, s, facts);
    // Placed user passes, in Settings.user_passes order, each where its resources are.
    for (UserPass* u : chosen)
        if (u->placed()) place_user_pass(chain, *u, s, facts);
    return chain;
}

std::vector<RenderPass*> Renderer::ordered_chain(const std::vector<RenderPass*>& passes,
                                                 const std::vector<UserPass*>& chosen, const RenderSettings& s,
                                                 const FrameFacts& facts) {
    std::vector<RenderPass*> running;
    for (RenderPass* p : passes) {
        if (!p->runs(s, facts)) continue;
        // A chosen user pass of this pass's stage takes its place.
        auto user = std::find_if(chosen.begin(), chosen.end(), [&](const UserPass* u) {
            return !u->placed() && !p->stage().empty() && u->stage() == p->stage();
        });
        running.push_back(user != chosen.end() ? *user : p);
    }
    std::vector<RenderPass*> chain =
        order_chain(running, [&](size_t i) { return declaration(*running[i], s, facts); }, reverse_chain_ties());
    // A user pass whose stage follows a pass's (a filter of the reflection after the resolve) runs
    // right after it: it rewrites what that pass wrote, before anyone reads it.
    for (UserPass* u : chosen) {
        if (u->placed()) continue;
        const auto at = std::find_if(chain.begin(), chain.end(), [&](const RenderPass* p) {
            return !p->stage().empty() && UserPass::after_stage(u->stage()) == p->stage();
        });
        if (at != chain.end()) chain.insert(at + 1, u);
    }
    return chain;
}


FrameFacts Renderer::facts(const Scene& scene, const GpuScene& gs, const RenderSettings& s) const {
    return frame_facts(scene, gs.bounds(), gs.has_reflective_surfaces(), gs.has_emissive_texture(),
                       gs.has_specular_texture(), s, fetch_by_image_);
}

// What makes two frames share their first-use costs: the passes, their textures' formats and
// sizes, and the common shader defines (render() adds the scene: its buffers' first use).
std::string Renderer::variant_key(const std::vector<RenderPass*>& chain, const std::vector<ResourceDesc>& descs,
                                  const Defines& defines) {
    std::string key;
    for (RenderPass* p : chain) key += p->name() + ";";
    for (const auto& d : descs)
        key += d.name + ":" + std::to_string(d.format) + "," + std::to_string(d.width) + "x" + std::to_string(d.height) +
               "x" + std::to_string(d.layers) + (d.cube ? "c" : "") + "/" + std::to_string(d.levels) + ";";
    for (const auto& [k, v] : defines) key += k + "=" + v + ";";
    return key;
}

void Renderer::upload_lights(const Scene& scene, const glm::mat4& view, const ShadowSetup& shadow) {
    std::vector<GpuLight> lights;
    const glm::mat4 inv_view = glm::inverse(view);
    const glm::mat4 to_unit = glm::translate(glm::mat4(1.0f), glm::vec3(0.5f)) * glm::scale(glm::mat4(1.0f), glm::vec3(0.5f));
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& l = scene.lights[i];
        const ShadowCaster* caster = shadow.caster_of(int(i));
        GpuLight g{};
        g.position_type = glm::vec4(glm::vec3(view * glm::vec4(l.position, 1.0f)),
                                    l.type == Light::Type::Directional ? 0.0f : (l.type == Light::Type::Spot ? 2.0f : 1.0f));
        g.direction_shadow = glm::vec4(glm::mat3(view) * glm::normalize(l.direction), caster ? 1.0f : 0.0f);
        // Its shadow map (lib/shadow_map.glsl): a layer's texture-space matrix, or a cube's
        // lookup frame (world axes about the light) and depth range.
        g.shadow = glm::vec4(-1.0f, -1.0f, 0.0f, 0.0f);
        g.view_to_shadow = glm::mat4(1.0f);
        if (caster && caster->cube) {
            g.shadow = glm::vec4(-1.0f, float(caster->slot), caster->near_plane, caster->far_plane);
            g.view_to_shadow = glm::translate(glm::mat4(1.0f), -caster->position) * inv_view;
        } else if (caster) {
            g.shadow = glm::vec4(float(caster->slot), -1.0f, caster->texel_world_size, 0.0f);
            g.view_to_shadow = to_unit * caster->light_view_proj * inv_view;
        }
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

// Without the GL context and without uploading the scene: the chain is a function of the
// settings, the scene's facts and the device's input fetch.
std::vector<Renderer::ChainEntry> Renderer::chain(const Scene& scene, const RenderSettings& s) const {
    s.validate();
    const FrameFacts f = scene_facts(scene, s, fetch_by_image_);
    return describe_chain(build_chain(s, f), s, f);
}

std::vector<Renderer::ChainEntry> Renderer::builtin_chain(const Scene& scene, const RenderSettings& s,
                                                          bool fetch_by_image) {
    s.validate();
    if (!s.user.passes.empty())
        throw std::invalid_argument("Settings.user_passes: a chain listed without a renderer has the built-in "
                                    "passes only (Renderer.chain lists the user passes registered on it)");
    // One instance of each registered pass, made once: runs(), inputs() and outputs() read no state.
    static const std::vector<std::unique_ptr<RenderPass>> owned = make_registered_passes();
    std::vector<RenderPass*> passes;
    for (const auto& p : owned) passes.push_back(p.get());
    const FrameFacts f = scene_facts(scene, s, fetch_by_image);
    return describe_chain(ordered_chain(passes, {}, s, f), s, f);
}

std::vector<Renderer::ChainEntry> Renderer::describe_chain(const std::vector<RenderPass*>& chain,
                                                           const RenderSettings& s, const FrameFacts& f) {
    std::vector<ChainEntry> out;
    for (RenderPass* p : chain) {
        ChainEntry e{p->name(), p->inputs(s, f), {}, p->history_inputs(s), {}, p->buffer_inputs(s, f),
                     p->buffer_outputs(s, f)};
        for (const auto& d : p->outputs(s, f)) {
            e.outputs.push_back(d.name);
            e.formats.push_back(format_name(d.format));
            std::string channels;
            for (const auto& c : d.channels)
                channels += (channels.empty() ? "" : ", ") + c.view + "." + c.name + " (" +
                            std::string("rgba").substr(size_t(c.first), size_t(c.count)) + ")";
            e.channels.push_back(channels);
            if (d.lifetime == Lifetime::Scratch) e.scratch.push_back(d.name);
        }
        // A rewritten texture is read and written.
        for (const auto& r : p->rewrites(s, f)) e.inputs.push_back(r), e.outputs.push_back(r);
        out.push_back(std::move(e));
    }
    return out;
}

void Renderer::check_errors() {
    CurrentContext current(*ctx_);
    check_gl(*ctx_, "(between calls)");
}

unsigned Renderer::compile(const std::vector<std::string>& stages, const Defines& defines) {
    CurrentContext current(*ctx_);
    const unsigned prog = shaders_->program(stages, defines);
    check_gl(*ctx_, "shader compile");
    return prog;
}

BlockLayout Renderer::block_layout(unsigned program, const std::string& block) {
    CurrentContext current(*ctx_);
    BlockLayout layout = ssr::block_layout(program, block);
    check_gl(*ctx_, "block layout query");
    return layout;
}

}  // namespace ssr
