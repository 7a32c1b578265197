#include "passes/classify.h"

#include "render/pass_registry.h"

#include "passes/resolve.h"
#include "passes/trace_pass.h"

#include <cstdint>

#include "passes/compute.h"
#include "passes/resolve.h"

namespace ssr {

namespace {
constexpr size_t kHeaderUints = 8;  // shaders/lib/ray_list.glsl
constexpr int kBlock = 4;  // pixels per invocation along x and y (classify.comp's CLASSIFY_BLOCK)
}

void ClassifyPass::bind_list() const { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBinding, list_.id()); }

void ClassifyPass::publish_list(FrameContext& ctx, const std::string& name) const {
    // The trace dispatches over the list. NVIDIA's driver (580, H100) dropped a dispatch's writes
    // to the buffer it read its indirect arguments from, from that buffer's second frame on (the
    // trace then added its counters to this header: Frame.stats read 0, the images were right),
    // so the arguments are a copy of the header's first three words.
    constexpr size_t kArgs = 3 * sizeof(uint32_t);
    if (!dispatch_args_) dispatch_args_ = Buffer::create(kArgs);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);  // this pass's atomics, before the copy
    glCopyNamedBufferSubData(list_.id(), dispatch_args_.id(), 0, 0, GLsizeiptr(kArgs));
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT);  // the copy, before a dispatch reads it
    ctx.buffers.publish(name, FrameBuffer{&list_, kBinding, &dispatch_args_, 0});
}

void ClassifyPass::reset_list(int w, int h, int rays, bool per_ray) {
    const size_t entries = size_t(w) * size_t(h) * (per_ray ? 2 * size_t(rays) : 1);
    const size_t bytes = (kHeaderUints + entries) * sizeof(uint32_t);
    if (list_.size() < bytes) list_ = Buffer::create(bytes);
    per_ray_ = per_ray;
    // A fresh header each frame: no groups, no rows of groups yet, a group layer per ray (one
    // layer when every entry is a ray).
    const uint32_t header[kHeaderUints] = {0, 0, per_ray ? 1u : uint32_t(rays), 0, 0, 0, 0, 0};
    list_.upload(header, sizeof(header));
}

