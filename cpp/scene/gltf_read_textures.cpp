// Images, samplers and textures (glTF 2.0, texture data, KHR_texture_transform).

#include <filesystem>

#include "scene/gltf_reader.h"
#include "scene/image_io.h"

namespace ssr::gltf_detail {

namespace fs = std::filesystem;

bool decode_with_oiio(tinygltf::Image* image, const int index, std::string* err, std::string* /*warn*/,
                      int, int, const unsigned char* bytes, int size, void*) {
    try {
        std::string hint = image->mimeType;
        if (hint.empty() && !image->uri.empty()) hint = fs::path(image->uri).extension().string();
        const std::string what =
            "image " + std::to_string(index) + (image->uri.empty() ? "" : " ('" + image->uri + "')");
        if (size <= 0) throw SceneError(what + ": image data is empty");
        Image img = decode_image_memory(bytes, size_t(size), hint, what);
        image->width = img.width;
        image->height = img.height;
        image->component = 4;
        image->bits = 8;
        image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
        image->image = std::move(img.rgba);
        return true;
    } catch (const std::exception& e) {
        if (err) *err += std::string(e.what()) + "\n";
        return false;
    }
}

void check_samplers(const tinygltf::Model& model, const GltfReader& r) {
    static const std::set<int> wraps{10497, 33071, 33648};
    static const std::set<int> mag_filters{-1, 9728, 9729};
    static const std::set<int> min_filters{-1, 9728, 9729, 9984, 9985, 9986, 9987};
    for (size_t i = 0; i < model.samplers.size(); ++i) {
        const auto& s = model.samplers[i];
        const std::string what = "sampler " + std::to_string(i);
        if (!wraps.count(s.wrapS)) r.fail(what + ": wrapS " + std::to_string(s.wrapS) + " is not a glTF wrap mode (33071, 33648, 10497)");
        if (!wraps.count(s.wrapT)) r.fail(what + ": wrapT " + std::to_string(s.wrapT) + " is not a glTF wrap mode (33071, 33648, 10497)");
        if (!mag_filters.count(s.magFilter)) r.fail(what + ": magFilter " + std::to_string(s.magFilter) + " is not a glTF filter");
        if (!min_filters.count(s.minFilter)) r.fail(what + ": minFilter " + std::to_string(s.minFilter) + " is not a glTF filter");
    }
}

int read_images(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const std::string& path,
                const std::string& err, const std::string& warn) {
    // Images: tinygltf keeps going when an external image is missing; we do not.
    const int image_base = int(scene.images.size());
    for (size_t i = 0; i < model.images.size(); ++i) {
        const auto& gi = model.images[i];
        if (gi.image.empty()) {
            std::string where = gi.uri.empty() ? "bufferView " + std::to_string(gi.bufferView) : "'" + gi.uri + "'";
            std::string detail = warn.empty() ? err : warn;
            while (!detail.empty() && (detail.back() == '\n' || detail.back() == ' ')) detail.pop_back();
            r.fail("image " + std::to_string(i) + " " + where + " could not be loaded" +
                   (detail.empty() ? "" : ": " + detail));
        }
        Image img;
        img.name = gi.name.empty() ? (gi.uri.empty() ? "image" + std::to_string(i) : fs::path(gi.uri).stem().string()) : gi.name;
        img.source = gi.uri.empty() ? path + "#image" + std::to_string(i) : (fs::path(path).parent_path() / gi.uri).string();
        img.width = gi.width;
        img.height = gi.height;
        img.rgba = gi.image;
        scene.images.push_back(std::move(img));
    }
    return image_base;
}

TextureRef texture_ref(const tinygltf::Model& model, int texture_index, int texcoord, int image_base,
                       const GltfReader& r, const std::string& what, const tinygltf::ExtensionMap& extensions) {
    TextureRef ref;
    if (texture_index < 0) return ref;
    // KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, as its specification
    // writes the matrices (rotation counter-clockwise in uv space), and an optional texCoord.
    if (auto it = extensions.find("KHR_texture_transform"); it != extensions.end()) {
        const std::string ext = what + ": KHR_texture_transform";
        const tinygltf::Value& v = it->second;
        glm::vec2 offset(0.0f), scale(1.0f);
        float rotation = 0.0f;
        auto vec2_of = [&](const char* key, glm::vec2 fallback) {
            if (!v.Has(key)) return fallback;
            const tinygltf::Value& a = v.Get(key);
            if (!a.IsArray() || a.ArrayLen() != 2) r.fail(ext + "." + key + " must be an array of 2 numbers");
            glm::vec2 out;
            for (int i = 0; i < 2; ++i) {
                const tinygltf::Value& x = a.Get(i);
                if (!x.IsNumber() && !x.IsInt()) r.fail(ext + "." + key + " must be an array of 2 numbers");
                const double d = x.GetNumberAsDouble();
                if (!in_range(d, -1e6, 1e6)) r.fail(ext + "." + key + " holds " + num(d) + ", outside [-1e6, 1e6]");
                out[i] = float(d);
            }
            return out;
        };
        offset = vec2_of("offset", offset);
        scale = vec2_of("scale", scale);
        if (v.Has("rotation")) rotation = float(number_from_value(v.Get("rotation"), r, ext + ".rotation", -1e6, 1e6));
        if (v.Has("texCoord")) texcoord = int(number_from_value(v.Get("texCoord"), r, ext + ".texCoord", 0, 7));
        const float c = std::cos(rotation), s = std::sin(rotation);
        ref.transform_u = glm::vec3(c * scale.x, s * scale.y, offset.x);
        ref.transform_v = glm::vec3(-s * scale.x, c * scale.y, offset.y);
    }
    if (texture_index >= int(model.textures.size()))
        r.fail(what + ": texture index " + std::to_string(texture_index) + " is out of range (the file has " +
               std::to_string(model.textures.size()) + " textures)");
    if (texcoord < 0 || texcoord > 7) r.fail(what + ": texCoord " + std::to_string(texcoord) + " is not a valid set");
    const auto& tex = model.textures[size_t(texture_index)];
    if (tex.source < 0 || tex.source >= int(model.images.size()))
        r.fail("texture " + std::to_string(texture_index) + ": image index " + std::to_string(tex.source) +
               " is out of range (the file has " + std::to_string(model.images.size()) + " images)");
    ref.image = image_base + tex.source;
    ref.texcoord = texcoord;
    if (tex.sampler >= int(model.samplers.size()) || tex.sampler < -1)
        r.fail("texture " + std::to_string(texture_index) + ": sampler index " + std::to_string(tex.sampler) +
               " is out of range (the file has " + std::to_string(model.samplers.size()) + " samplers)");
    if (tex.sampler >= 0) {
        ref.wrap_s = model.samplers[size_t(tex.sampler)].wrapS;
        ref.wrap_t = model.samplers[size_t(tex.sampler)].wrapT;
    }
    return ref;
}

}  // namespace ssr::gltf_detail
