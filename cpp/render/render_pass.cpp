#include "render/render_pass.h"

#include <algorithm>

#include "core/errors.h"

namespace ssr {

Texture& FrameResources::get(const std::string& name) {
    auto it = textures_.find(name);
    if (it == textures_.end()) throw GLError("frame has no texture '" + name + "'");
    return it->second;
}

const Texture& FrameResources::get(const std::string& name) const {
    auto it = textures_.find(name);
    if (it == textures_.end()) throw GLError("frame has no texture '" + name + "'");
    return it->second;
}

void FrameResources::allocate(const std::vector<ResourceDesc>& descs) {
    descs_ = descs;
    textures_.clear();
    for (const auto& d : descs) {
        Texture t = d.layers > 0 ? Texture::create_2d_array(d.format, d.width, d.height, d.layers, d.levels)
                                 : Texture::create_2d(d.format, d.width, d.height, d.levels);
        textures_.emplace(d.name, std::move(t));
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
        Texture t = d.layers > 0 ? Texture::create_2d_array(d.format, d.width, d.height, d.layers, d.levels)
                                 : Texture::create_2d(d.format, d.width, d.height, d.levels);
        textures_.emplace(d.name, std::move(t));
    }
}

}  // namespace ssr
