#include "render/render_pass.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/errors.h"

namespace ssr {

size_t texture_bytes(const ResourceDesc& d) {
    size_t texel = 16;
    switch (d.format) {
        case GL_R8: texel = 1; break;
        case GL_R32F: case GL_R32UI: case GL_DEPTH_COMPONENT32F: case GL_RGBA8: case GL_SRGB8_ALPHA8: case GL_RG16F: texel = 4; break;
        case GL_RG32F: case GL_RGBA16F: texel = 8; break;
        default: texel = 16; break;  // RGBA32F and anything wider: an upper bound
    }
    const int levels = d.levels > 0 ? d.levels : 1 + int(std::floor(std::log2(double(std::max({d.width, d.height, 1})))));
    size_t texels = 0;
    for (int l = 0; l < levels; ++l) texels += size_t(std::max(d.width >> l, 1)) * size_t(std::max(d.height >> l, 1));
    return texels * size_t(std::max(d.layers, 1)) * texel;
}

size_t FrameResources::bytes() const {
    size_t total = 0;
    for (const auto& d : descs_) total += texture_bytes(d);
    return total;
}

void FrameResources::check_declared(const std::string& name) const {
    if (declared_ && !declared_->count(name))
        throw GLError("pass " + *pass_ + " uses the texture '" + name +
                      "', which it does not declare (RenderPass::inputs, rewrites or outputs)");
}

Texture& FrameResources::get(const std::string& name) {
    check_declared(name);
    auto it = textures_.find(name);
    if (it != textures_.end()) return it->second;
    if (scratch_ && scratch_->has(name)) return scratch_->get(name);
    throw GLError("frame has no texture '" + name + "'");
}

const Texture& FrameResources::get(const std::string& name) const {
    check_declared(name);
    auto it = textures_.find(name);
    if (it != textures_.end()) return it->second;
    if (scratch_ && scratch_->has(name)) return static_cast<const FrameResources*>(scratch_)->get(name);
    throw GLError("frame has no texture '" + name + "'");
}

void FrameBuffer::bind() const {
    if (data) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, data->id());
    if (args) glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, args->id());
}

const FrameBuffer& FrameBuffers::get(const std::string& name) const {
    auto it = buffers_.find(name);
    if (it == buffers_.end()) throw GLError("no pass of this frame published the buffer '" + name + "'");
    return it->second;
}

const char* decode_name(ChannelDecode d) {
    switch (d) {
        case ChannelDecode::Value: return "value";
        case ChannelDecode::Flag: return "flag";
        case ChannelDecode::Integer: return "integer";
        case ChannelDecode::ByteIdMinusOne: return "byte_id_minus_one";
        case ChannelDecode::WindowPoint: return "window_point";
        case ChannelDecode::WindowVector: return "window_vector";
    }
    return "value";
}

namespace {
std::atomic<uint64_t> texture_generations{1};

Texture create_texture(const ResourceDesc& d) {
    if (d.cube) return Texture::create_cube_array(d.format, d.width, d.layers / 6, d.levels);
    return d.layers > 0 ? Texture::create_2d_array(d.format, d.width, d.height, d.layers, d.levels)
                        : Texture::create_2d(d.format, d.width, d.height, d.levels);
}
}  // namespace

void FrameResources::allocate(const std::vector<ResourceDesc>& descs) {
    descs_ = descs;
    textures_.clear();
    generations_.clear();
    for (const auto& d : descs) {
        Texture t = create_texture(d);
        textures_.emplace(d.name, std::move(t));
        generations_[d.name] = texture_generations++;
    }
}

void FrameResources::add(const std::vector<ResourceDesc>& descs) {
    for (const auto& d : descs) {
        auto same = std::find_if(descs_.begin(), descs_.end(), [&](const ResourceDesc& x) { return x == d; });
        if (same != descs_.end()) continue;  // already there with this shape
        descs_.erase(std::remove_if(descs_.begin(), descs_.end(), [&](const ResourceDesc& x) { return x.name == d.name; }),
                     descs_.end());
        textures_.erase(d.name);
        descs_.push_back(d);
        Texture t = create_texture(d);
        textures_.emplace(d.name, std::move(t));
        generations_[d.name] = texture_generations++;
    }
}

uint64_t FrameResources::generation(const std::string& name) const {
    auto it = generations_.find(name);
    if (it != generations_.end() && textures_.count(name)) return it->second;
    if (scratch_ && scratch_->has(name)) return scratch_->generation(name);
    return 0;
}

}  // namespace ssr
