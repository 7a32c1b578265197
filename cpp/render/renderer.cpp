// The renderer's set-up, its scenes, the chain built from the pass registry, the frame's lights
// and jitter. The render loop is render_loop.cpp, resource planning resource_plan.cpp, read-back
// readback.cpp, the device tools device_tools.cpp.
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

std::vector<UserPass*> Renderer::check_user_settings(const RenderSettings& s) const {
    std::vector<UserPass*> chosen;
    auto find = [&](const std::string& name) -> UserPass* {
        for (const auto& u : user_passes_)
            if (u->name() == name) return u.get();
        return nullptr;
    };
    auto registered = [&] {
        std::string names;
        for (const auto& u : user_passes_) names += (names.empty() ? "" : ", ") + u->name();
        return names.empty() ? std::string("none: Renderer.register_pass adds one") : names;
    };
    for (const auto& name : s.user.passes) {
        UserPass* u = find(name);
        if (!u)
            throw std::invalid_argument("Settings.user_passes names '" + name +
                                        "', which is not registered on this renderer (registered: " + registered() + ")");
        for (const UserPass* c : chosen)
            if (c->stage() == u->stage() && !u->placed())
                throw std::invalid_argument("Settings.user_passes: '" + c->name() + "' and '" + name +
                                            "' both fill the stage '" + u->stage() + "'");
        if (u->stage() == "trace") {
            if (s.method != TraceMethod::Linear && s.method != TraceMethod::Hiz)
                throw std::invalid_argument("Settings.user_passes: the trace pass '" + name +
                                            "' takes the place of the screen-space trace; Settings.method must be "
                                            "'linear' or 'hiz' (it chooses the passes around it: 'hiz' builds the "
                                            "Hi-Z pyramid)");
            if (s.variance_rays)
                throw std::invalid_argument("Settings.user_passes: the trace pass '" + name +
                                            "' does not serve Settings.variance_rays (its second trace is built in)");
        }
        chosen.push_back(u);
    }
    for (const auto& [key, value] : s.user.params) {
        const size_t dot = key.rfind('.');
        UserPass* u = dot == std::string::npos ? nullptr : find(key.substr(0, dot));
        if (!u)
            throw std::invalid_argument("Settings.user_params['" + key + "']: no registered user pass '" +
                                        key.substr(0, dot == std::string::npos ? key.size() : dot) +
                                        "' (keys are '<pass>.<param>'; registered: " + registered() + ")");
        const auto& params = u->desc().params;
        if (std::none_of(params.begin(), params.end(), [&](const UserParam& p) { return p.name == key.substr(dot + 1); })) {
            std::string names;
            for (const auto& p : params) names += (names.empty() ? "" : ", ") + p.name;
            throw std::invalid_argument("Settings.user_params['" + key + "']: user pass '" + u->name() +
                                        "' has no parameter '" + key.substr(dot + 1) + "' (it has: " +
                                        (names.empty() ? "none" : names) + ")");
        }
    }
    return chosen;
}

