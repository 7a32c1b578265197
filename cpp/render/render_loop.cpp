// The render loop: a frame's constants, its chain (build_chain) and resources
// (plan_resources), the untimed first-use run and the timed run; and the references that
// render a frame's ground truth with the same resources.
#include "render/renderer.h"

#include <chrono>
#include <set>
#include <glm/gtc/matrix_transform.hpp>

#include "core/errors.h"
#include "passes/composite.h"
#include "passes/compute.h"
#include "render/ssr_uniforms.h"

namespace ssr {

namespace {
constexpr size_t kMaxWarmedVariants = 1024;  // forgotten (and warmed again) beyond this
}  // namespace

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
    shadow_map_->set_setup(shadow);

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
    // Motion vectors: both frames' transforms without the jitter. The previous frame's objects are
    // the sequence's where it showed this scene with as many objects (moved or not), else this
    // frame's: no motion.
    u.view_proj_unjittered = unjittered_proj * u.view;
    u.previous_view_proj = u.view_proj_unjittered;
    std::vector<glm::mat4> models;
    models.reserve(scene.objects.size());
    for (const Object& o : scene.objects) models.push_back(o.transform);
    const bool motion_history = sequence && sequence->previous && sequence->scene_id == scene.id() &&
                                sequence->previous_models.size() == models.size() &&
                                sequence->previous_settings.width == s.width &&
                                sequence->previous_settings.height == s.height;
    if (motion_history) u.previous_view_proj = sequence->previous_unjittered_proj * sequence->previous_uniforms.view;
    // What the chain depends on besides the settings (the G-buffer writes motion for a chain that
    // reprojects: writes_motion).
    const FrameFacts frame_facts = facts(scene, gs, s);
    if (writes_motion(s, frame_facts)) {
        const std::vector<glm::mat4>& previous = motion_history ? sequence->previous_models : models;
        const size_t bytes = std::max<size_t>(previous.size(), 1) * sizeof(glm::mat4);
        if (previous_models_.size() < bytes) previous_models_ = Buffer::create(bytes);
        if (!previous.empty()) previous_models_.upload(previous.data(), previous.size() * sizeof(glm::mat4));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kPreviousModelsBinding, previous_models_.id());
    }
    frame_ubo_.upload(&u, sizeof(u));
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameUniformsBinding, frame_ubo_.id());

    upload_lights(scene, u.view, shadow);

    // Reflection settings as the shaders see them.
    const SsrUniforms su = ssr_uniforms(s);
    if (!ssr_ubo_) ssr_ubo_ = Buffer::create(sizeof(SsrUniforms));
    ssr_ubo_.upload(&su, sizeof(su));
    glBindBufferBase(GL_UNIFORM_BUFFER, kSsrSettingsBinding, ssr_ubo_.id());
    if (gs.environment_map()) glBindTextureUnit(frame_texture_unit("environment_map"), gs.environment_map());
    bind_specular_albedo();
    gs.bind_geometry();  // the scene's objects and materials, for every pass that reads them

    // The chain and its resources (resource_plan.cpp).
    const std::vector<RenderPass*> chain = build_chain(s, frame_facts);
    const ResourcePlan plan = plan_resources(chain, s, frame_facts);
    const std::vector<ResourceDesc>& descs = plan.descs;
    const std::string& sized_by = plan.sized_by;
    const size_t needed = plan.bytes;
    // Scratch outputs (declared Lifetime::Scratch: the shadow map, Hi-Z) live once per renderer;
    // the frame gets the rest.
    std::vector<ResourceDesc> own, scratch;
    for (const auto& d : descs) (d.lifetime == Lifetime::Scratch ? scratch : own).push_back(d);
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

    const Defines defines = common_defines(scene, gs, depth);
    FrameContext fc{*ctx_, *shaders_, timer_, s, scene, gs, camera, depth, u, *resources, defines};
    fc.clear_by_compute = clear_by_compute();
    fc.visibility_tiles = marks_visibility_tiles();
    fc.facts = frame_facts;
    if (sequence && sequence->usable(s, scene.id(), scene.geometry_revision()) && sequence->previous != resources) {
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
    // The scene's part is its geometry: a moved object or an edited material uses the same
    // buffers (a material that needs another program is caught below, by the compilation).
    const std::string variant = variant_key(chain, descs, defines) + "scene:" + std::to_string(scene.id()) + "/" +
                                std::to_string(scene.geometry_revision());
    bool warm = warmed_variants_.count(variant) != 0;
    // Each pass's own checks of the user's input, before any pass runs.
    for (RenderPass* p : chain) p->check(scene, gs, s);
    auto first_uses = [&chain] {
        uint64_t n = 0;
        for (const RenderPass* p : chain) n += p->first_uses();
        return n;
    };
    for (RenderPass* p : chain) p->begin_frame();
    for (int run = 0;; ++run) {
        const size_t programs_before = shaders_->cached_programs();
        const uint64_t first_uses_before = first_uses();
        timer_.begin_frame();
        frame->passes.clear();
        fc.layers_used = -1;
        fc.layers_filled = -1;
        fc.buffers.clear();
        for (RenderPass* p : chain) {
            // The pass gets the textures it declares and no others (FrameResources::restrict_to).
            std::set<std::string> declared;
            for (const auto& x : p->inputs(s, frame_facts)) declared.insert(x);
            for (const auto& x : p->rewrites(s, frame_facts)) declared.insert(x);
            for (const auto& d : p->outputs(s, frame_facts)) declared.insert(d.name);
            const std::string name = p->name();
            struct Unrestrict {
                FrameResources& r;
                ~Unrestrict() { r.restrict_to(nullptr, nullptr); }
            } unrestrict{*resources};
            resources->restrict_to(&declared, &name);
            try {
                GpuScope t(timer_, p->name());
                p->execute(fc);
            } catch (const ShaderError&) {
                // The compiler's message is the ShaderError's: it must not come back as a GLError
                // from the driver's debug output at the next call (a user pass's shader being edited).
                ctx_->take_debug_errors();
                throw;
            }
            check_gl(*ctx_, p->name().c_str());
            for (const auto& b : p->buffer_outputs(s, frame_facts))
                if (!fc.buffers.has(b))
                    throw GLError("pass " + p->name() + " declares the buffer '" + b + "' and did not publish it");
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
    // A pass whose outputs still held what this frame needs did nothing (a reused shadow map).
    for (const RenderPass* p : chain)
        if (p->reused()) frame->timings[p->name()] = 0.0;
    // A construction's time, whatever passes built it (RenderPass::part_of: the deep G-buffer by
    // peeling, or by the visibility buffer and its attribute pass), and the layers' samples from the
    // pass that counted them.
    for (const RenderPass* p : chain)
        if (!p->part_of().empty()) frame->timings[p->part_of()] += frame->timings[p->name()];
    for (RenderPass* p : chain)
        if (frame->layer_samples.empty()) frame->layer_samples = p->layer_samples();
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
    frame->shadow_maps = shadow.maps;
    frame->shadow_cubes = shadow.cubes;
    frame->serial = serial;
    for (const auto& d : scratch) scratch_owner_[d.name] = serial;
    frame->wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start).count();
    // The frame becomes its sequence's history only now, after every run of the chain: the
    // untimed first-use run and the timed run read the same history and write the same result.
    if (sequence) {
        sequence->previous = resources;
        sequence->previous_uniforms = u;
        sequence->previous_unjittered_proj = unjittered_proj;
        sequence->previous_models = std::move(models);
        sequence->previous_settings = s;
        sequence->scene_id = scene.id();
        sequence->scene_revision = scene.geometry_revision();
        ++sequence->frames;
    }
    recycle();
    return frame;
}

std::map<std::string, double> Renderer::reference(const Scene& scene, Frame& frame, bool per_ray, int rays,
                                                  uint32_t seed, Sampling sampling, bool viewer_is_ray,
                                                  bool traced_shadows, const std::string& tracer,
                                                  std::function<bool(int, int)> progress) {
    if (tracer != "auto" && tracer != "embree" && tracer != "glsl" && tracer != "cpu")
        throw std::invalid_argument("reference: tracer must be 'auto', 'cpu', 'embree' or 'glsl', got '" + tracer + "'");
    if (tracer == "cpu" && per_ray)
        throw std::invalid_argument("reference: tracer 'cpu' traces the converged reference only, not the per-ray one");
    const bool shadows = frame.shadow_maps + frame.shadow_cubes > 0;
    if (tracer == "cpu" && shadows && !traced_shadows)
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
    // The scene is the frame's own (same revision, checked above) and the fit depends only on
    // the scene and the settings: the casters and maps the frame was lit with.
    const ShadowSetup setup = ShadowMapPass::fit(scene, gs.bounds(), s);
    FrameFacts shadow_facts;
    shadow_facts.shadows = shadows;
    shadow_facts.shadow_maps = frame.shadow_maps;
    shadow_facts.shadow_cubes = frame.shadow_cubes;
    upload_lights(scene, frame.uniforms.view, setup);
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
    if (gs.environment_map()) glBindTextureUnit(frame_texture_unit("environment_map"), gs.environment_map());
    bind_specular_albedo();

    if (shadows && !traced_shadows) {
        // The shared shadow maps may hold a later frame's (another scene, settings or state of
        // this one): the pass draws again every map that does not hold this frame's (its keys,
        // passes/shadow_map.h), and none when they all do.
        scratch_.add(shadow_map_->outputs(s, shadow_facts));
        shadow_map_->set_setup(setup);
        const DepthConvention dc{s.depth_mode};
        Defines d;
        dc.add_defines(d);
        FrameContext sfc{*ctx_, *shaders_, timer_, s, scene, gs, frame.camera, dc, frame.uniforms, scratch_, d};
        sfc.clear_by_compute = clear_by_compute();
        sfc.facts = shadow_facts;
        shadow_map_->begin_frame();
        shadow_map_->execute(sfc);
        check_gl(*ctx_, "shadow_map (again, for the reference)");
        for (const auto& d : shadow_map_->outputs(s, shadow_facts)) scratch_owner_[d.name] = frame.serial;
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
    const Defines defines = common_defines(scene, gs, depth);
    FrameContext fc{*ctx_, *shaders_, timer_, s, scene, gs, frame.camera, depth, frame.uniforms, frame.resources(),
                    defines};
    fc.clear_by_compute = clear_by_compute();
    fc.visibility_tiles = marks_visibility_tiles();
    fc.facts.shadows = shadows;
    fc.facts.reflections = true;
    fc.facts.fetch_by_image = fetch_by_image_;
    fc.facts.emission_texture = gs.has_emissive_texture();
    fc.facts.shadow_maps = frame.shadow_maps;
    fc.facts.shadow_cubes = frame.shadow_cubes;
    fc.facts.specular_texture = gs.has_specular_texture();
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
        for (const auto& in : p->inputs(s, fc.facts))
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

}  // namespace ssr
