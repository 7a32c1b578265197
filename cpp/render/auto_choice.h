// Every 'auto' ssrlab takes, decided here and nowhere else: the settings flagged kAuto in
// settings_fields.def (ssrlab.Settings.resolved() asks decide_auto, a Renderer's measurement asks
// deep_gbuffer_candidates and choose_deep_gbuffer) and the Renderer's own options (readback_path,
// clear_path, visibility_tiles, input_fetch). The option names are checked here too (check_choice),
// so that Python and C++ callers read one message. `cpu_device`: Mesa's llvmpipe.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "render/settings.h"

namespace ssr {

// Throws std::invalid_argument "<what> must be 'a', 'b' or 'c', got 'value'" unless `value` is one of `choices`.
void check_choice(const std::string& what, const std::string& value, const std::vector<std::string>& choices);

// Sets the kAuto setting `field` of `s` to what 'auto' is on `device` ('cpu' or 'gpu'; anything
// else is refused by name): skip classifies on the CPU device only, deep_gbuffer peels where no
// renderer has measured the constructions (see choose_deep_gbuffer).
void decide_auto(RenderSettings& s, const std::string& field, const std::string& device);

// The constructions deep_gbuffer 'auto' measures on a renderer for `layers` layers; a single one
// is taken without measuring.
std::vector<DeepGBuffer> deep_gbuffer_candidates(bool cpu_device, int layers);
// GPU milliseconds of one construction's repeats.
struct Spread {
    double median = 0, min = 0, max = 0;
};
// The construction 'auto' takes from its measurements: the smallest median, unless its [min, max]
// overlaps peeling's, the reference's (a difference within the spread decides nothing); peeling
// where nothing was measured.
DeepGBuffer choose_deep_gbuffer(const std::vector<std::pair<DeepGBuffer, Spread>>& measured);

// The Renderer's options (renderer.h says what each path does).
extern const std::vector<std::string> kReadbackPaths, kClearPaths, kVisibilityTiles, kInputFetches;
bool auto_readback_staged(bool cpu_device);
bool auto_clear_by_compute(bool cpu_device);
bool auto_visibility_tiles(bool cpu_device);
bool auto_fetch_by_image(bool cpu_device, bool images_enough);

}  // namespace ssr