void ClassifyPass::reset_resolve_list(int width, int height, bool pixels) {
    const size_t tiles = size_t((width + 15) / 16) * size_t((height + 15) / 16);
    const size_t capacity = pixels ? size_t(width) * size_t(height) : tiles;
    const size_t bytes = (kHeaderUints + capacity + (pixels ? 0 : tiles)) * sizeof(uint32_t);
    if (resolve_list_.size() < bytes) resolve_list_ = Buffer::create(bytes);
    const uint32_t header[kHeaderUints] = {0, 0, 1, 0, 0, uint32_t(capacity), 0, 0};
    resolve_list_.upload(header, sizeof(header));
    if (!pixels) {  // the tiles' flags: none listed yet
        const uint32_t zero = 0;
        glClearNamedBufferSubData(resolve_list_.id(), GL_R32UI, (kHeaderUints + capacity) * sizeof(uint32_t),
                                  tiles * sizeof(uint32_t), GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    }
    resolve_pixels_ = pixels;
}

std::vector<ResourceDesc> ClassifyPass::outputs(const RenderSettings& s) const {
    // The skipped pixels' rays are cleared in rays.sample alone (its traced flag 0): their hit and
    // direction are declared undefined there rather than cleared, which would cost a full-screen
    // pass over two of the three ray textures.
    std::vector<ResourceDesc> out{TracePass::ray_texture("rays.hit", s), TracePass::ray_texture("rays.sample", s),
                                  TracePass::ray_texture("rays.direction", s)};
    for (int i : {0, 2}) out[i].defined_by = "rays.sample", out[i].defined_component = 3;
    if (resolves_over_lists(s)) out.push_back(ResolvePass::reflection_texture(s));
    return out;
}

void ClassifyPass::execute(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    const int w = s.trace_width(), h = s.trace_height();
    reset_list(w, h, s.traced_rays(), per_ray(s));
    resolve_lists_ = resolves_over_lists(s);
    if (resolve_lists_) reset_resolve_list(s.width, s.height, ResolvePass::own_rays_only(s));

    auto& r = ctx.resources;
    // "No ray" is all zeros (lib/trace_common.glsl): one clear per frame, here so that the
    // pass's timing holds it (llvmpipe clears on the calling thread, between this pass's
    // timestamps), and the shader writes the listed pixels only. Only rays.sample is cleared:
    // every reader of rays.hit and rays.direction tests the slot's weight or traced flag first
    // (a third of the bytes: the clear was most of this pass at 0 % reflective);
    // Frame.read zeroes the other two where the flag is 0, so they read as with skip off.
    {
        GpuScope t(ctx.timer, "classify.clear");  // a part of this pass's interval, shown apart
        const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        clear_layers(ctx, r.get("rays.sample"), 0, zero);
        if (resolve_lists_) {
            // What a non-receiver reflects where the resolve will not run: nothing (alpha 1, as
            // the resolve writes it); the rough reflective pixels' environment is the shader's.
            const float none[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            clear_layers(ctx, r.get("reflection"), 0, none);
        }
    }

    Defines d = ctx.defines;
    d["RAY_LIST_PER_RAY"] = per_ray(s) ? "1" : "0";
    d["CLASSIFY_FACING"] = std::to_string(s.classify_facing);
    d["ADAPTIVE_RAYS"] = s.adaptive_rays ? "1" : "0";
    d["RESOLVE_LISTS"] = resolve_lists_ ? "1" : "0";
    d["RESOLVE_LIST_PIXELS"] = resolve_lists_ && resolve_pixels_ ? "1" : "0";
    d["CLASSIFY_BLOCK"] = std::to_string(kBlock);
    // The peeling's list of the 32x32 regions where layer 0 holds a reflective surface (the
    // group's footprint): the groups run over those only (at 0 % reflective the
    // invocations over the whole image were most of the pass).
    const FrameBuffer& tiles = ctx.buffers.get("covered_tiles");
    regions_ = tiles.data;
    regions_offset_ = DepthPeelPass::classify_regions_offset(s);
    NamedUnits units = ray_generation_units();
    if (resolve_lists_) units.images.emplace_back("reflection", GL_WRITE_ONLY);
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({"passes/classify.comp"}, d);
    glUseProgram(prog);
    glUniform1i(glGetUniformLocation(prog, "u_rays"), s.traced_rays());
    units.bind_by_name(r, prog, "passes/classify.comp");
    if (resolve_lists_) {
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kResolveBinding, resolve_list_.id());
    }
    tiles.bind();
    bind_list();
    // One invocation per block of kBlock x kBlock full-resolution pixels (receivers are
    // full-resolution pixels; a trace pixel is examined at its origin pixel). llvmpipe pays a
    // fixed cost per invocation even for one that returns at once, and its texelFetch of the
    // RGBA8 material costs ~25 ns (2 shared cores, 320x180: an 8x8-group dispatch of one
    // invocation per pixel measured 2-4 ms with nothing else to do); blocks of 4x4 pixels
    // that first gather their reflectivity 2x2 at a time measured 0.25-0.45 ms, and a block's
    // list entries take one atomic.
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, regions_->id());
    glDispatchComputeIndirect(GLintptr(regions_offset_));
    glMemoryBarrier(GL_COMMAND_BARRIER_BIT);  // the trace's and the resolve's indirect arguments
    publish_list(ctx, "ray_list");
    if (resolve_lists_)
        ctx.buffers.publish("resolve_list", FrameBuffer{&resolve_list_, kResolveBinding, &resolve_list_, 0});
}

std::map<std::string, double> ClassifyPass::counters() const {
    uint32_t header[kHeaderUints] = {};
    if (!list_) return {};
    // GL makes the shaders' atomics visible to glGetBufferSubData only after this barrier
    // (llvmpipe finishes every dispatch first; a GPU need not).
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(list_.id(), 0, sizeof(header), header);
    std::map<std::string, double> c = {{"pixels_classified", double(header[6])},
                                       {"pixels_traced", double(per_ray_ ? header[7] : header[3])},
                                       {"trace_groups", double(header[0]) * header[1] * header[2]}};
    // rays_traced and depth_fetches: Frame.stats sums them from rays.sample when asked (the trace
    // keeps no counters: shaders/passes/trace_hiz.comp).
    if (regions_) {
        uint32_t regions = 0;
        glGetNamedBufferSubData(regions_->id(), GLintptr(regions_offset_), sizeof(regions), &regions);
        c["classify_regions"] = double(regions);
    }
    if (resolve_lists_ && resolve_list_) {
        uint32_t rh[kHeaderUints] = {};  // shaders/lib/resolve_list.glsl
        glGetNamedBufferSubData(resolve_list_.id(), 0, sizeof(rh), rh);
        c[resolve_pixels_ ? "resolve_pixels" : "resolve_tiles"] = double(rh[3]);
        c["resolve_groups"] = double(rh[0]) * rh[1] * rh[2];
        c["environment_pixels"] = double(rh[4]);
    }
    return c;
}

SSR_REGISTER_PASS(ClassifyPass());

}  // namespace ssr
