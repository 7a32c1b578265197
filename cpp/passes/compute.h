// Small helpers shared by the compute passes.
#pragma once

#include <cctype>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/gl_resources.h"
#include "render/render_pass.h"

namespace ssr {

// Binds every layer of `tex` (level `level`) as image unit `unit`.
inline void bind_image_layered(GLuint unit, const Texture& tex, GLenum access, int level = 0) {
    glBindImageTexture(unit, tex.id(), level, tex.target() == GL_TEXTURE_2D_ARRAY ? GL_TRUE : GL_FALSE, 0, access,
                       tex.format());
}

// A buffer texture over `buffer` read as `format` (an image buffer, FETCH_BY_IMAGE: llvmpipe reads
// one inline where a storage-buffer read at a per-invocation address loops over the lanes);
// deleted with the object.
struct BufferView {
    GLuint id = 0;
    BufferView(const Buffer& buffer, GLenum format) {
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &id);
        glTextureBuffer(id, format, buffer.id());
    }
    ~BufferView() { glDeleteTextures(1, &id); }
    BufferView(const BufferView&) = delete;
    BufferView& operator=(const BufferView&) = delete;
};

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

// The image format qualifier of a format a clear by image stores can write ("" for one it
// cannot: depth, sRGB and integer formats).
inline const char* clear_format_qualifier(GLenum format) {
    if (format == GL_RGBA8) return "rgba8";
    return image_format_qualifier(format);
}