void Renderer::register_user_pass(const UserPassDesc& d) {
    auto fail = [&](const std::string& m) { throw std::invalid_argument("user pass '" + d.name + "': " + m); };
    auto join = [](const std::vector<std::string>& v) {
        std::string out;
        for (const auto& x : v) out += (out.empty() ? "'" : ", '") + x + "'";
        return out;
    };
    if (d.name.empty()) throw std::invalid_argument("user pass: the name is empty");
    for (const RenderPass* p : passes_)
        if (p->name() == d.name) fail("a built-in pass has this name");
    for (const auto& u : user_passes_)
        if (u->name() == d.name) fail("a user pass of this name is registered on this renderer already");
    if (d.stage != "trace" && d.stage != "reflection_filter" && d.stage != "placed")
        fail("stage must be 'trace', 'reflection_filter' or 'placed', got '" + d.stage + "'");
    if (d.stage == "trace" && d.dispatch != "ray" && d.dispatch != "list")
        fail("a trace pass dispatches per ray: dispatch must be 'ray' (over classify's list with Settings.skip) "
             "or 'list' (classify's list only), got '" + d.dispatch + "'");
    if (d.stage != "trace" && d.dispatch != "pixel" && d.dispatch != "ray")
        fail("a " + d.stage + " pass dispatches per pixel: dispatch must be 'pixel' or 'ray', got '" + d.dispatch + "'");
    if (d.stage != "placed" && (!d.after.empty() || !d.before.empty()))
        fail("only a placed pass (no stage) names the pass it runs after or before; a " + d.stage +
             " pass has its stage's place");
    if (!d.after.empty() && !d.before.empty())
        fail("names both a pass to run after ('" + d.after + "') and one to run before ('" + d.before +
             "'): name one, the other follows from the chain");
    // Who writes what, in registry order: the union over settings that switch outputs on.
    std::vector<RenderSettings> variants(2);
    variants[1].specular_occlusion = SpecularOcclusion::Horizon;
    variants[1].method = TraceMethod::Hiz;
    struct Owner {
        std::string pass;
        size_t at;      // registry index of the first pass that declares it
        GLenum format;  // its format (0: a user pass's texture, declared with an image format)
        // The last pass that writes or rewrites it (classify clears what the trace and the
        // resolve then write): a reader sees it whole only after that one.
        std::string last_pass;
        size_t last_at;
    };
    std::map<std::string, Owner> owner;
    // The registry index a user pass of `stage` runs at: the place of the built-in pass of its
    // stage, or right after the pass its stage follows (UserPass::after_stage).
    auto place = [&](const std::string& stage) {
        for (size_t i = 0; i < passes_.size(); ++i) {
            const std::string& own = passes_[i]->stage();
            if (own.empty()) continue;
            if (own == stage) return i;
            if (own == UserPass::after_stage(stage)) return i + 1;
        }
        return passes_.size();
    };
    auto registry_index = [&](const std::string& name) -> long {
        for (size_t i = 0; i < passes_.size(); ++i)
            if (passes_[i]->name() == name) return long(i);
        return -1;
    };
    for (size_t i = 0; i < passes_.size(); ++i) {
        const RenderPass* p = passes_[i];
        FrameFacts every;  // the facts that switch outputs on
        every.emission_texture = true;
        every.shadows = true;
        every.shadow_maps = every.shadow_cubes = 1;
        every.specular_texture = true;
        for (const auto& s : variants)
            for (const auto& o : p->outputs(s, every)) {
                const auto [it, fresh] = owner.emplace(o.name, Owner{p->name(), i, o.format, p->name(), i});
                if (!fresh && i > it->second.last_at) it->second.last_pass = p->name(), it->second.last_at = i;
            }
    }
    for (size_t i = 0; i < passes_.size(); ++i)
        for (const auto& s : variants)
            for (const auto& x : passes_[i]->rewrites(s, FrameFacts{})) {
                auto it = owner.find(x);
                if (it != owner.end() && i > it->second.last_at)
                    it->second.last_pass = passes_[i]->name(), it->second.last_at = i;
            }
    // Earlier user passes' own textures: written at their stage's place (a placed pass's: at its
    // anchor's, or anywhere: the chain check decides).
    for (const auto& u : user_passes_) {
        const UserPassDesc& ud = u->desc();
        size_t at = place(ud.stage);
        if (ud.stage == "placed") {
            const long a = registry_index(ud.after.empty() ? ud.before : ud.after);
            at = a < 0 ? 0 : size_t(a) + (ud.after.empty() ? 0 : 1);
        }
        for (const auto& c : ud.creates) owner.emplace(c.name, Owner{u->name(), at, 0, u->name(), at});
    }
    const std::vector<std::string> allowed = UserPass::stage_writes(d.stage);
    if (d.stage == "placed") {
        // The pass it names must exist.
        const std::string& anchor = d.after.empty() ? d.before : d.after;
        const bool anchor_user = std::any_of(user_passes_.begin(), user_passes_.end(),
                                             [&](const auto& u) { return u->name() == anchor; });
        if (!anchor.empty() && registry_index(anchor) < 0 && !anchor_user) {
            std::string names;
            for (const RenderPass* p : passes_) names += (names.empty() ? "" : ", ") + p->name();
            fail("runs " + std::string(d.after.empty() ? "before" : "after") + " '" + anchor +
                 "', which is no pass (passes: " + names + ", and the user passes registered before it)");
        }
        std::vector<std::string> needs = d.reads;
        for (const auto& w : d.writes)
            if (std::find(needs.begin(), needs.end(), w) == needs.end()) needs.push_back(w);
        for (const auto& r : needs) {
            const bool rewrites = std::find(d.writes.begin(), d.writes.end(), r) != d.writes.end();
            auto it = owner.find(r);
            if (it == owner.end())
                fail(std::string(rewrites ? "rewrites" : "reads") + " '" + r + "', which no pass writes" +
                     (rewrites ? ": declare a texture of its own in creates with its format and size" : ""));
            if (rewrites && it->second.format != 0 && !UserPass::image_format(it->second.format))
                fail("rewrites '" + r + "', whose format an image store cannot write (the formats it can: rgba8, "
                     "rgba16f, rgba32f, rg16f, rg32f, r16f, r32f)");
        }
        // Named after or before a built-in pass: a place no chain could give it is refused now,
        // naming the input it would lack (the chains of the techniques' settings, every pass that
        // some scene switches on; a place some chain allows is checked again per frame).
        if (!anchor.empty() && !anchor_user) {
            const UserPass probe(d);
            FrameFacts every;
            every.reflections = every.shadows = every.emission_texture = every.specular_texture = true;
            every.shadow_maps = every.shadow_cubes = 1;
            every.fetch_by_image = fetch_by_image_;
            std::string first;
            bool possible = false;
            for (const RenderSettings& v : placement_variants()) {
                std::vector<RenderPass*> chain;
                for (RenderPass* p : passes_)
                    if (p->runs(v, every)) chain.push_back(p);
                if (std::none_of(chain.begin(), chain.end(), [&](const RenderPass* p) { return p->name() == anchor; }))
                    continue;
                size_t at = 0;
                const std::string why = placement(chain, probe, v, every, at);
                if (why.empty()) {
                    possible = true;
                    break;
                }
                if (first.empty()) first = why.substr(0, why.find(", which no pass of this frame's chain"));
            }
            if (!possible && !first.empty()) fail(first);
        }
    } else {
        const size_t at = place(d.stage);
        for (const auto& r : d.reads) {
            auto it = owner.find(r);
            if (it == owner.end()) fail("reads '" + r + "', which no pass writes");
            const bool own = std::find(allowed.begin(), allowed.end(), r) != allowed.end() &&
                             d.stage == "reflection_filter";
            if (it->second.last_at >= at && !own)
                fail("reads '" + r + "', which no pass before its stage '" + d.stage + "' writes ('" +
                     it->second.last_pass + "' writes it later)");
        }
        if (d.stage == "trace" && d.writes != allowed)
            fail("a trace pass writes exactly " + join(allowed) + " (the ray textures the resolve, the stats and "
                 "the per-ray reference read), got " + (d.writes.empty() ? std::string("none") : join(d.writes)));
        for (const auto& w : d.writes) {
            if (std::find(allowed.begin(), allowed.end(), w) != allowed.end()) continue;
            auto it = owner.find(w);
            if (it != owner.end())
                fail("writes '" + w + "', which pass '" + it->second.pass + "' owns; a " + d.stage + " pass writes " +
                     join(allowed) + " and the textures it creates (a placed pass, without a stage, may rewrite it)");
            fail("writes '" + w + "', which no pass declares: declare it in creates with its format and size");
        }
    }
    std::set<std::string> created;
    for (const auto& c : d.creates) {
        auto it = owner.find(c.name);
        if (it != owner.end()) fail("creates '" + c.name + "', which pass '" + it->second.pass + "' owns already");
        if (!created.insert(c.name).second) fail("creates '" + c.name + "' twice");
        if (!UserPass::parse_format(c.format))
            fail("creates '" + c.name + "' with format '" + c.format +
                 "' (formats: rgba8, rgba16f, rgba32f, rg16f, rg32f, r16f, r32f)");
        if (c.size != "image" && c.size != "trace" && c.size != "rays")
            fail("creates '" + c.name + "' with size '" + c.size + "' (sizes: image, trace, rays)");
    }
    for (const auto& p : d.params)
        if (p.type != "float" && p.type != "int" && p.type != "bool")
            fail("parameter '" + p.name + "' has type '" + p.type + "' (types: float, int, bool)");
    user_passes_.push_back(std::make_unique<UserPass>(d));
}

