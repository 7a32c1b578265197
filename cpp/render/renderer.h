// The renderer: owns the EGL context, the shader library, the GPU copies of scenes and the
// passes, and runs a frame as a chain of passes (build_chain). Every public call makes the
// context current for its duration only (CurrentContext): any thread, one call at a time.
#pragma once

#include <list>
#include <functional>
#include <map>
#include <set>
#include <memory>
#include <string>
#include <vector>

#include "core/egl_context.h"
#include "core/gpu_timer.h"
#include "core/shader_library.h"
#include "passes/reference.h"
#include "passes/shadow_map.h"
#include "passes/user_pass.h"
#include "render/frame.h"
#include "render/pass_registry.h"
#include "render/gpu_scene.h"
#include "render/sequence.h"

namespace ssr {

class Renderer : public std::enable_shared_from_this<Renderer> {
public:
    // input_fetch: how the passes read float inputs (lib/input_fetch.glsl): "auto" (imageLoad on the
    // CPU device, texelFetch on a GPU), "imageLoad" or "texelFetch".
    static std::shared_ptr<Renderer> create(const std::string& device, const std::string& shader_dir,
                                            const std::string& input_fetch = "auto");
    ~Renderer();

    // `sequence` (optional): the frame is the next of that sequence; temporal passes read the
    // previous frame's textures from it, and the frame becomes its history (render/sequence.h).
    std::shared_ptr<Frame> render(const Scene& scene, const Camera& camera, const RenderSettings& settings,
                                  Sequence* sequence = nullptr);
    // The passes a render of `scene` with `settings` runs, in order, each with the resources it
    // reads and writes (what render() would run: the same build_chain, the same scene facts).
    struct ChainEntry {
        std::string pass;
        std::vector<std::string> inputs, outputs;
        std::vector<std::string> history;  // read from the previous frame of a sequence (history_inputs)
        std::vector<std::string> scratch;  // the outputs that are per-renderer scratch (Lifetime::Scratch)
        std::vector<std::string> buffer_inputs, buffer_outputs;  // FrameBuffer names
        std::vector<std::string> formats;  // of each texture it creates (outputs but its rewrites), as GL names it
        std::vector<std::string> channels;  // of each texture it creates: its declared channels, "view.name (rgb)", ", "-joined
    };
    // The passes a frame of `scene` with `settings` runs, in order, with what each reads and
    // writes: no GL call, no scene upload (the facts come from the scene itself).
    std::vector<ChainEntry> chain(const Scene& scene, const RenderSettings& settings) const;
    // The same for the built-in passes alone, without a renderer (no GL context is made):
    // `fetch_by_image` as a renderer on the CPU device decides it (Renderer::fetch_by_image).
    static std::vector<ChainEntry> builtin_chain(const Scene& scene, const RenderSettings& settings,
                                                 bool fetch_by_image);
    static std::vector<ChainEntry> describe_chain(const std::vector<RenderPass*>& chain, const RenderSettings& s,
                                                  const FrameFacts& f);
    // Registers a user pass (passes/user_pass.h) after checking its declaration against the passes
    // this renderer has: a name no other pass has; reads that an earlier pass (or an earlier user
    // pass) writes; writes only its stage's resources (a placed pass: any declared texture an
    // image store can write); a pass it names to run after or before that exists and a place
    // where what it reads is written; new textures no pass declares. Throws
    // std::invalid_argument naming the pass and the resource (and the pass that owns it).
    void register_user_pass(const UserPassDesc& desc);
    std::vector<UserPassDesc> user_passes() const;
    // A new, empty sequence of frames (its history lives as long as it does).
    std::shared_ptr<Sequence> begin_sequence() { return std::make_shared<Sequence>(ctx_); }
    static glm::vec2 taa_jitter(TaaMode mode, int index);

