// The pass registry and the chain's order. A built-in pass registers itself with one line in its
// own C++ file,
//
//     SSR_REGISTER_PASS(TraceHizPass());
//
// and the renderer makes one instance of every registered pass. No list names the passes and
// no index orders them: a frame's chain is the passes that say they run (RenderPass::runs), put
// in the order their declarations give (order_chain): a pass after the writer of every texture
// and buffer it reads, a pass that rewrites a texture (RenderPass::rewrites) after its writer
// and before the readers it does not itself depend on. Passes the declarations leave unordered
// run in the order of their names, so the order depends on nothing but the declarations.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/render_pass.h"

namespace ssr {

using PassFactory = std::function<std::unique_ptr<RenderPass>()>;

// Adds a factory to the registry (at static initialisation; SSR_REGISTER_PASS); returns true.
bool register_pass_factory(PassFactory make);
// One new instance of every registered pass (no GL object is made before a pass executes).
std::vector<std::unique_ptr<RenderPass>> make_registered_passes();

// What a pass declares in one frame, as the ordering reads it.
struct PassDeclaration {
    std::vector<std::string> reads, writes, rewrites, buffer_reads, buffer_writes;
};
PassDeclaration declaration(const RenderPass& p, const RenderSettings& s, const FrameFacts& f);

// `passes` in the order their declarations give (`declared(i)` is passes[i]'s). Throws
// std::invalid_argument naming both passes when two write the same texture or buffer, or when
// the declarations form a cycle. `reverse_ties`: unordered passes in reverse name order instead
// (a check that no order between them is left undeclared: the images must not change).
// `alternatives`: the declarations are a union over settings (the registry's order), where
// passes that never run together write the same texture (the resolve, cone and blur_mips).
std::vector<RenderPass*> order_chain(const std::vector<RenderPass*>& passes,
                                     const std::function<PassDeclaration(size_t)>& declared, bool reverse_ties,
                                     bool alternatives = false);

// Whether unordered passes run in reverse name order ($SSRLAB_CHAIN_TIES=reverse): the
// golden-frame tests render both ways to show that the declarations alone order the chain.
bool reverse_chain_ties();

// The facts of a frame of `scene` with settings `s` that choose its chain (FrameFacts), from the
// scene itself: no GL context and no upload (Renderer::chain, ssrlab.chain.derive).
FrameFacts scene_facts(const Scene& scene, const RenderSettings& s, bool fetch_by_image);
// The same from what a scene copy keeps of them (GpuScene): its bounds and whether some material
// reflects, has an emissive texture, has a specular texture.
FrameFacts frame_facts(const Scene& scene, const Bounds& bounds, bool reflective, bool emission_texture,
                       bool specular_texture, const RenderSettings& s, bool fetch_by_image);

}  // namespace ssr

#define SSR_REGISTER_PASS_JOIN2(a, b) a##b
#define SSR_REGISTER_PASS_JOIN(a, b) SSR_REGISTER_PASS_JOIN2(a, b)
// Registers a built-in pass: `...` constructs it (a class name and its constructor's arguments).
#define SSR_REGISTER_PASS(...)                                                                      \
    namespace {                                                                                     \
    const bool SSR_REGISTER_PASS_JOIN(ssr_registered_pass_, __LINE__) = ::ssr::register_pass_factory( \
        [] { return std::unique_ptr<::ssr::RenderPass>(new __VA_ARGS__); });                         \
    }
