// A render pass: one unit that decides when it runs and declares the textures and buffers it
// reads and writes, in the spirit of Falcor's render passes. The renderer keeps every pass in
// one registry, in the order the papers run them; a frame's chain is the passes that say they
// run (Renderer::build_chain). The renderer allocates every declared texture, checks that each
// input, texture or buffer, was written by an earlier pass, times each pass on the GPU and
// checks GL errors after it. Texture names are shared with Python: frame.read("gbuffer.normal").
#pragma once

#include <algorithm>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "core/egl_context.h"
#include "core/gl_resources.h"
#include "core/gpu_timer.h"
#include "core/shader_library.h"
#include "render/camera.h"
#include "render/depth_convention.h"
#include "render/gpu_structs.h"
#include "render/gpu_scene.h"
#include "render/settings.h"

namespace ssr {

// How long a declared texture lives. Frame: with the frame that wrote it (frame.read()), in a
// texture set pooled for reuse. History: as Frame, and a later frame of a sequence reads it
// (the pass that reads it declares it in history_inputs()). Scratch: one copy per renderer,
// shared by every frame (the shadow map, the Hi-Z pyramid): only later passes of the same frame
// read it, and Python right after the render.
enum class Lifetime { Frame, History, Scratch };

// What components of a texel mean, declared with the texture that holds them: Frame's views
// (python/ssrlab/frame_views.py: GBuffer, RayResults, Reprojection) are made from these, so a
// channel's meaning and its decoding are written once, here, beside the format.
enum class ChannelDecode {
    Value,          // as stored (float)
    Flag,           // a bool: the stored value > 0.5
    Integer,        // an int32: the stored value rounded
    ByteIdMinusOne, // two unorm8 components, low byte first, as one integer minus 1 (-1: none)
    WindowPoint,    // (x, y) in GL window pixels (y up) as (column, row from the top): (x, height - y)
    WindowVector,   // a difference of window positions as (columns, rows down): (x, -y)
};
struct ChannelDesc {
    std::string view;  // the view that shows it: "gbuffer", "rays", "reprojection"
    std::string name;  // its property there: frame.gbuffer.normal
    int first = 0, count = 1;  // the texel's components [first, first + count)
    ChannelDecode decode = ChannelDecode::Value;
    std::string doc;   // what it is, with its unit and convention
    bool operator==(const ChannelDesc& o) const {
        return view == o.view && name == o.name && first == o.first && count == o.count && decode == o.decode;
    }
};
const char* decode_name(ChannelDecode d);

struct ResourceDesc {
    std::string name;
    GLenum format = GL_RGBA8;
    int width = 0, height = 0;
    int layers = 0;  // 0: a 2D texture; n >= 1: a 2D array of n layers (cube: 6 x its cubes)
    int levels = 1;  // 0: a full mip chain
    Lifetime lifetime = Lifetime::Frame;
    bool cube = false;  // a cube-map array of layers / 6 cubes (width == height)
    std::vector<ChannelDesc> channels;  // what its components mean, for Frame's views (none: raw)
    // Where the pass that creates it leaves texels unwritten (no work spent on them): a texel is
    // defined only where component `defined_component` of texture `defined_by`, same layer and
    // texel, is > 0.5; Frame::read gives 0 elsewhere. Empty: every texel is written.
    std::string defined_by;
    int defined_component = 0;
    bool operator==(const ResourceDesc& o) const {
        return name == o.name && format == o.format && width == o.width && height == o.height &&
               layers == o.layers && levels == o.levels && lifetime == o.lifetime && cube == o.cube &&
               channels == o.channels && defined_by == o.defined_by && defined_component == o.defined_component;
    }
    ResourceDesc with(std::vector<ChannelDesc> c) && {
        channels = std::move(c);
        return std::move(*this);
    }
};

// GPU bytes of a texture described by `d` (every mip level and layer).
size_t texture_bytes(const ResourceDesc& d);

// The textures of one frame, by name. While a chain runs, the renderer attaches its
// per-renderer scratch set (shadow map, Hi-Z pyramid: textures no one reads after the
// frame): get() and has() fall back to it, descs() and bytes() list the frame's own only.
class FrameResources {
public:
    Texture& get(const std::string& name);
    const Texture& get(const std::string& name) const;
    bool has(const std::string& name) const {
        return textures_.count(name) != 0 || (scratch_ && scratch_->has(name));
    }
    bool owns(const std::string& name) const { return textures_.count(name) != 0; }
    void attach_scratch(FrameResources* scratch) { scratch_ = scratch; }
    size_t bytes() const;
    void allocate(const std::vector<ResourceDesc>& descs);
    // Adds (or replaces) textures after allocation, e.g. a reference computed for a frame.
    void add(const std::vector<ResourceDesc>& descs);
    const std::vector<ResourceDesc>& descs() const { return descs_; }
    // While a pass executes, get() hands out only the textures it declares (its inputs, rewrites
    // and outputs) and throws GLError naming the pass and the texture otherwise: an undeclared read
    // would order the chain wrongly without a word (render_loop.cpp). Null: no restriction.
    void restrict_to(const std::set<std::string>* declared, const std::string* pass) {
        declared_ = declared;
        pass_ = pass;
    }
    // A number unique to the allocation that holds texture `name` now (0: none): a pass that
    // keeps what it wrote across frames (the shadow maps) knows that its texture was replaced.
    uint64_t generation(const std::string& name) const;

private:
    std::map<std::string, Texture> textures_;
    std::map<std::string, uint64_t> generations_;
    std::vector<ResourceDesc> descs_;
    FrameResources* scratch_ = nullptr;
    const std::set<std::string>* declared_ = nullptr;
    const std::string* pass_ = nullptr;
    void check_declared(const std::string& name) const;
};

// A GPU buffer one pass writes for later passes of its frame: a work list and the indirect
// dispatch arguments over it (classify's ray list, the peeling's covered tiles). Unlike a
// texture its size follows what the frame holds, so the writing pass owns the storage (one per
// renderer, Lifetime::Scratch: the passes of the same frame read it) and publishes it in
// FrameContext::buffers when it runs; a reader declares the name in buffer_inputs() and finds
// it there. The renderer checks that every declared buffer input is written by an earlier pass
// and that every pass published what it declared.
struct FrameBuffer {
    const Buffer* data = nullptr;
    GLuint binding = 0;              // the SSBO binding its shaders declare (shaders/lib/...)
    const Buffer* args = nullptr;    // the indirect dispatch arguments over it, or none
    GLintptr args_offset = 0;        // ... at this byte offset in `args`
    // Binds `data` as SSBO `binding` and `args` (if any) as the dispatch-indirect buffer: a
    // glDispatchComputeIndirect(args_offset) then runs over the list.
    void bind() const;
};

class FrameBuffers {
public:
    void publish(const std::string& name, const FrameBuffer& b) { buffers_[name] = b; }
    bool has(const std::string& name) const { return buffers_.count(name) != 0; }
    // The buffer published as `name` in this frame; throws GLError naming it when none was.
    const FrameBuffer& get(const std::string& name) const;
    void clear() { buffers_.clear(); }

private:
    std::map<std::string, FrameBuffer> buffers_;
};

// What a frame's chain depends on besides the settings: facts of the scene and the device.
struct FrameFacts {
    bool shadows = false;         // some light casts a shadow (the shadow_map pass runs)
    bool reflections = false;     // tracing is on and some surface reflects
    bool fetch_by_image = false;  // the passes read float inputs by imageLoad (the CPU device)
    // Some object's material has an emissive texture (GpuScene::has_emissive_texture): the
    // G-buffer then carries the emission (gbuffer.emission), which the lighting pass adds.
    bool emission_texture = false;
    int shadow_maps = 0;          // directional and spot casters: layers of shadow_map
    int shadow_cubes = 0;         // point casters: cubes of shadow_cubes
    // Some object's material has a KHR_materials_specular texture (GpuScene::has_specular_texture):
    // the G-buffer then carries every surface's dielectric F0 (gbuffer.specular), which the passes
    // that take F0 from the G-buffer read instead of the material's factor value.
    bool specular_texture = false;
};

// Whether a temporal technique of this frame reprojects its history (the reproject pass runs):
// the temporal reflections, the clamped TAA, bounces from history, ray reuse over time, or SVGF
// over a reflection (the thesis's TAA blends at the same pixel and needs none).
inline bool reprojects(const RenderSettings& s, const FrameFacts& f) {
    return s.temporal_reflections || s.taa == TaaMode::Clamped || s.bounces == Bounces::History ||
           s.temporal_ray_reuse || (f.reflections && s.denoise == Denoise::Svgf);
}
// Whether the deep G-buffer writes gbuffer.motion: asked for (Settings.motion_vectors), or read by
// the reprojection (seed 002, 4.6.4: a velocity buffer reprojects what moved). The one decision
// every construction's outputs() and execute() and the renderer's upload of the previous frame's
// object transforms follow: a frame that reprojects nothing writes no motion.
inline bool writes_motion(const RenderSettings& s, const FrameFacts& f) { return s.motion_vectors || reprojects(s, f); }

// What a pass may use while it executes.
struct FrameContext {
    EglContext& gl;
    ShaderLibrary& shaders;
    GpuTimer& timer;
    const RenderSettings& settings;
    const Scene& scene;
    const GpuScene& gpu_scene;
    const Camera& camera;
    const DepthConvention& depth;
    const FrameUniforms& uniforms;
    FrameResources& resources;
    Defines defines;  // common shader defines (depth convention, ...)
    // The buffers the passes of this frame published so far (FrameBuffer).
    FrameBuffers buffers{};
    // The previous frame of a sequence (render/sequence.h): its textures and constants, null
    // outside a sequence, on its first frame, or when its size or scene differ. Temporal passes
    // only read them, so running the chain again (the untimed first-use run) is harmless.
    const FrameResources* history = nullptr;
    const FrameUniforms* history_uniforms = nullptr;
    // Sub-pixel jitter of this frame (Settings.taa), in pixels, and the previous frame's
    // projection without its jitter: reprojection works on unjittered positions.
    glm::vec2 jitter_px{0.0f};
    glm::mat4 history_unjittered_proj{1.0f};
    // The G-buffer layers that hold a surface somewhere (frame.stats["layers_used"]),
    // set by the renderer after the peeling with Settings.skip; -1 (skip off, or before the
    // peeling): every allocated layer. The per-layer passes work on these layers only.
    int layers_used = -1;
    // The G-buffer layers the construction filled, as far as it knows them without waiting for the
    // GPU (its geometry pass sets it; the layers after them are empty); -1: unknown, every layer.
    int layers_filled = -1;
    // Clears of float and RGBA8 textures by image stores instead of glClearTexSubImage and
    // framebuffer clears (Renderer.clear_path; on by default on a GPU: passes/compute.h).
    bool clear_by_compute = false;
    // The visibility constructions mark and use each layer's covered tiles (Renderer.visibility_tiles).
    bool visibility_tiles = false;
    // The frame's facts (FrameFacts): the passes choose their variant from them and the settings.
    FrameFacts facts{};
    int layers_in_use() const { return layers_used >= 0 ? std::min(layers_used, settings.layers) : settings.layers; }
    // The passes read their float inputs as read-only images (FETCH_BY_IMAGE, the CPU
    // device; lib/input_fetch.glsl), bound by name (NamedUnits::fetch, passes/compute.h).
    bool fetch_by_image() const {
        const auto it = defines.find("FETCH_BY_IMAGE");
        return it != defines.end() && it->second == "1";
    }
};

// Image units a pass binds at most, outputs and inputs read by imageLoad (FETCH_BY_IMAGE) together:
// the device must offer this many to compute shaders for FETCH_BY_IMAGE (GL's minimum is 8; the
// resolve binds 10: its output, 7 inputs and resolve_fetch's two textures).
constexpr int kImageUnitsPerPass = 10;


class RenderPass {
public:
    virtual ~RenderPass() = default;
    // The name the papers give the pass; also its timer and error label.
    virtual std::string name() const = 0;
    // Whether the pass runs in a frame with these settings and facts: each pass decides.
    virtual bool runs(const RenderSettings& s, const FrameFacts& f) const = 0;
    // What it reads in a frame with these settings and facts (a variant's inputs).
    virtual std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const = 0;
    // Textures an earlier pass declares that this one reads and writes in place (the second trace
    // adds its rays to the first trace's textures). The chain runs it after their writer and before
    // every other reader it does not itself depend on (render/pass_registry.h).
    virtual std::vector<std::string> rewrites(const RenderSettings& s, const FrameFacts& f) const { return {}; }
    virtual std::vector<ResourceDesc> outputs(const RenderSettings& s) const = 0;
    // What it writes in a frame with these settings and facts: for most passes the settings'.
    virtual std::vector<ResourceDesc> outputs(const RenderSettings& s, const FrameFacts& f) const { return outputs(s); }
    // The buffers (FrameBuffer) it reads, found in FrameContext::buffers, and those it writes and
    // publishes there, in a frame with these settings and facts.
    virtual std::vector<std::string> buffer_inputs(const RenderSettings& s, const FrameFacts& f) const { return {}; }
    virtual std::vector<std::string> buffer_outputs(const RenderSettings& s, const FrameFacts& f) const { return {}; }
    // Textures of the previous frame of a sequence the pass reads when they are there (and falls
    // back without): declared, so the chain shows what a frame keeps for the next one.
    virtual std::vector<std::string> history_inputs(const RenderSettings& s) const { return {}; }
    // The stage of the chain the pass fills ("trace" for the screen-space tracers, "resolve"): a
    // user pass declared for that stage takes its place, one whose stage follows it runs right
    // after it (passes/user_pass.h). Empty: no stage a user pass refers to.
    virtual std::string stage() const { return ""; }
    // Settings this device cannot hold for this pass (a buffer too large), before anything is
    // allocated: throws std::invalid_argument naming the setting.
    virtual void check_device(const RenderSettings& s) const {}
    // Checks of the user's input that only this pass makes, before any pass of the frame runs.
    virtual void check(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& s) {}
    virtual void execute(FrameContext& ctx) = 0;
    // Work done outside the GL timeline that counts as first use (a capture cached across
    // frames): a change of this count makes the renderer run the chain again, untimed.
    virtual uint64_t first_uses() const { return 0; }
    // The pass's counts of the timed run, into frame.stats.
    virtual void report(const RenderSettings& s, std::map<std::string, double>& stats) const {}
    // Called once per frame before its runs (the untimed first-use run and the timed one), so
    // that a pass keeping its outputs across frames decides from the state the frame began with.
    virtual void begin_frame() {}
    // Whether the timed run did no work because everything it writes still held what this
    // frame needs (a shadow map reused): its timing is then 0.
    virtual bool reused() const { return false; }
    // The construction this pass is part of, whose time is the sum of its passes' (frame.timings
    // ["deep_gbuffer"]: the peeling, or the visibility buffer and its attribute pass); "": none.
    virtual std::string part_of() const { return ""; }
    // The samples each G-buffer layer received in the last frame (Frame.layer_samples), from the
    // pass that counts them; empty from every other pass.
    virtual std::vector<uint64_t> layer_samples() { return {}; }
    // Deletes the GL objects the pass keeps across frames, in the current context.
    virtual void release() {}
};

}  // namespace ssr