    // Ground truth for a rendered frame (passes/reference.h): per-ray (the frame's own SSR
    // rays) or converged (`rays` rays per pixel drawn with `sampling`). The textures join the
    // frame (frame.read("reference.reflection"), ...). Returns the GPU milliseconds spent.
    // tracer: "glsl" (the BVH traversal in the shader), "embree" (the converged reference's rays
    // through Embree on the CPU, ray generation and shading still in the shader) or "auto" (for now
    // "glsl", the faster one measured on both devices); the per-ray reference always traces in GLSL. progress is
    // called after each sample round with (done, total); returning false (or throwing) stops the
    // reference, and an error is raised: its textures are then incomplete. The timings name the
    // wavefront's stages (reference.shade, .intersect, .transfer) and its traced ray count.
    std::map<std::string, double> reference(const Scene& scene, Frame& frame, bool per_ray, int rays, uint32_t seed,
                                            Sampling sampling, bool viewer_is_ray, bool traced_shadows,
                                            const std::string& tracer = "glsl",
                                            std::function<bool(int, int)> progress = nullptr);
    DeviceInfo info() const { return ctx_->info(); }
    // Float textures are downloaded with rows top first by the driver (GL_MESA_pack_invert).
    bool pack_invert() const { return pack_invert_; }
    // How textures reach the CPU (read_texture): "download" (glGetTextureSubImage of float
    // formats, the copy pass for the others), "staged" (every format through the copy pass into
    // a storage buffer, copied into a persistently mapped client buffer, read after a fence), or
    // "auto": staged on a GPU, download on the CPU device.
    const std::string& readback_path() const { return readback_path_; }
    void set_readback_path(const std::string& path);
    bool readback_staged() const;
    // How the passes clear textures (passes/compute.h, clear_layers): "gl" (glClearTexSubImage and
    // framebuffer clears), "compute" (image stores, for float and RGBA8 formats) or "auto":
    // compute on a GPU, gl on the CPU device. The images are the same either way.
    const std::string& clear_path() const { return clear_path_; }
    void set_clear_path(const std::string& path);
    bool clear_by_compute() const;
    // Whether the visibility constructions mark each layer's covered tiles as they build them and
    // the attribute pass works over those tiles only (passes/visibility_buffer.h): "auto" (on the
    // CPU device: llvmpipe shades every pixel it is given; a GPU is not stalled to read the tiles
    // back), "on" or "off". The images are the same either way.
    const std::string& visibility_tiles() const { return visibility_tiles_; }
    void set_visibility_tiles(const std::string& mode);
    bool marks_visibility_tiles() const;
    // Whether the passes read their float inputs by imageLoad (lib/input_fetch.glsl).
    bool fetch_by_image() const { return fetch_by_image_; }
    int max_texture_size() const { return max_texture_size_; }
    int max_array_layers() const { return max_array_layers_; }
    // Programs compiled so far (every program is compiled once per renderer and variant).
    size_t compiled_programs() const { return shaders_->cached_programs(); }
    void check_errors();
    ShaderLibrary& shaders() { return *shaders_; }
    // Compiles a program in this renderer's context (tests and tooling); raises ShaderError.
    unsigned compile(const std::vector<std::string>& stages, const Defines& defines);
    // A compiled program's block as the driver laid it out (block_layout, core/shader_library.h).
    BlockLayout block_layout(unsigned program, const std::string& block);

    // Reflection directions drawn by the trace passes' GLSL (shaders/tools/brdf_samples.comp):
    // `count` rows of (l.x, l.y, l.z, weight, pdf, u1, u2, 0) for a local view direction.
    std::vector<float> sample_reflections(const std::string& sampling, float alpha, const glm::vec3& view, int count,
                                          uint32_t seed, bool stratified);

    // Device peaks for the roofline (shaders/tools/microbench.comp): runs kernel `kernel`
    // ("coherent", "dependent", "store", "bandwidth", "copy") over a width x height grid with
    // `iterations` operations per invocation, once untimed (compilation, first use) and then
    // `repeats` times, each timed alone on the GPU; returns the milliseconds of each repeat.
    std::vector<double> microbenchmark(const std::string& kernel, int width, int height, int iterations, int repeats);

