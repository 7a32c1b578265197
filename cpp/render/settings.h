// The native mirror of ssrlab.Settings (python/ssrlab/settings.py holds the documentation,
// units, defaults and validation users see). validate() repeats the range checks so that
// the C++ core never runs on values that would hang or crash a pass.
#pragma once

#include <string>

#include "render/depth_convention.h"

namespace ssr {

struct RenderSettings {
    // Image
    int width = 640;   // pixels
    int height = 360;  // pixels

    // Deep G-buffer (seed 000, 1.5.1 and 2.2)
    int layers = 1;                 // depth-peeled layers, 1..16
    bool backface_culling = false;  // off as in the thesis: back faces fill deeper layers
    DepthMode depth_mode = DepthMode::Standard;

    // Direct lighting
    int shadow_map_size = 2048;         // texels per side; 0 turns shadows off
    float shadow_normal_offset = 1.5f;  // receiver offset along its normal, in shadow-map texels
    int shadow_pcf_radius = 1;          // PCF kernel (2r+1)^2 hardware-filtered taps

    void validate() const;  // throws std::invalid_argument naming the field
};

}  // namespace ssr
