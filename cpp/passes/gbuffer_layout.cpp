#include "passes/gbuffer_layout.h"

namespace ssr {

namespace {
using D = ChannelDecode;
}

std::vector<ResourceDesc> gbuffer_base_textures(const RenderSettings& s) {
    const int w = s.width, h = s.height, l = s.layers;
    return {
        ResourceDesc{"gbuffer.albedo", GL_SRGB8_ALPHA8, w, h, l, 1}.with({
            {"gbuffer", "albedo", 0, 3, D::Value, "linear base colour"},
            {"gbuffer", "metallic", 3, 1, D::Value, "metalness in [0, 1]"},
        }),
        ResourceDesc{"gbuffer.normal", GL_RGBA16F, w, h, l, 1}.with({
            {"gbuffer", "normal", 0, 3, D::Value, "view-space unit normal (x right, y up, z toward the camera)"},
            {"gbuffer", "roughness", 3, 1, D::Value, "perceptual roughness (GGX alpha = roughness**2)"},
        }),
        ResourceDesc{"gbuffer.material", GL_RGBA8, w, h, l, 1}.with({
            {"gbuffer", "reflectivity", 0, 1, D::Value, "the material's reflectivity in [0, 1]"},
            {"gbuffer", "coverage", 1, 1, D::Flag, "True where the layer holds a surface"},
            {"gbuffer", "object_id", 2, 2, D::ByteIdMinusOne, "index of the scene object the layer shows, -1 where none"},
        }),
    };
}

std::vector<ResourceDesc> gbuffer_attribute_textures(const RenderSettings& s, const FrameFacts& f) {
    std::vector<ResourceDesc> out = gbuffer_base_textures(s);
    const int w = s.width, h = s.height, l = s.layers;
    if (f.emission_texture)
        out.push_back(ResourceDesc{"gbuffer.emission", GL_RGBA16F, w, h, l, 1}.with(
            {{"gbuffer", "emission", 0, 3, D::Value, "emitted radiance where the scene has an emissive texture"}}));
    // F0 in half floats: 2^-11 relative (an 8-bit unorm would round 0.04 to 10/255, 2 % off, and
    // 0.01 by 18 %; sRGB8 still by 1-3 %), so a texel's F0 reaches the lighting as computed.
    if (f.specular_texture)
        out.push_back(ResourceDesc{"gbuffer.specular", GL_RGBA16F, w, h, l, 1}.with(
            {{"gbuffer", "specular_f0", 0, 3, D::Value, "a dielectric's F0 where the scene has a specular texture"}}));
    // Motion in pixels (lib/motion.glsl): float32, as a half float holds 0.01 px only below 16 px.
    if (writes_motion(s, f))
        out.push_back(ResourceDesc{"gbuffer.motion", GL_RG32F, w, h, l, 1}.with(
            {{"gbuffer", "motion", 0, 2, D::WindowVector,
              "where each sample was in the previous frame of the sequence minus where it is, in pixels "
              "(x right, y down: previous (row, col) = (row + motion[..., 1], col + motion[..., 0])); 0 outside "
              "a sequence and where nothing moved"}}));
    return out;
}

ResourceDesc gbuffer_depth_texture(const RenderSettings& s, GLenum format) {
    return ResourceDesc{"gbuffer.depth", format, s.width, s.height, s.layers, 1}.with(
        {{"gbuffer", "window_depth", 0, 1, D::Value, "the stored depth-buffer value, in the frame's depth convention"}});
}

ResourceDesc linear_depth_texture(const RenderSettings& s) {
    return ResourceDesc{"linear_depth", GL_R32F, s.width, s.height, s.layers, 1}.with(
        {{"gbuffer", "depth", 0, 1, D::Value,
          "positive view-space depth (distance along the view axis); the far-plane distance where a layer "
          "covers nothing"}});
}

ResourceDesc lit_texture(const RenderSettings& s) {
    return ResourceDesc{"lit", GL_RGBA16F, s.width, s.height, s.layers, 1}.with(
        {{"gbuffer", "lit", 0, 3, D::Value, "direct lighting of every layer (the colour a reflection ray fetches)"}});
}

}  // namespace ssr
