// The deep G-buffer's textures as every construction declares them (depth peeling, the
// visibility buffer's attribute pass): one format and one meaning of each channel, written once
// for the passes that write them and for Frame's views (frame.gbuffer). The layout follows the
// thesis's per-layer G-buffer (seed 000, 2.2), extended with metallic-roughness; the shaders'
// side is lib/gbuffer.glsl.
#pragma once

#include "render/render_pass.h"

namespace ssr {

// gbuffer.albedo, gbuffer.normal and gbuffer.material of s.layers layers, then what the scene's
// facts add: gbuffer.emission (an emissive texture), gbuffer.specular (a specular texture) and
// gbuffer.motion (motion vectors, or a pass that reprojects).
std::vector<ResourceDesc> gbuffer_attribute_textures(const RenderSettings& s, const FrameFacts& f);
// The attributes every frame has, whatever its facts (the first three above).
std::vector<ResourceDesc> gbuffer_base_textures(const RenderSettings& s);
// gbuffer.depth: the window depth of each layer in `format` (a depth format where rasterised
// into, R32F where stored by compute).
ResourceDesc gbuffer_depth_texture(const RenderSettings& s, GLenum format);
// linear_depth and lit, as the lighting pass writes them for every layer.
ResourceDesc linear_depth_texture(const RenderSettings& s);
ResourceDesc lit_texture(const RenderSettings& s);

}  // namespace ssr