    // The device's floors under the deep G-buffer's constructions (shaders/tools/raster_floor.*):
    // `scene`'s own triangles seen by `camera` at settings.width x height (its depth mode and
    // culling), through the G-buffer's vertex shader, drawn depth only ("depth"), into the
    // G-buffer's targets through the raster outputs ("gbuffer"), into depth and an R32UI triangle id
    // ("id"), appended 8 bytes a fragment to per-pixel arrays ("append") and linked lists
    // ("append_list"); compute image stores of one layer's bytes ("stores"); and the clears
    // ("clear.depth", "clear.gbuffer", "clear.id_texture", "clear.id_compute", "clear.counters",
    // "clear.heads", "clear.compute_colour"). Each floor once untimed, then `repeats` times each in
    // turn, each timed alone on the GPU: the milliseconds of every repeat. Keys "count.*" hold one
    // value each, counted untimed: the fragments rasterised (occlusion query and per-pixel
    // counters), the samples and covered pixels of the depth and id draws, the deepest pixel.
    std::map<std::string, std::vector<double>> raster_floor(const Scene& scene, const Camera& camera,
                                                            const RenderSettings& settings, int repeats);

    // The split-sum table (A, B) of the GGX directional albedo (shaders/lib/specular_albedo.glsl),
    // integrated once per renderer: (size, size, 2) floats, rows roughness, columns n.v.
    Readback specular_albedo_table();

    // Used by Frame::read: copies a texture level into host memory through readback.comp.
    Readback read_texture(const Texture& tex, int level);
    DisplayBytes display_bytes(const Texture& tex, float exposure, const std::vector<float>& thresholds);

    // Whether `name` is a per-renderer scratch texture (declared Lifetime::Scratch): shared by
    // all frames instead of one copy per kept frame.
    bool is_scratch(const std::string& name) const { return scratch_.owns(name); }
    // The scratch texture `name` if it still holds frame `serial`'s content, else null.
    const Texture* scratch_of(const std::string& name, uint64_t serial) const;
    std::vector<std::string> scratch_names_of(uint64_t serial) const;
    // Drops idle texture sets beyond the pool's size and gives freed heap memory back to the
    // OS (malloc_trim) once enough was freed, or at once with force. Frames call it when they
    // release or die.
    void recycle(bool force = false);
    // GPU bytes held: every frame texture set (live or pooled) plus scratch.
    size_t gpu_bytes() const;
    size_t scratch_bytes() const { return scratch_.bytes(); }
    // Work the renderer did outside the frame chain ("passes only when used"): scene
    // uploads (a GpuScene built, its geometry uploaded: a new scene or new geometry; a camera
    // change is none), scene updates (moved objects', edited materials' or lights' changes
    // written into the copy, object_updates and material_updates entries), BVH builds (once per
    // scene geometry) and updates after moves (bvh_updated_triangles rebuilt in all; the last
    // update's wall time bvh_update_ms and its triangles bvh_update_last_triangles), texture
    // read-backs and their bytes.
    std::map<std::string, double> stats() const {
        return {{"scene_uploads", double(scene_uploads_)},
                {"scene_updates", double(scene_updates_)},
                {"object_updates", double(scene_work_.object_updates)},
                {"material_updates", double(scene_work_.material_updates)},
                {"bvh_builds", double(scene_work_.bvh_builds)},
                {"bvh_updates", double(scene_work_.bvh_updates)},
                {"bvh_updated_triangles", double(scene_work_.bvh_updated_triangles)},
                {"bvh_update_ms", scene_work_.bvh_update_ms},
                {"bvh_update_last_triangles", double(scene_work_.bvh_update_last_triangles)},
                {"readbacks", double(readbacks_)},
                {"readback_bytes", double(readback_bytes_)}};
    }

private:
    Renderer(const std::string& device, const std::string& shader_dir, const std::string& input_fetch);
    const GpuScene& gpu_scene(const Scene& scene);
    std::shared_ptr<FrameResources> acquire(const std::vector<ResourceDesc>& descs);
    // The passes of a frame with these settings and facts: those of passes_ that say they run.
    std::vector<RenderPass*> build_chain(const RenderSettings& s, const FrameFacts& facts) const;
    // Those of `passes` that run, a chosen user pass of a stage in its pass's place (or right after
    // the pass its stage follows), in the order of their declarations (order_chain).
    static std::vector<RenderPass*> ordered_chain(const std::vector<RenderPass*>& passes,
                                                  const std::vector<UserPass*>& chosen, const RenderSettings& s,
                                                  const FrameFacts& facts);
    // Puts a placed user pass into `chain` where its resources are (invalid_argument naming the
    // texture it would read before a pass writes it).
    void place_user_pass(std::vector<RenderPass*>& chain, UserPass& u, const RenderSettings& s,
                         const FrameFacts& facts) const;
    // The place of a placed user pass in `chain` (at), or why it has none there, naming the input.
    std::string placement(const std::vector<RenderPass*>& chain, const UserPass& u, const RenderSettings& s,
                          const FrameFacts& facts, size_t& at) const;
    // Settings whose chains together hold every built-in pass (a placement checked at registration).
    static std::vector<RenderSettings> placement_variants();
    FrameFacts facts(const Scene& scene, const GpuScene& gs, const RenderSettings& s) const;
    // Settings.user_passes and user_params against the registered user passes (invalid_argument
    // naming them); returns the chosen passes.
    std::vector<UserPass*> check_user_settings(const RenderSettings& s) const;
    // The defines every pass of a frame of `scene` compiles with (depth convention, environment, ...).
    Defines common_defines(const Scene& scene, const GpuScene& gs, const DepthConvention& depth) const;
    // The textures of a chain, checked (each input written before it is read, the device's limits,
    // its memory) before any is allocated (resource_plan.cpp).
    struct ResourcePlan {
        std::vector<ResourceDesc> descs;
        size_t bytes = 0;
        std::string sized_by;  // the settings that size them, for messages
    };
    ResourcePlan plan_resources(const std::vector<RenderPass*>& chain, const RenderSettings& s, const FrameFacts& f) const;
    static std::string gib(size_t bytes);
    void upload_lights(const Scene& scene, const glm::mat4& view, const ShadowSetup& shadow);
    void destroy_gl_objects();
    // Integrates the specular-albedo table on first use and binds it to its texture unit.
    void bind_specular_albedo();
    static std::string variant_key(const std::vector<RenderPass*>& chain, const std::vector<ResourceDesc>& descs,
                                   const Defines& defines);

