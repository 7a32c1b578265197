// Reading glTF into a Scene: the file and its GLB container are checked (gltf_checks.cpp), tinygltf
// parses what the checks let through, and the model is read section by section in the order
// below (gltf_reader.h names the file of each); every value is checked again where it is used.

#include "scene/gltf_io.h"

#include <tiny_gltf.h>

#include <cstring>
#include <filesystem>
#include <new>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string_view>

#include "core/errors.h"
#include "scene/gltf_internal.h"
#include "scene/gltf_reader.h"

namespace fs = std::filesystem;

namespace ssr {

using namespace gltf_detail;

namespace {

int load_gltf_checked(Scene& scene, const std::string& path, const glm::mat4& transform, const GltfLoadOptions& options,
                      std::vector<std::string>& warnings) {
    if (!fs::exists(path)) throw FileNotFound("glTF file not found: " + path);
    if (fs::is_directory(path)) throw SceneError(path + ": is a folder, not a glTF file");
    const std::vector<uint8_t> bytes = read_regular_file(path, path);

    PathPolicy pol;
    pol.file = path;
    pol.dir = fs::absolute(fs::path(path)).parent_path();
    std::error_code ec;
    pol.dir_real = fs::canonical(pol.dir, ec);
    if (ec) throw SceneError(path + ": cannot resolve the model's folder: " + ec.message());
    pol.allow_external = options.allow_external_files;
    const std::string base_dir = pol.dir.string();

    // GLB: a 12-byte header, a JSON chunk, an optional BIN chunk; every length checked in 64 bits.
    const bool glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    std::string_view json_text;
    uint64_t glb_length = 0, glb_bin = 0;
    if (glb) {
        if (bytes.size() < 20) throw SceneError(path + ": GLB file is shorter than its 20-byte header");
        const uint32_t version = read_u32(bytes.data() + 4);
        if (version != 2) throw SceneError(path + ": GLB version " + std::to_string(version) + " is not 2");
        glb_length = read_u32(bytes.data() + 8);
        if (glb_length > bytes.size() || glb_length < 20)
            throw SceneError(path + ": GLB header says " + std::to_string(glb_length) + " bytes, the file has " +
                             std::to_string(bytes.size()));
        const uint64_t json_len = read_u32(bytes.data() + 12);
        if (read_u32(bytes.data() + 16) != 0x4E4F534Au) throw SceneError(path + ": GLB's first chunk is not JSON");
        if (20 + json_len > glb_length)
            throw SceneError(path + ": GLB JSON chunk (" + std::to_string(json_len) + " bytes) runs past the file's end");
        json_text = std::string_view(reinterpret_cast<const char*>(bytes.data()) + 20, size_t(json_len));
        const uint64_t bin_at = 20 + json_len;
        if (bin_at + 8 <= glb_length) {
            const uint64_t bin_len = read_u32(bytes.data() + bin_at);
            if (read_u32(bytes.data() + bin_at + 4) != 0x004E4942u)
                throw SceneError(path + ": GLB's second chunk is not BIN");
            if (bin_at + 8 + bin_len > glb_length)
                throw SceneError(path + ": GLB BIN chunk (" + std::to_string(bin_len) + " bytes) runs past the file's end");
            glb_bin = bin_len;
        }
    } else {
        if (fs::path(path).extension() == ".glb")
            throw SceneError(path + ": not a GLB file (it does not start with the magic 'glTF')");
        json_text = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    }
    if (const std::string problem = check_json_text(json_text); !problem.empty())
        throw SceneError(path + ": " + problem);
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(json_text.begin(), json_text.end());
    } catch (const nlohmann::json::exception& e) {
        throw SceneError(path + ": not valid JSON: " + e.what());
    }
    FsContext fsctx;
    precheck_json(j, pol, base_dir, glb, glb_bin, &fsctx);

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decode_with_oiio, nullptr);
    loader.SetFsCallbacks(tinygltf::FsCallbacks{fs_exists, fs_expand, fs_read, fs_write, &fsctx});
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(glb_length), base_dir)
                        : loader.LoadASCIIFromString(&model, &err, &warn, json_text.data(), unsigned(json_text.size()), base_dir);
    if (!ok) {
        std::string msg = err.empty() ? warn : err;
        while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
        throw SceneError(path + ": not a valid glTF 2.0 file: " + (msg.empty() ? "unknown error" : msg));
    }
    GltfReader r(model, path);
    // The numbers of every sampler, camera, light and material, each checked against glTF's
    // ranges (and the lighting buffers' capacity) before anything is built from them.
    check_samplers(model, r);
    check_cameras(model, r, warnings, path);
    check_lights(model, r);
    check_materials(model, r);

    if (!model.skins.empty())
        warnings.push_back(path + ": " + std::to_string(model.skins.size()) +
                           " skin(s) ignored: skinned meshes are drawn in their bind pose");
    {
        // Extensions the file uses that change what it looks like but ssrlab does not implement:
        // named together, so a user knows what the image leaves out (required ones failed above).
        std::string ignored;
        for (const std::string& name : model.extensionsUsed)
            if (!implemented_extensions().count(name)) ignored += (ignored.empty() ? "" : ", ") + name;
        if (!ignored.empty())
            warnings.push_back(path + ": extensions not rendered (ignored): " + ignored);
    }

    const int image_base = read_images(model, r, scene, path, err, warn);
    const int material_base = read_materials(model, r, scene, image_base, path, warnings);
    PrimitiveReader primitive{model, r, scene, material_base, path, warnings};
    const int first_object = int(scene.objects.size());
    const std::vector<int> scene_node = read_nodes(model, r, scene, transform, primitive, path, warnings);
    if (!model.animations.empty()) read_animations(model, r, scene, scene_node, path, warnings);
    read_scene_extras(model, r, scene, pol, path);
    fit_infinite_far_plane(scene, r);
    if (int(scene.objects.size()) == first_object)
        warnings.push_back(path + ": no triangles were loaded (the file's default scene has nothing ssrlab can draw)");
    if (scene.name == "scene") scene.name = fs::path(path).stem().string();
    scene.touch();
    return first_object;
}

}  // namespace

int load_gltf(Scene& scene, const std::string& path, const glm::mat4& transform, const GltfLoadOptions& options,
              std::vector<std::string>* warnings) {
    std::vector<std::string> local;
    try {
        const int first = load_gltf_checked(scene, path, transform, options, local);
        if (warnings)
            for (auto& w : local) warnings->push_back(printable(w));
        return first;
    } catch (const FileNotFound& e) {
        throw FileNotFound(printable(e.what()));
    } catch (const SceneError& e) {
        throw SceneError(printable(e.what()));
    } catch (const std::bad_alloc&) {
        throw SceneError(printable(path) + ": out of memory while loading (the file's sizes are too large)");
    } catch (const std::length_error& e) {
        throw SceneError(printable(path) + ": a size in the file is too large (" + printable(e.what()) + ")");
    } catch (const std::invalid_argument& e) {
        throw SceneError(printable(path) + ": " + printable(e.what()));
    } catch (const std::out_of_range& e) {
        throw SceneError(printable(path) + ": " + printable(e.what()));
    } catch (const fs::filesystem_error& e) {
        throw SceneError(printable(path) + ": " + printable(e.what()));
    }
}

}  // namespace ssr
