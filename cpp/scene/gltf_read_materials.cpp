// Materials (glTF 2.0, materials) and the extensions ssrlab reads on them:
// KHR_materials_emissive_strength, KHR_materials_ior, KHR_materials_specular.

#include "scene/gltf_reader.h"
#include "scene/scene_limits.h"

namespace ssr::gltf_detail {

void check_materials(const tinygltf::Model& model, const GltfReader& r) {
    for (size_t i = 0; i < model.materials.size(); ++i) {
        const auto& m = model.materials[i];
        const std::string what = "material " + std::to_string(i) + " ('" + m.name + "')";
        const auto& pbr = m.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4) r.fail(what + ": baseColorFactor does not have 4 values");
        for (double x : pbr.baseColorFactor)
            if (!in_range(x, 0.0, 1.0)) r.fail(what + ": baseColorFactor holds " + num(x) + ", outside [0, 1]");
        if (!in_range(pbr.metallicFactor, 0.0, 1.0)) r.fail(what + ": metallicFactor " + num(pbr.metallicFactor) + " is outside [0, 1]");
        if (!in_range(pbr.roughnessFactor, 0.0, 1.0)) r.fail(what + ": roughnessFactor " + num(pbr.roughnessFactor) + " is outside [0, 1]");
        if (!m.emissiveFactor.empty() && m.emissiveFactor.size() != 3) r.fail(what + ": emissiveFactor does not have 3 values");
        for (double x : m.emissiveFactor)
            if (!in_range(x, 0.0, 1.0)) r.fail(what + ": emissiveFactor holds " + num(x) + ", outside [0, 1]");
        if (!in_range(m.normalTexture.scale, -1e3, 1e3)) r.fail(what + ": normalTexture.scale " + num(m.normalTexture.scale) + " is not finite");
        if (!in_range(m.alphaCutoff, 0.0, 1e30)) r.fail(what + ": alphaCutoff " + num(m.alphaCutoff) + " must be finite and >= 0");
        if (m.extras.Has("reflectivity"))
            number_from_value(m.extras.Get("reflectivity"), r, what + ": extras.reflectivity", 0.0, 1.0);
    }
}

