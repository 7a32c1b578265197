// fragment_lists: the deep G-buffer in one geometry pass (Settings.deep_gbuffer "lists"; Yang et
// al. 2010's per-pixel linked lists, the one-pass deep G-buffer the thesis names as the way out of
// peeling's cost, seed 000 1.5 and 4.2). It shares depth peeling's shading pass and writes the same
// textures (passes/gbuffer_layout.h), bit for bit the peeled layers: the shading pass appends every
// fragment's encoded outputs to its pixel's list, a compute pass keeps each pixel's nearest
// `layers` distinct depths by peeling's rules, one full-screen draw per layer writes them. Timed
// as fragment_lists.append, .select and .write (and .redo where the store grew). A frame whose
// fragments exceed Settings.deep_gbuffer_budget is peeled instead, never truncated, under this
// pass's name (fragment_lists.layer<i>; Frame.stats deep_gbuffer_fell_back = 1).
#pragma once

#include "passes/depth_peel.h"

namespace ssr {

class FragmentListsPass : public DepthPeelPass {
public:
    std::string name() const override { return "fragment_lists"; }
    bool runs(const RenderSettings& s, const FrameFacts&) const override {
        return s.deep_gbuffer == DeepGBuffer::Lists;
    }
};

}  // namespace ssr
