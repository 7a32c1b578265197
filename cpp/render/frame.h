// The result of Renderer::render: the frame's textures stay on the GPU and are read back
// only when asked for (read()). A Frame keeps its textures (and the GL context) alive;
// the renderer reuses a texture set once no Frame holds it any more. Scratch textures
// (shadow map, Hi-Z pyramid) belong to the renderer and are shared by every frame: a frame
// can read them only until the next render overwrites them (a kept frame no
// longer holds a 16 MiB shadow map). release() gives the frame's own textures back early.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/egl_context.h"
#include "render/camera.h"
#include "render/gpu_structs.h"
#include "render/ssr_uniforms.h"
#include "render/render_pass.h"
#include "render/settings.h"

namespace ssr {

class Renderer;

// An allocator whose resize leaves new floats uninitialised: a readback overwrites every one,
// so zeroing them first would be one more pass over up to hundreds of MB.
template <typename T>
struct UninitialisedAllocator : std::allocator<T> {
    template <typename U>
    struct rebind {
        using other = UninitialisedAllocator<U>;
    };
    UninitialisedAllocator() = default;
    template <typename U>
    UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
    template <typename U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

using ReadbackData = std::vector<float, UninitialisedAllocator<float>>;

struct Readback {
    int layers = 1, height = 0, width = 0, channels = 4;
    ReadbackData data;  // (layers, height, width, 4), row 0 = top of the image
};

// A colour as 8-bit sRGB codes, (height, width, 3), row 0 = top of the image.
struct DisplayBytes {
    int height = 0, width = 0;
    std::vector<uint8_t, UninitialisedAllocator<uint8_t>> rgb;
};

class Frame {
public:
    Frame(std::shared_ptr<EglContext> ctx, std::weak_ptr<Renderer> renderer, std::shared_ptr<FrameResources> resources);
    ~Frame();

    // All layers of a texture's mip `level`, as float RGBA (depth in channel 0).
    Readback read(const std::string& name, int level = 0);
    std::vector<std::string> texture_names() const;
    // A float colour texture of the frame as the 8-bit sRGB codes of `exposure` times it
    // (passes/display_bytes.comp): thresholds[k - 1] is the smallest linear value of code k.
    DisplayBytes display_bytes(const std::string& name, float exposure, const std::vector<float>& thresholds);
    // What the channels of the frame's own textures mean, as the passes that wrote them declared
    // (ResourceDesc::channels), with the texture that holds each, in the chain's order.
    std::vector<std::pair<const ResourceDesc*, ChannelDesc>> channels() const;
    bool has(const std::string& name) const;
    FrameResources& resources();
    // Frees the frame's own textures now (later reads raise); idempotent.
    void release();
    bool released() const { return !resources_; }
    size_t gpu_bytes() const { return resources_ ? resources_->bytes() : 0; }
    uint64_t serial = 0;  // which render made it: scratch textures name the frame they hold

    std::map<std::string, double> timings;  // GPU milliseconds per pass (and per part)
    double wall_ms = 0.0;                   // CPU time of Renderer::render, GPU finished
    int warmup_runs = 0;                    // untimed runs of the chain before the timed one (first use)
    RenderSettings settings;
    Camera camera;
    FrameUniforms uniforms{};
    SsrUniforms ssr{};
    uint64_t scene_id = 0, scene_revision = 0;  // the scene it showed, to match a later reference
    int shadow_maps = 0, shadow_cubes = 0;       // its shadow maps: layers of shadow_map, cubes of shadow_cubes
    std::vector<std::string> passes;        // the chain that ran, in order
    std::map<std::string, double> stats;   // work counts from the GPU
    std::vector<uint64_t> layer_samples;    // depth-test-passing samples drawn into each layer

private:
    std::shared_ptr<EglContext> ctx_;
    std::weak_ptr<Renderer> renderer_;
    std::shared_ptr<FrameResources> resources_;
};

}  // namespace ssr
