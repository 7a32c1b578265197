// Owning wrappers for GL objects: a texture, buffer or framebuffer is deleted with its
// wrapper. They are move-only; the context that created them must be current when they die
// (the Renderer guarantees it by keeping its context alive longer than every target set).
#pragma once

#include <cstddef>
#include <string>
#include <utility>

#include "core/gl.h"

namespace ssr {

class Texture {
public:
    Texture() = default;
    ~Texture() { reset(); }
    Texture(Texture&& o) noexcept { *this = std::move(o); }
    Texture& operator=(Texture&& o) noexcept;
    Texture(const Texture&) = delete;
    Texture& operator=(const Texture&) = delete;

    // Immutable storage (glTextureStorage*): levels = 0 means a full mip chain.
    static Texture create_2d(GLenum internal_format, int width, int height, int levels = 1);
    static Texture create_2d_array(GLenum internal_format, int width, int height, int layers, int levels = 1);
    // A cube-map array of `cubes` cubes (6 x cubes layer-faces; layers() counts the layer-faces).
    static Texture create_cube_array(GLenum internal_format, int size, int cubes, int levels = 1);
    // A view of a cube-map array's layer-faces as a 2D array (6 per cube, GL's face order), with
    // its own sampling state: for reading it back.
    static Texture view_as_2d_array(const Texture& cube_array);

    GLuint id() const { return id_; }
    GLenum target() const { return target_; }
    GLenum format() const { return format_; }
    int width() const { return width_; }
    int height() const { return height_; }
    int layers() const { return layers_; }
    int levels() const { return levels_; }
    explicit operator bool() const { return id_ != 0; }

    void set_filter(GLenum min_filter, GLenum mag_filter);
    void set_wrap(GLenum wrap_s, GLenum wrap_t);
    void reset();

private:
    GLuint id_ = 0;
    GLenum target_ = 0, format_ = 0;
    int width_ = 0, height_ = 0, layers_ = 1, levels_ = 1;
};

class Buffer {
public:
    Buffer() = default;
    ~Buffer() { reset(); }
    Buffer(Buffer&& o) noexcept { *this = std::move(o); }
    Buffer& operator=(Buffer&& o) noexcept;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;

    // Storage of `bytes` bytes, initialised from `data` when given; upload() may rewrite it.
    static Buffer create(size_t bytes, const void* data = nullptr);
    // Storage in client memory, mapped for reading for its whole life (persistent, coherent): a
    // copy into it is a DMA transfer the CPU reads once a fence has passed, without the driver's
    // own staging copy of glGet*SubData.
    static Buffer create_readable(size_t bytes);
    void upload(const void* data, size_t bytes, size_t offset = 0);
    const void* mapped() const { return map_; }

    GLuint id() const { return id_; }
    size_t size() const { return size_; }
    explicit operator bool() const { return id_ != 0; }
    void reset();

private:
    GLuint id_ = 0;
    size_t size_ = 0;
    void* map_ = nullptr;
};

class Framebuffer {
public:
    Framebuffer() = default;
    ~Framebuffer() { reset(); }
    Framebuffer(Framebuffer&& o) noexcept { *this = std::move(o); }
    Framebuffer& operator=(Framebuffer&& o) noexcept;
    Framebuffer(const Framebuffer&) = delete;
    Framebuffer& operator=(const Framebuffer&) = delete;

    static Framebuffer create();
    GLuint id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    // Attaches one layer (or the whole level, layer < 0) of a texture.
    void attach(GLenum attachment, const Texture& tex, int level = 0, int layer = -1);
    // Raises GLError naming `what` when the framebuffer is incomplete.
    void check_complete(const char* what) const;
    void reset();

private:
    GLuint id_ = 0;
};

// Bytes per texel of the sized internal formats used by the renderer (for readback sizes).
int texel_components(GLenum internal_format);
std::string format_name(GLenum internal_format);

}  // namespace ssr