// Settings whose chains hold every built-in pass somewhere: each trace method, each glossy method, the
// temporal techniques, SVGF, the fallbacks, the variance-guided second trace, skip (classify).
std::vector<RenderSettings> Renderer::placement_variants() {
    std::vector<RenderSettings> out;
    for (TraceMethod method : {TraceMethod::Linear, TraceMethod::Hiz, TraceMethod::Bvh})
        for (Glossy glossy : {Glossy::Stochastic, Glossy::Cone, Glossy::BlurMips})
            for (int extra = 0; extra < 7; ++extra) {
                if (method == TraceMethod::Bvh && (glossy != Glossy::Stochastic || extra > 1)) continue;
                if (glossy != Glossy::Stochastic && extra >= 3) continue;
                RenderSettings s;
                s.method = method;
                s.glossy = glossy;
                if (extra == 1) s.denoise = Denoise::Svgf;
                if (extra == 2) s.skip = true, s.temporal_reflections = true, s.taa = TaaMode::Clamped;
                if (extra == 3) s.fallback = Fallback::Bvh;
                if (extra == 4) s.fallback = Fallback::Probes;
                if (extra == 5) s.variance_rays = s.adaptive_rays = s.skip = true;
                if (extra == 6) s.specular_occlusion = SpecularOcclusion::Horizon;
                out.push_back(s);
            }
    return out;
}