// Gives layers [from, from + count) (count < 0: to the last) of every level of the array `tex` the
// value a pass writes for an empty layer (`value`: as many floats as the format has channels), by a
// clear instead of a dispatch, so a skipped layer reads exactly as if the pass had run on it. By
// image stores where FrameContext::clear_by_compute says so (shaders/passes/clear_layers.comp),
// else by glClearTexSubImage.
constexpr GLuint kClearImageUnit = 0;
inline void clear_layers(FrameContext& ctx, Texture& tex, int from, const float* value, int count = -1) {
    const int layers = tex.layers();
    if (count < 0) count = layers - from;
    count = std::min(count, layers - from);
    if (from >= layers || count <= 0) return;
    const int channels = tex.format() == GL_R32F || tex.format() == GL_R16F   ? 1
                         : tex.format() == GL_RG32F || tex.format() == GL_RG16F ? 2
                                                                                 : 4;
    const char* qualifier = clear_format_qualifier(tex.format());
    const bool array = tex.target() == GL_TEXTURE_2D_ARRAY;
    if (ctx.clear_by_compute && *qualifier && (array || tex.target() == GL_TEXTURE_2D)) {
        Defines d;
        d["IMAGE_FORMAT"] = qualifier;
        d["IMAGE_ARRAY"] = array ? "1" : "0";
        // Its one image by name (as NamedUnits names it), at kClearImageUnit.
        d["IMAGE_TARGET"] = std::to_string(kClearImageUnit);
        const GLuint prog = ctx.shaders.program({"passes/clear_layers.comp"}, d);
        glUseProgram(prog);
        float v[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // absent channels are not stored
        for (int c = 0; c < channels; ++c) v[c] = value[c];
        glUniform4fv(glGetUniformLocation(prog, "u_value"), 1, v);
        glUniform1i(glGetUniformLocation(prog, "u_first"), from);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
        for (int level = 0; level < tex.levels(); ++level) {
            const int w = std::max(tex.width() >> level, 1), h = std::max(tex.height() >> level, 1);
            glUniform2i(glGetUniformLocation(prog, "u_size"), w, h);
            glBindImageTexture(kClearImageUnit, tex.id(), level, array ? GL_TRUE : GL_FALSE, 0, GL_WRITE_ONLY, tex.format());
            glDispatchCompute(GLuint((w + 7) / 8), GLuint((h + 7) / 8), GLuint(count));
        }
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                        GL_TEXTURE_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
        return;
    }
    const GLenum fmt = channels == 1 ? GL_RED : channels == 2 ? GL_RG : GL_RGBA;
    for (int level = 0; level < tex.levels(); ++level)
        glClearTexSubImage(tex.id(), level, 0, 0, from, std::max(tex.width() >> level, 1),
                           std::max(tex.height() >> level, 1), count, fmt, GL_FLOAT, value);
}

// Gives `count` uints of `buffer` from uint `first` the value `value`: by stores
// (shaders/passes/clear_buffer.comp) where FrameContext::clear_by_compute says so, else by
// glClearNamedBufferSubData. Storage binding kClearBufferBinding (which no other shader declares) is
// left bound to `buffer`.
constexpr GLuint kClearBufferBinding = kClearTargetBinding;
inline void clear_uints(FrameContext& ctx, const Buffer& buffer, size_t first, size_t count, GLuint value) {
    if (count == 0) return;
    if (!ctx.clear_by_compute) {
        glClearNamedBufferSubData(buffer.id(), GL_R32UI, GLintptr(sizeof(GLuint) * first),
                                  GLsizeiptr(sizeof(GLuint) * count), GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
        return;
    }
    const GLuint prog = ctx.shaders.program({"passes/clear_buffer.comp"}, {});
    glUseProgram(prog);
    glUniform1ui(glGetUniformLocation(prog, "u_first"), GLuint(first));
    glUniform1ui(glGetUniformLocation(prog, "u_count"), GLuint(count));
    glUniform1ui(glGetUniformLocation(prog, "u_value"), value);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kClearBufferBinding, buffer.id());
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    const size_t groups = (count + 255) / 256, row = 65535;
    glDispatchCompute(GLuint(std::min(groups, row)), GLuint((groups + row - 1) / row), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

// The texture units bound for the whole frame by what owns them rather than by a pass: the
// specular-albedo table (render/device_tools.cpp) and the environment map (render/render_loop.cpp).
// Every NamedUnits gives its shader their defines and numbers its own textures around them.
inline const std::vector<std::pair<std::string, GLuint>>& frame_texture_units() {
    static const std::vector<std::pair<std::string, GLuint>> units = {{"specular_albedo", 13}, {"environment_map", 15}};
    return units;
}
inline GLuint frame_texture_unit(const std::string& name) {
    for (const auto& u : frame_texture_units())
        if (u.first == name) return u.second;
    throw std::invalid_argument("no frame-wide texture unit named '" + name + "'");
}

bool is_sampler_type(GLenum type);
bool is_image_type(GLenum type);

// Holds the linked program `prog` (built from `shader`) against the units its pass bound by name:
// an active sampler or image uniform at a unit outside `texture_units` / `image_units` would read
// whatever an earlier pass left there, so it throws a ShaderError naming the shader, the uniform
// and its unit. Checked once per program (the answer is cached by program id and shader).
void check_bound_units(GLuint prog, const std::string& shader, const std::vector<GLuint>& texture_units,
                       const std::vector<GLuint>& image_units);

// Textures and images bound by name, their units written once. A pass lists the textures its
// shader samples and the images it stores to; bind_by_name binds texture i to the i-th free
// texture unit and image i to the i-th free image unit (free: not a frame-wide unit nor one in
// placed_textures / placed_images), and add_unit_defines gives the shader the same units as
// defines, TEXTURE_<NAME> and IMAGE_<NAME> (the name upper-cased, '.' as '_': gbuffer.normal is
// TEXTURE_GBUFFER_NORMAL), which it declares its samplers and images at:
//     layout(binding = TEXTURE_GBUFFER_NORMAL) uniform sampler2DArray u_normal;
// No unit is written in the shader, and a name the shader asks for that the pass does not bind
// fails to compile, naming it. A name may be bound to a texture that is not a frame resource
// (a previous frame's, the pass's own) through `own`. Placed units are bound by what owns the
// resource (the scene's material textures, the shadow maps): their names get defines and count
// as bound, and bind_by_name leaves them alone.
struct NamedUnits {
    std::vector<std::string> textures;
    std::vector<std::pair<std::string, GLenum>> images;  // name, access (GL_WRITE_ONLY, ...)
    std::vector<std::pair<std::string, GLuint>> placed_textures = {};
    std::vector<std::pair<std::string, GLuint>> placed_images = {};
    std::vector<std::pair<std::string, const Texture*>> own = {};

    static std::string define(const char* prefix, const std::string& name) {
        std::string d = prefix;
        for (char c : name) d += c == '.' ? '_' : char(std::toupper(static_cast<unsigned char>(c)));
        return d;
    }
    // FETCH_BY_IMAGE (lib/input_fetch.glsl): the inputs `names` read by imageLoad, bound as
    // read-only images of their own format (IMAGE_<NAME>), where `by_image` says so.
    NamedUnits& fetch(bool by_image, const std::vector<std::string>& names) {
        if (by_image)
            for (const auto& n : names) images.emplace_back(n, GL_READ_ONLY);
        return *this;
    }
    GLuint texture_unit(size_t i) const { return nth_free(i, placed_textures, true); }
    GLuint image_unit(size_t i) const { return nth_free(i, placed_images, false); }
    // The unit bind_by_name binds `name` to (a pass rebinding it between dispatches).
    GLuint texture_unit(const std::string& name) const {
        for (size_t i = 0; i < textures.size(); ++i)
            if (textures[i] == name) return texture_unit(i);
        throw std::invalid_argument("no texture named '" + name + "' in the pass's units");
    }
    GLuint image_unit(const std::string& name) const {
        for (size_t i = 0; i < images.size(); ++i)
            if (images[i].first == name) return image_unit(i);
        throw std::invalid_argument("no image named '" + name + "' in the pass's units");
    }
    void add_unit_defines(Defines& d) const {
        for (const auto& u : frame_texture_units()) d[define("TEXTURE_", u.first)] = std::to_string(u.second);
        for (const auto& u : placed_textures) d[define("TEXTURE_", u.first)] = std::to_string(u.second);
        for (const auto& u : placed_images) d[define("IMAGE_", u.first)] = std::to_string(u.second);
        for (size_t i = 0; i < textures.size(); ++i) d[define("TEXTURE_", textures[i])] = std::to_string(texture_unit(i));
        for (size_t i = 0; i < images.size(); ++i) d[define("IMAGE_", images[i].first)] = std::to_string(image_unit(i));
    }
    const Texture& get(const FrameResources& r, const std::string& name) const {
        for (const auto& o : own)
            if (o.first == name) return *o.second;
        return r.get(name);
    }
    void bind_by_name(const FrameResources& r) const {
        for (size_t i = 0; i < textures.size(); ++i) glBindTextureUnit(texture_unit(i), get(r, textures[i]).id());
        for (size_t i = 0; i < images.size(); ++i)
            bind_image_layered(image_unit(i), get(r, images[i].first), images[i].second);
    }
    // bind_by_name, then the program's check against what is bound (check_bound_units).
    void bind_by_name(const FrameResources& r, GLuint prog, const std::string& shader) const {
        bind_by_name(r);
        check(prog, shader);
    }
    void check(GLuint prog, const std::string& shader) const {
        std::vector<GLuint> t, im;
        for (const auto& u : frame_texture_units()) t.push_back(u.second);
        for (const auto& u : placed_textures) t.push_back(u.second);
        for (const auto& u : placed_images) im.push_back(u.second);
        for (size_t i = 0; i < textures.size(); ++i) t.push_back(texture_unit(i));
        for (size_t i = 0; i < images.size(); ++i) im.push_back(image_unit(i));
        check_bound_units(prog, shader, t, im);
    }

   private:
    static GLuint nth_free(size_t i, const std::vector<std::pair<std::string, GLuint>>& placed, bool texture) {
        for (GLuint unit = 0;; ++unit) {
            bool taken = false;
            for (const auto& p : placed) taken = taken || p.second == unit;
            if (texture)
                for (const auto& f : frame_texture_units()) taken = taken || f.second == unit;
            if (!taken && i-- == 0) return unit;
        }
    }
};

// What every pass that generates or traces reflection rays binds, by name: the layer-0 G-buffer
// a ray is generated from and the per-ray outputs rays.hit, rays.sample, rays.direction
// (lib/trace_common.glsl).
inline NamedUnits ray_generation_units() {
    return NamedUnits{{"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"},
                      {{"rays.hit", GL_WRITE_ONLY}, {"rays.sample", GL_WRITE_ONLY}, {"rays.direction", GL_WRITE_ONLY}}};
}

}  // namespace ssr
