// Small helpers shared by the compute passes.
#pragma once

#include <algorithm>

#include "core/gl_resources.h"
#include "render/render_pass.h"

namespace ssr {

// Binds every layer of `tex` (level `level`) as image unit `unit`.
inline void bind_image_layered(GLuint unit, const Texture& tex, GLenum access, int level = 0) {
    glBindImageTexture(unit, tex.id(), level, tex.target() == GL_TEXTURE_2D_ARRAY ? GL_TRUE : GL_FALSE, 0, access,
                       tex.format());
}

// FETCH_BY_IMAGE (lib/input_fetch.glsl): binds the inputs `names` as read-only images of
// their own format, every layer of level 0, to image units first, first + 1, ... (after the pass's
// outputs), where the device reads float textures faster by imageLoad than by texelFetch.
inline void bind_input_images(const FrameResources& r, GLuint first, const std::vector<std::string>& names) {
    for (GLuint i = 0; i < GLuint(names.size()); ++i) bind_image_layered(first + i, r.get(names[i]), GL_READ_ONLY);
}

// The GLSL image format qualifier of a float texture format (a FETCH_BY_IMAGE input whose format
// depends on the chain, e.g. the composite's direct light: lit RGBA16F, the reference's RGBA32F).
inline const char* image_format_qualifier(GLenum format) {
    switch (format) {
        case GL_RGBA32F: return "rgba32f";
        case GL_RGBA16F: return "rgba16f";
        case GL_RG32F: return "rg32f";
        case GL_RG16F: return "rg16f";
        case GL_R32F: return "r32f";
        case GL_R16F: return "r16f";
        default: return "";
    }
}

// Dispatches ceil(width/gx) x ceil(height/gy) x depth work groups and makes the writes
// visible to every later fetch, image load and readback.
inline void dispatch_2d(int width, int height, int depth, int gx, int gy) {
    glDispatchCompute(GLuint((width + gx - 1) / gx), GLuint((height + gy - 1) / gy), GLuint(depth));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

// Gives layers [from, layers) of every level of the array `tex` the value a pass
// writes for an empty layer (`value`: as many floats as the format has channels), by a clear
// instead of a dispatch, so a skipped layer reads exactly as if the pass had run on it.
inline void clear_layers(Texture& tex, int from, const float* value) {
    if (from >= tex.layers()) return;
    const GLenum fmt = tex.format() == GL_R32F || tex.format() == GL_R16F   ? GL_RED
                       : tex.format() == GL_RG32F || tex.format() == GL_RG16F ? GL_RG
                                                                              : GL_RGBA;
    for (int level = 0; level < tex.levels(); ++level)
        glClearTexSubImage(tex.id(), level, 0, 0, from, std::max(tex.width() >> level, 1),
                           std::max(tex.height() >> level, 1), tex.layers() - from, fmt, GL_FLOAT, value);
}

// Binds a pass's declared inputs to texture units 0, 1, ... in the order it lists them (the
// order its shader declares its samplers in).
inline void bind_inputs_in_order(const FrameResources& r, const std::vector<std::string>& names) {
    for (GLuint unit = 0; unit < GLuint(names.size()); ++unit) glBindTextureUnit(unit, r.get(names[unit]).id());
}

// What every pass that generates or traces reflection rays binds: the layer-0 G-buffer a ray
// is generated from (texture units 0-3, lib/ray_generation.glsl) and the per-ray outputs
// rays.hit, rays.sample, rays.direction (image units 0-2).
inline void bind_ray_generation_io(FrameResources& r) {
    glBindTextureUnit(0, r.get("linear_depth").id());
    glBindTextureUnit(1, r.get("gbuffer.albedo").id());
    glBindTextureUnit(2, r.get("gbuffer.normal").id());
    glBindTextureUnit(3, r.get("gbuffer.material").id());
    bind_image_layered(0, r.get("rays.hit"), GL_WRITE_ONLY);
    bind_image_layered(1, r.get("rays.sample"), GL_WRITE_ONLY);
    bind_image_layered(2, r.get("rays.direction"), GL_WRITE_ONLY);
}

}  // namespace ssr
