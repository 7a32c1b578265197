#include "core/gl_resources.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/errors.h"

namespace ssr {

namespace {
int full_mip_count(int w, int h) {
    return 1 + int(std::floor(std::log2(double(std::max(std::max(w, h), 1)))));
}
}  // namespace

Texture& Texture::operator=(Texture&& o) noexcept {
    if (this != &o) {
        reset();
        std::swap(id_, o.id_);
        target_ = o.target_;
        format_ = o.format_;
        width_ = o.width_;
        height_ = o.height_;
        layers_ = o.layers_;
        levels_ = o.levels_;
    }
    return *this;
}

Texture Texture::create_2d(GLenum fmt, int w, int h, int levels) {
    Texture t;
    t.target_ = GL_TEXTURE_2D;
    t.format_ = fmt;
    t.width_ = w;
    t.height_ = h;
    t.levels_ = levels > 0 ? levels : full_mip_count(w, h);
    glCreateTextures(GL_TEXTURE_2D, 1, &t.id_);
    glTextureStorage2D(t.id_, t.levels_, fmt, w, h);
    t.set_filter(t.levels_ > 1 ? GL_NEAREST_MIPMAP_NEAREST : GL_NEAREST, GL_NEAREST);
    t.set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    return t;
}

Texture Texture::create_2d_array(GLenum fmt, int w, int h, int layers, int levels) {
    Texture t;
    t.target_ = GL_TEXTURE_2D_ARRAY;
    t.format_ = fmt;
    t.width_ = w;
    t.height_ = h;
    t.layers_ = layers;
    t.levels_ = levels > 0 ? levels : full_mip_count(w, h);
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &t.id_);
    glTextureStorage3D(t.id_, t.levels_, fmt, w, h, layers);
    t.set_filter(t.levels_ > 1 ? GL_NEAREST_MIPMAP_NEAREST : GL_NEAREST, GL_NEAREST);
    t.set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    return t;
}

Texture Texture::create_cube_array(GLenum fmt, int size, int cubes, int levels) {
    Texture t;
    t.target_ = GL_TEXTURE_CUBE_MAP_ARRAY;
    t.format_ = fmt;
    t.width_ = size;
    t.height_ = size;
    t.layers_ = 6 * cubes;
    t.levels_ = levels > 0 ? levels : full_mip_count(size, size);
    glCreateTextures(GL_TEXTURE_CUBE_MAP_ARRAY, 1, &t.id_);
    glTextureStorage3D(t.id_, t.levels_, fmt, size, size, 6 * cubes);
    t.set_filter(t.levels_ > 1 ? GL_NEAREST_MIPMAP_NEAREST : GL_NEAREST, GL_NEAREST);
    t.set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    return t;
}

Texture Texture::view_as_2d_array(const Texture& cube_array) {
    Texture t;
    t.target_ = GL_TEXTURE_2D_ARRAY;
    t.format_ = cube_array.format_;
    t.width_ = cube_array.width_;
    t.height_ = cube_array.height_;
    t.layers_ = cube_array.layers_;
    t.levels_ = cube_array.levels_;
    glGenTextures(1, &t.id_);  // a view's name must not have a target yet (glCreateTextures gives one)
    glTextureView(t.id_, GL_TEXTURE_2D_ARRAY, cube_array.id_, cube_array.format_, 0, t.levels_, 0, t.layers_);
    t.set_filter(GL_NEAREST, GL_NEAREST);
    return t;
}

void Texture::set_filter(GLenum min_filter, GLenum mag_filter) {
    glTextureParameteri(id_, GL_TEXTURE_MIN_FILTER, GLint(min_filter));
    glTextureParameteri(id_, GL_TEXTURE_MAG_FILTER, GLint(mag_filter));
}

void Texture::set_wrap(GLenum s, GLenum t) {
    glTextureParameteri(id_, GL_TEXTURE_WRAP_S, GLint(s));
    glTextureParameteri(id_, GL_TEXTURE_WRAP_T, GLint(t));
}

