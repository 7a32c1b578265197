#include "render/settings.h"

#include <cmath>
#include <stdexcept>

namespace ssr {

namespace {
void check(bool ok, const std::string& msg) {
    if (!ok) throw std::invalid_argument(msg);
}
}  // namespace

void RenderSettings::validate() const {
    check(width >= 1 && width <= 16384, "Settings.width must be in [1, 16384] pixels, got " + std::to_string(width));
    check(height >= 1 && height <= 16384, "Settings.height must be in [1, 16384] pixels, got " + std::to_string(height));
    check(layers >= 1 && layers <= 16, "Settings.layers must be in [1, 16], got " + std::to_string(layers));
    check(shadow_map_size == 0 || (shadow_map_size >= 16 && shadow_map_size <= 16384),
          "Settings.shadow_map_size must be 0 (off) or in [16, 16384], got " + std::to_string(shadow_map_size));
    check(std::isfinite(shadow_normal_offset) && shadow_normal_offset >= 0.0f,
          "Settings.shadow_normal_offset must be finite and >= 0");
    check(shadow_pcf_radius >= 0 && shadow_pcf_radius <= 4,
          "Settings.shadow_pcf_radius must be in [0, 4], got " + std::to_string(shadow_pcf_radius));
}

}  // namespace ssr