int read_materials(const tinygltf::Model& model, const GltfReader& r, Scene& scene, int image_base,
                   const std::string& path, std::vector<std::string>& warnings) {
    const int material_base = int(scene.materials.size());
    std::string blended;  // the BLEND materials, named in one warning
    for (size_t i = 0; i < model.materials.size(); ++i) {
        const auto& gm = model.materials[i];
        const std::string what = "material " + std::to_string(i) + " ('" + gm.name + "')";
        Material m;
        m.name = gm.name.empty() ? "material" + std::to_string(i) : gm.name;
        const auto& pbr = gm.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() == 4)
            m.base_color = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2],
                                     pbr.baseColorFactor[3]);
        m.metallic = float(pbr.metallicFactor);
        m.roughness = float(pbr.roughnessFactor);
        m.emissive = vec3_from(gm.emissiveFactor, glm::vec3(0.0f));
        // KHR_materials_emissive_strength scales the [0, 1] factor; the product is what is
        // emitted, and it must stay within the half-float lighting buffers (scene_limits.h).
        if (auto it = gm.extensions.find("KHR_materials_emissive_strength");
            it != gm.extensions.end() && it->second.Has("emissiveStrength")) {
            const double strength = number_from_value(it->second.Get("emissiveStrength"), r,
                                                      what + ": KHR_materials_emissive_strength.emissiveStrength", 0.0, 1e30);
            m.emissive *= float(strength);
            if (const std::string p = radiance_problem(m.emissive, 1.0f); !p.empty())
                r.fail(what + ": emissiveFactor x emissiveStrength " + p);
        }
        // KHR_materials_ior and KHR_materials_specular: the dielectric F0 (Material::dielectric_f0).
        if (auto it = gm.extensions.find("KHR_materials_ior"); it != gm.extensions.end() && it->second.Has("ior")) {
            m.ior = float(number_from_value(it->second.Get("ior"), r, what + ": KHR_materials_ior.ior", 0.0, 1e6));
            if (m.ior > 0.0f && m.ior < 1.0f)
                r.fail(what + ": KHR_materials_ior.ior " + num(m.ior) + " must be 0 or at least 1");
        }
        if (auto it = gm.extensions.find("KHR_materials_specular"); it != gm.extensions.end()) {
            const std::string ext = what + ": KHR_materials_specular";
            if (it->second.Has("specularFactor"))
                m.specular = float(number_from_value(it->second.Get("specularFactor"), r, ext + ".specularFactor", 0.0, 1.0));
            if (it->second.Has("specularColorFactor"))
                m.specular_color = vec3_from_value(it->second.Get("specularColorFactor"), glm::vec3(1.0f), r,
                                                   ext + ".specularColorFactor", 0.0, 1e6);
            // Its textures (glTF textureInfo objects inside the extension): specularTexture's A
            // scales specularFactor, specularColorTexture's sRGB-decoded RGB specularColorFactor.
            auto info = [&](const char* key) {
                if (!it->second.Has(key)) return TextureRef{};
                const tinygltf::Value& v = it->second.Get(key);
                const std::string t = ext + "." + key;
                if (!v.IsObject() || !v.Has("index")) r.fail(t + " must be an object with an index");
                const int index = int(number_from_value(v.Get("index"), r, t + ".index", 0, 1e9));
                const int texcoord = v.Has("texCoord") ? int(number_from_value(v.Get("texCoord"), r, t + ".texCoord", 0, 7)) : 0;
                tinygltf::ExtensionMap extensions;
                if (v.Has("extensions") && v.Get("extensions").IsObject())
                    for (const auto& key_value : v.Get("extensions").Get<tinygltf::Value::Object>())
                        extensions.insert(key_value);
                return texture_ref(model, index, texcoord, image_base, r, t, extensions);
            };
            m.specular_texture = info("specularTexture");
            m.specular_color_texture = info("specularColorTexture");
        }
        m.double_sided = gm.doubleSided;
        if (gm.alphaMode == "MASK") {
            m.alpha_mode = Material::AlphaMode::Mask;
            m.alpha_cutoff = float(gm.alphaCutoff);
        } else if (gm.alphaMode == "BLEND") {
            m.alpha_mode = Material::AlphaMode::Blend;
            blended += (blended.empty() ? "" : ", ") + what;
        } else if (gm.alphaMode != "OPAQUE" && !gm.alphaMode.empty()) {
            r.fail(what + ": alphaMode '" + gm.alphaMode + "' is not OPAQUE, MASK or BLEND");
        }
        m.base_color_texture = texture_ref(model, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, image_base, r,
                                           what + ": baseColorTexture", pbr.baseColorTexture.extensions);
        m.metallic_roughness_texture =
            texture_ref(model, pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord, image_base, r,
                        what + ": metallicRoughnessTexture", pbr.metallicRoughnessTexture.extensions);
        m.normal_texture = texture_ref(model, gm.normalTexture.index, gm.normalTexture.texCoord, image_base, r,
                                       what + ": normalTexture", gm.normalTexture.extensions);
        m.normal_scale = float(gm.normalTexture.scale);
        // The emitted radiance is emissiveFactor x strength x this texture's (sRGB-decoded) texel.
        m.emissive_texture = texture_ref(model, gm.emissiveTexture.index, gm.emissiveTexture.texCoord, image_base, r,
                                         what + ": emissiveTexture", gm.emissiveTexture.extensions);
        // The thesis's explicit reflectivity where ssrlab wrote it; otherwise the material
        // reflects as its metallic-roughness parameters say (kAutoReflectivity).
        // TEXCOORD_0 and _1 are loaded; a texture on a later set samples set 0.
        for (TextureRef* t : {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture, &m.emissive_texture,
                              &m.specular_texture, &m.specular_color_texture})
            if (t->valid() && t->texcoord > 1) {
                warnings.push_back(path + ": " + what + ": texCoord " + std::to_string(t->texcoord) +
                                   " is not loaded (only TEXCOORD_0 and TEXCOORD_1); TEXCOORD_0 is used");
                t->texcoord = 0;
            }
        m.reflectivity = kAutoReflectivity;
        if (gm.extras.Has("reflectivity")) m.reflectivity = float(gm.extras.Get("reflectivity").GetNumberAsDouble());
        scene.materials.push_back(m);
    }
    if (!blended.empty())
        warnings.push_back(path + ": alphaMode BLEND drawn as MASK at alpha 0.5 (a hole below, opaque above; no "
                           "translucent layer): " + blended);
    return material_base;
}

}  // namespace ssr::gltf_detail