void Texture::reset() {
    if (id_) glDeleteTextures(1, &id_);
    id_ = 0;
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
    if (this != &o) {
        reset();
        std::swap(id_, o.id_);
        size_ = o.size_;
        std::swap(map_, o.map_);
    }
    return *this;
}

Buffer Buffer::create_readable(size_t bytes) {
    Buffer b;
    b.size_ = std::max<size_t>(bytes, 16);
    const GLbitfield flags = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
    glCreateBuffers(1, &b.id_);
    glNamedBufferStorage(b.id_, GLsizeiptr(b.size_), nullptr, flags | GL_CLIENT_STORAGE_BIT);
    b.map_ = glMapNamedBufferRange(b.id_, 0, GLsizeiptr(b.size_), flags);
    if (!b.map_) throw GLError("could not map a readback buffer of " + std::to_string(b.size_) + " bytes");
    return b;
}

Buffer Buffer::create(size_t bytes, const void* data) {
    Buffer b;
    b.size_ = std::max<size_t>(bytes, 16);  // zero-sized storage is an error in GL
    glCreateBuffers(1, &b.id_);
    glNamedBufferStorage(b.id_, GLsizeiptr(b.size_), nullptr, GL_DYNAMIC_STORAGE_BIT);
    if (data && bytes) glNamedBufferSubData(b.id_, 0, GLsizeiptr(bytes), data);
    return b;
}

void Buffer::upload(const void* data, size_t bytes, size_t offset) {
    glNamedBufferSubData(id_, GLintptr(offset), GLsizeiptr(bytes), data);
}

void Buffer::reset() {
    if (id_) glDeleteBuffers(1, &id_);  // unmaps a mapped buffer
    id_ = 0;
    size_ = 0;
    map_ = nullptr;
}

Framebuffer& Framebuffer::operator=(Framebuffer&& o) noexcept {
    if (this != &o) {
        reset();
        std::swap(id_, o.id_);
    }
    return *this;
}

Framebuffer Framebuffer::create() {
    Framebuffer f;
    glCreateFramebuffers(1, &f.id_);
    return f;
}

void Framebuffer::attach(GLenum attachment, const Texture& tex, int level, int layer) {
    if (layer >= 0) glNamedFramebufferTextureLayer(id_, attachment, tex.id(), level, layer);
    else glNamedFramebufferTexture(id_, attachment, tex.id(), level);
}

void Framebuffer::check_complete(const char* what) const {
    const GLenum status = glCheckNamedFramebufferStatus(id_, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        std::ostringstream os;
        os << "framebuffer of " << what << " is incomplete (status 0x" << std::hex << status << ")";
        throw GLError(os.str());
    }
}

void Framebuffer::reset() {
    if (id_) glDeleteFramebuffers(1, &id_);
    id_ = 0;
}

int texel_components(GLenum f) {
    switch (f) {
        case GL_R8: case GL_R16F: case GL_R32F: case GL_R32UI: case GL_DEPTH_COMPONENT32F: return 1;
        case GL_RG8: case GL_RG16F: case GL_RG32F: case GL_RG32UI: return 2;
        case GL_RGB8: case GL_RGB16F: case GL_RGB32F: return 3;
        default: return 4;
    }
}

std::string format_name(GLenum f) {
    switch (f) {
        case GL_R8: return "R8";
        case GL_R32F: return "R32F";
        case GL_R32UI: return "R32UI";
        case GL_RG32F: return "RG32F";
        case GL_RGBA8: return "RGBA8";
        case GL_SRGB8_ALPHA8: return "SRGB8_ALPHA8";
        case GL_RGBA16F: return "RGBA16F";
        case GL_RGBA32F: return "RGBA32F";
        case GL_DEPTH_COMPONENT32F: return "DEPTH32F";
        default: return "format 0x" + std::to_string(f);
    }
}

}  // namespace ssr
