// Meshes (glTF 2.0, geometry): a primitive's attributes and indices as an ssr::Mesh.
// Primitives that are not triangles are skipped with a warning (points and lines have no
// surface to reflect); a triangle primitive without POSITION, or with non-integer indices,
// is a broken file and an error.

#include "scene/gltf_reader.h"

namespace ssr::gltf_detail {

namespace {

// Turns strips and fans into a triangle list.
std::vector<uint32_t> to_triangle_list(const std::vector<uint32_t>& idx, int mode) {
    if (mode == kModeTriangles) return idx;
    std::vector<uint32_t> out;
    for (size_t i = 2; i < idx.size(); ++i) {
        if (mode == kModeStrip) {
            if (i % 2 == 0) out.insert(out.end(), {idx[i - 2], idx[i - 1], idx[i]});
            else out.insert(out.end(), {idx[i - 1], idx[i - 2], idx[i]});
        } else {  // fan
            out.insert(out.end(), {idx[0], idx[i - 1], idx[i]});
        }
    }
    return out;
}

}  // namespace

std::pair<int, int> PrimitiveReader::operator()(int mesh_index, int prim_index) {
    static const char* kModeNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
    auto key = std::make_pair(mesh_index, prim_index);
    if (auto it = primitive_cache.find(key); it != primitive_cache.end()) return it->second;
    const auto& gmesh = model.meshes[size_t(mesh_index)];
    const auto& prim = gmesh.primitives[size_t(prim_index)];
    const std::string what = "mesh " + std::to_string(mesh_index) + " ('" + gmesh.name + "') primitive " +
                             std::to_string(prim_index);
    std::pair<int, int> result{-1, -1};
    if (prim.mode != kModeTriangles && prim.mode != kModeStrip && prim.mode != kModeFan && prim.mode != -1) {
        warnings.push_back(path + ": " + what + ": " +
                           (prim.mode >= 0 && prim.mode < 4
                                ? std::string("mode ") + kModeNames[prim.mode] + " skipped (only triangles are rendered)"
                                : "mode " + std::to_string(prim.mode) + " is not a glTF primitive mode; skipped"));
        primitive_cache[key] = result;
        return result;
    }
    if (!prim.targets.empty())
        warnings.push_back(path + ": " + what + ": " + std::to_string(prim.targets.size()) +
                           " morph target(s) ignored (drawn with base positions)");
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) r.fail(what + ": no POSITION attribute");
    Mesh mesh;
    mesh.name = (gmesh.name.empty() ? "mesh" + std::to_string(mesh_index) : gmesh.name) +
                (gmesh.primitives.size() > 1 ? "/" + std::to_string(prim_index) : "");
    mesh.positions = r.read_floats<3>(pos->second, what + " POSITION");
    if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end())
        mesh.normals = r.read_floats<3>(it->second, what + " NORMAL");
    if (auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end())
        mesh.uvs = r.read_floats<2>(it->second, what + " TEXCOORD_0");
    if (auto it = prim.attributes.find("TANGENT"); it != prim.attributes.end())
        mesh.tangents = r.read_floats<4>(it->second, what + " TANGENT");
    if (auto it = prim.attributes.find("TEXCOORD_1"); it != prim.attributes.end())
        mesh.uvs1 = r.read_floats<2>(it->second, what + " TEXCOORD_1");
    if (auto it = prim.attributes.find("COLOR_0"); it != prim.attributes.end())
        mesh.colors = r.read_colors(it->second, what + " COLOR_0");
    for (const auto* attr : {&mesh.normals})
        if (!attr->empty() && attr->size() != mesh.positions.size())
            r.fail(what + ": NORMAL has " + std::to_string(attr->size()) + " values for " +
                   std::to_string(mesh.positions.size()) + " positions");
    if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size())
        r.fail(what + ": TEXCOORD_0 has " + std::to_string(mesh.uvs.size()) + " values for " +
               std::to_string(mesh.positions.size()) + " positions");
    if (!mesh.tangents.empty() && mesh.tangents.size() != mesh.positions.size())
        r.fail(what + ": TANGENT has " + std::to_string(mesh.tangents.size()) + " values for " +
               std::to_string(mesh.positions.size()) + " positions");
    if (!mesh.uvs1.empty() && mesh.uvs1.size() != mesh.positions.size())
        r.fail(what + ": TEXCOORD_1 has " + std::to_string(mesh.uvs1.size()) + " values for " +
               std::to_string(mesh.positions.size()) + " positions");
    if (!mesh.colors.empty() && mesh.colors.size() != mesh.positions.size())
        r.fail(what + ": COLOR_0 has " + std::to_string(mesh.colors.size()) + " values for " +
               std::to_string(mesh.positions.size()) + " positions");
    std::vector<uint32_t> idx;
    if (prim.indices >= 0) {
        idx = r.read_indices(prim.indices, what + " indices");
    } else {
        idx.resize(mesh.positions.size());
        for (size_t i = 0; i < idx.size(); ++i) idx[i] = uint32_t(i);
    }
    mesh.indices = to_triangle_list(idx, prim.mode == -1 ? kModeTriangles : prim.mode);
    if (mesh.indices.empty()) r.fail(what + ": fewer than 3 vertices, no triangle");
    int material;
    if (prim.material >= 0) {
        if (prim.material >= int(model.materials.size()))
            r.fail(what + ": material index " + std::to_string(prim.material) + " is out of range (the file has " +
                   std::to_string(model.materials.size()) + " materials)");
        material = material_base + prim.material;
    } else {
        if (default_material < 0) {
            Material dm;
            dm.name = "default";
            dm.base_color = glm::vec4(1.0f);
            dm.metallic = 1.0f;
            dm.roughness = 1.0f;
            default_material = scene.add_material(dm);
        }
        material = default_material;
    }
    // A texture on set 1 of a primitive without TEXCOORD_1 samples set 0 (GpuScene copies it).
    if (mesh.uvs1.empty() && !uv1_warned.count(material)) {
        const Material& mat = scene.materials[size_t(material)];
        for (const TextureRef* t : {&mat.base_color_texture, &mat.metallic_roughness_texture, &mat.normal_texture,
                                    &mat.emissive_texture, &mat.specular_texture, &mat.specular_color_texture})
            if (t->valid() && t->texcoord == 1) {
                warnings.push_back(path + ": material '" + mat.name + "' samples TEXCOORD_1, which " + what +
                                   " lacks; TEXCOORD_0 is used there");
                uv1_warned.insert(material);
                break;
            }
    }
    try {
        result = {scene.add_mesh(std::move(mesh)), material};
    } catch (const std::invalid_argument& e) {
        r.fail(what + ": " + e.what());
    }
    primitive_cache[key] = result;
    return result;
}

}  // namespace ssr::gltf_detail