std::vector<UserPassDesc> Renderer::user_passes() const {
    std::vector<UserPassDesc> out;
    for (const auto& u : user_passes_) out.push_back(u->desc());
    return out;
}

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

// Where a placed user pass runs in `chain`: right after the pass it names (after), right before
// the one it names (before), or, naming none, right after the last pass that declares a texture
// it reads or rewrites (the earliest place where all of them exist). User passes placed at the
// same place keep Settings.user_passes order. Every texture it reads or rewrites must be declared
// by a pass before its place: otherwise the place is impossible, and the answer says why, naming
// that texture ("" when the place is `at`).
std::string Renderer::placement(const std::vector<RenderPass*>& chain, const UserPass& u, const RenderSettings& s,
                                const FrameFacts& facts, size_t& at) const {
    const UserPassDesc& d = u.desc();
    // The last pass that writes or rewrites `r`: what it reads is whole only after that one.
    auto writer = [&](const std::string& r) -> long {
        long last = -1;
        for (size_t i = 0; i < chain.size(); ++i) {
            for (const auto& o : chain[i]->outputs(s, facts))
                if (o.name == r) last = long(i);
            for (const auto& x : chain[i]->rewrites(s, facts))
                if (x == r) last = long(i);
        }
        return last;
    };
    auto names = [&] {
        std::string out;
        for (const RenderPass* p : chain) out += (out.empty() ? "" : ", ") + p->name();
        return out;
    };
    // Who would write a texture in another chain (for the message): the registry's first declarer.
    auto declarer = [&](const std::string& r) -> std::string {
        for (const RenderPass* p : passes_)
            for (const auto& o : p->outputs(s, facts))
                if (o.name == r) return p->name();
        return "";
    };
    const std::vector<std::string> needs = u.inputs(s, facts);
    auto verb = [&](const std::string& r) {
        return std::find(d.writes.begin(), d.writes.end(), r) != d.writes.end() ? "rewrites" : "reads";
    };
    at = 0;
    const std::string& anchor = d.after.empty() ? d.before : d.after;
    const std::string side = d.after.empty() ? "before" : "after";
    if (!anchor.empty()) {
        const auto a = std::find_if(chain.begin(), chain.end(), [&](const RenderPass* p) { return p->name() == anchor; });
        if (a == chain.end())
            return "runs " + side + " '" + anchor + "', which this frame's chain does not run (it runs: " + names() + ")";
        at = size_t(a - chain.begin()) + (d.after.empty() ? 0 : 1);
    } else {
        for (const auto& r : needs) {
            const long w = writer(r);
            if (w >= 0) at = std::max(at, size_t(w) + 1);  // a missing one is named below
        }
    }
    // After the user passes already placed here (Settings.user_passes order).
    if (d.before.empty())
        while (at < chain.size() && dynamic_cast<const UserPass*>(chain[at]) &&
               static_cast<const UserPass*>(chain[at])->placed())
            ++at;
    const std::string lead = anchor.empty() ? "" : "cannot run " + side + " '" + anchor + "': ";
    for (const auto& r : needs) {
        const long w = writer(r);
        if (w >= 0 && size_t(w) < at) continue;
        if (w >= 0)
            return lead + "it " + verb(r) + " '" + r + "', which no pass before that place writes ('" +
                   chain[size_t(w)]->name() + "' writes it" + (!d.before.empty() && size_t(w) == at ? "" : " later") + ")";
        const std::string who = declarer(r);
        return lead + "it " + verb(r) + " '" + r + "', which no pass of this frame's chain writes" +
               (who.empty() ? std::string("") : " ('" + who + "' declares it, and these settings do not run it)") +
               "; the chain runs: " + names();
    }
    return "";
}

void Renderer::place_user_pass(std::vector<RenderPass*>& chain, UserPass& u, const RenderSettings& s,
                               const FrameFacts& facts) const {
    size_t at = 0;
    const std::string why = placement(chain, u, s, facts, at);
    if (!why.empty()) {
        const bool named = why.rfind("runs ", 0) == 0;  // "runs after 'x', which ..." follows the name
        throw std::invalid_argument("Settings.user_passes: user pass '" + u.name() + "'" + (named ? " " : ": ") + why);
    }
    chain.insert(chain.begin() + long(at), &u);
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
