#include "render/auto_choice.h"

#include <stdexcept>

namespace ssr {

void check_choice(const std::string& what, const std::string& value, const std::vector<std::string>& choices) {
    std::string known;
    for (size_t i = 0; i < choices.size(); ++i) {
        if (choices[i] == value) return;
        known += std::string(i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + "'" + choices[i] + "'";
    }
    throw std::invalid_argument(what + " must be " + known + ", got '" + value + "'");
}

void decide_auto(RenderSettings& s, const std::string& field, const std::string& device) {
    check_choice("device", device, {"cpu", "gpu"});
    const bool cpu = device == "cpu";
    if (field == "skip") {
        // llvmpipe shades every pixel it is given, so listing the pixels that need rays pays; a
        // GPU ran skip off faster at every reflective share (docs/guide/skip.md).
        s.skip = cpu;
    } else if (field == "deep_gbuffer") {
        s.deep_gbuffer = choose_deep_gbuffer({});  // no renderer, no scene: nothing measured
    } else {
        throw std::invalid_argument("Settings." + field + " takes no 'auto'");
    }
}

std::vector<DeepGBuffer> deep_gbuffer_candidates(bool cpu_device, int layers) {
    // On the CPU device the visibility constructions' compute pass costs what peeling's shading
    // pass does or more (benchmarks/timing/deep_gbuffer.py): measuring them would let noise choose between
    // images that differ in their last bits. One layer on it is peeled without measuring; one layer
    // on a GPU compares peeling with the visibility buffer only (the lists' one geometry pass is
    // what one layer already is, plus a selection).
    if (cpu_device) {
        if (layers == 1) return {DeepGBuffer::Peel};
        return {DeepGBuffer::Peel, DeepGBuffer::Lists};
    }
    if (layers == 1) return {DeepGBuffer::Peel, DeepGBuffer::Visibility};
    return {DeepGBuffer::Peel, DeepGBuffer::Lists, DeepGBuffer::Visibility, DeepGBuffer::VisibilityLists};
}

DeepGBuffer choose_deep_gbuffer(const std::vector<std::pair<DeepGBuffer, Spread>>& measured) {
    if (measured.empty()) return DeepGBuffer::Peel;
    const std::pair<DeepGBuffer, Spread>* best = &measured.front();
    const Spread* peel = nullptr;
    for (const auto& m : measured) {
        if (m.second.median < best->second.median) best = &m;
        if (m.first == DeepGBuffer::Peel) peel = &m.second;
    }
    if (best->first != DeepGBuffer::Peel && peel && best->second.max >= peel->min) return DeepGBuffer::Peel;
    return best->first;
}

const std::vector<std::string> kReadbackPaths = {"auto", "download", "staged"};
const std::vector<std::string> kClearPaths = {"auto", "gl", "compute"};
const std::vector<std::string> kVisibilityTiles = {"auto", "on", "off"};
const std::vector<std::string> kInputFetches = {"auto", "imageLoad", "texelFetch"};

// On llvmpipe the copy pass the staged path starts with was most of a readback; a GPU copies by
// DMA into pinned memory (benchmarks/timing/readback.py times both).
bool auto_readback_staged(bool cpu_device) { return !cpu_device; }
// A GPU built for compute has few raster units, and its GL clears ran far below its memory
// bandwidth (benchmarks/timing/peel_profile.py); the CPU device keeps GL's clears.
bool auto_clear_by_compute(bool cpu_device) { return !cpu_device; }
// llvmpipe shades every pixel a dispatch covers; a GPU is not stalled to read the tiles back.
bool auto_visibility_tiles(bool cpu_device) { return cpu_device; }
// llvmpipe's texelFetch of a float format is a call to a generic sampling function
// (lib/input_fetch.glsl); GPUs keep texelFetch, the path measured there.
bool auto_fetch_by_image(bool cpu_device, bool images_enough) { return cpu_device && images_enough; }

}  // namespace ssr