    std::shared_ptr<EglContext> ctx_;  // first member: destroyed last, after every GL object
    std::unique_ptr<ShaderLibrary> shaders_;
    GpuTimer timer_;
    Buffer frame_ubo_, ssr_ubo_, lights_ssbo_, readback_ssbo_, readback_staging_, display_ssbo_;
    Buffer previous_models_;  // motion vectors: the previous frame's model matrices (lib/motion.glsl)
    std::string readback_path_ = "auto";
    std::string clear_path_ = "auto";
    std::string visibility_tiles_ = "auto";
    GLuint readback_sampler_ = 0;
    bool pack_invert_ = false;  // GL_MESA_pack_invert: downloads come with rows top first
    bool fetch_by_image_ = false;  // FETCH_BY_IMAGE: the CPU device (llvmpipe), see lib/input_fetch.glsl
    GLint max_texture_size_ = 0, max_array_layers_ = 0, max_cube_size_ = 0;  // the device's limits, checked per frame
    Texture specular_albedo_;

    struct CachedScene {
        uint64_t id = 0;
        std::unique_ptr<GpuScene> gpu;
    };
    std::list<CachedScene> scenes_;  // most recently used first
    std::vector<std::shared_ptr<FrameResources>> pool_;
    std::set<std::string> warmed_variants_;  // variants whose first-use costs were paid untimed
    FrameResources scratch_;                        // outputs declared Lifetime::Scratch
    std::map<std::string, uint64_t> scratch_owner_;  // scratch name -> serial of the frame it holds
    uint64_t next_serial_ = 1;
    size_t freed_since_trim_ = 0;  // bytes of texture sets freed since the last malloc_trim
    uint64_t scene_uploads_ = 0, scene_updates_ = 0, readbacks_ = 0, readback_bytes_ = 0;  // stats()
    SceneWork scene_work_;  // stats(): what the scene copies did

    // One instance of every registered pass (render/pass_registry.h), and the same in the order
    // their declarations give over every technique's settings (the order a user pass's
    // registration is checked against; a frame's chain is ordered anew from its own declarations).
    std::vector<std::unique_ptr<RenderPass>> owned_passes_;
    std::vector<RenderPass*> passes_;
    // The shadow maps, which a reference draws again for its own lights (reference()).
    ShadowMapPass* shadow_map_ = nullptr;
    // User passes (register_user_pass), in registration order: build_chain puts those
    // Settings.user_passes names in their stage's place.
    std::vector<std::unique_ptr<UserPass>> user_passes_;
};

}  // namespace ssr
