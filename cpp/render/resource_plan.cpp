// Resource planning: the textures a chain declares, checked against the device and its
// memory before any is allocated; the pool of frame texture sets and the per-renderer
// scratch (outputs declared Lifetime::Scratch).
#include "render/renderer.h"

#include <algorithm>
#include <cstdio>
#include <set>
#if defined(__GLIBC__)
#include <malloc.h>  // malloc_trim
#endif

#include "core/errors.h"

namespace ssr {

namespace {

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

constexpr size_t kPoolSize = 4;  // idle texture sets kept for reuse
// llvmpipe keeps textures in host memory from malloc; glibc keeps freed blocks in its heap,
// so memory of dropped frames stayed with the process (6.9 GB after 400 kept-then-dropped
// frames) until malloc_trim returns it, once this much was freed since the last trim.
constexpr size_t kTrimBytes = size_t(8) << 20;
}  // namespace

std::string Renderer::gib(size_t bytes) { return ssr::gib(bytes); }

// Every texture the chain declares, in chain order, after checking that each input is written
// by an earlier pass, that each fits the device's limits and that all fit its memory.
Renderer::ResourcePlan Renderer::plan_resources(const std::vector<RenderPass*>& chain, const RenderSettings& s,
                                                const FrameFacts& f) const {
    std::vector<ResourceDesc> descs;
    std::set<std::string> written, buffers;
    for (RenderPass* p : chain) {
        for (const auto& in : p->inputs(s, f))
            if (!written.count(in))
                throw GLError("pass " + p->name() + " reads '" + in + "', which no earlier pass writes");
        for (const auto& in : p->rewrites(s, f))
            if (!written.count(in))
                throw GLError("pass " + p->name() + " rewrites '" + in + "', which no earlier pass writes");
        for (const auto& in : p->buffer_inputs(s, f))
            if (!buffers.count(in))
                throw GLError("pass " + p->name() + " reads the buffer '" + in + "', which no earlier pass writes");
        for (const auto& d : p->outputs(s, f)) {
            descs.push_back(d);
            written.insert(d.name);
        }
        for (const auto& b : p->buffer_outputs(s, f)) buffers.insert(b);
    }
    // Every texture within the device's limits before any is allocated (GL would only answer
    // GL_INVALID_VALUE): the message names the texture and the settings that size it.
    for (const auto& d : descs) {
        // The shadow maps are sized by Settings.shadow_map_size and counted by the casting lights.
        const bool shadow = d.name == "shadow_map" || d.name == "shadow_cubes";
        const int max_size = d.cube ? max_cube_size_ : max_texture_size_;
        if (d.width > max_size || d.height > max_size) {
            const std::string limit = std::string("this device's ") +
                                      (d.cube ? "GL_MAX_CUBE_MAP_TEXTURE_SIZE (" : "GL_MAX_TEXTURE_SIZE (") +
                                      std::to_string(max_size) + ")";
            if (shadow)
                throw std::invalid_argument("Settings.shadow_map_size = " + std::to_string(d.width) + " is beyond " +
                                            limit + (d.cube ? " (the cube maps of the point lights that cast shadows)" : ""));
            throw std::invalid_argument(
                "Settings.width x Settings.height = " + std::to_string(s.width) + " x " + std::to_string(s.height) +
                " needs the texture '" + d.name + "' of " + std::to_string(d.width) + " x " + std::to_string(d.height) +
                " texels, beyond " + limit + ": render a smaller image");
        }
        if (d.layers > max_array_layers_) {
            if (shadow)
                throw std::invalid_argument("the texture '" + d.name + "' needs " + std::to_string(d.layers) +
                                            " layers (" + (d.cube ? "6 per point light" : "1 per directional or spot light") +
                                            " that casts a shadow), beyond this device's GL_MAX_ARRAY_TEXTURE_LAYERS (" +
                                            std::to_string(max_array_layers_) + "): set cast_shadow=False on some lights");
            throw std::invalid_argument("the texture '" + d.name + "' needs " + std::to_string(d.layers) +
                                        " layers, beyond this device's GL_MAX_ARRAY_TEXTURE_LAYERS (" +
                                        std::to_string(max_array_layers_) + "): lower Settings.layers or rays_per_pixel");
        }
    }
    // Each pass's limits of this device (a buffer it would allocate), refused before anything is.
    for (const RenderPass* p : chain) p->check_device(s);
    // On the CPU device the textures take system memory: a frame that cannot fit is refused
    // here rather than killed by the OS mid-frame (idle texture sets and scratch can be reused).
    // Asked of the system only beyond 256 MiB of new textures, not on every ordinary frame.
    size_t needed = 0;
    for (const auto& d : descs) needed += texture_bytes(d);
    // The shadow maps' share: shadow_map_size^2 x 4 bytes x (layers + 6 x cubes), one layer per
    // directional or spot caster, one cube per point caster.
    int shadow_layers = 0;
    for (const auto& d : descs)
        if (d.name == "shadow_map" || d.name == "shadow_cubes") shadow_layers += std::max(d.layers, 1);
    const std::string sized_by = "Settings (" + std::to_string(s.width) + " x " + std::to_string(s.height) +
                                 ", layers " + std::to_string(s.layers) + ", rays_per_pixel " +
                                 std::to_string(s.rays_per_pixel) +
                                 (shadow_layers > 0 ? ", shadow_map_size " + std::to_string(s.shadow_map_size) + " for " +
                                                          std::to_string(shadow_layers) +
                                                          (shadow_layers == 1 ? " shadow-map face" : " shadow-map faces")
                                                    : std::string()) +
                                 ")";
    if (ctx_->info().chosen == "cpu") {
        size_t reusable = scratch_.bytes();
        for (const auto& r : pool_)
            if (r.use_count() == 1) reusable += r->bytes();
        const size_t available = needed > reusable + (size_t(256) << 20) ? system_memory_available() : 0;
        if (available > 0 && needed > available + reusable)
            throw std::invalid_argument(sized_by + " need " + gib(needed) + " of textures, more than the " +
                                        gib(available + reusable) +
                                        " of memory available to the CPU device: render a smaller image or "
                                        "fewer layers or rays" +
                                        (shadow_layers > 0 ? std::string(", or lower Settings.shadow_map_size") : ""));
    }
    // Outputs a pass of the chain reads from the previous frame of a sequence live as History.
    for (const RenderPass* p : chain)
        for (const auto& h : p->history_inputs(s))
            for (auto& d : descs)
                if (d.name == h && d.lifetime == Lifetime::Frame) d.lifetime = Lifetime::History;
    return {std::move(descs), needed, sized_by};
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

}  // namespace ssr
