// Writing a Scene as glTF 2.0.

#include "scene/gltf_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <tiny_gltf.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string_view>

#include "core/errors.h"
#include "scene/image_io.h"
#include "scene/scene_limits.h"

#include "scene/gltf_internal.h"

namespace fs = std::filesystem;

namespace ssr {

using namespace gltf_detail;

// ---------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------

namespace {

class GltfBuilder {
public:
    tinygltf::Model model;

    GltfBuilder() {
        model.asset.version = "2.0";
        model.asset.generator = "ssrlab";
        model.buffers.emplace_back();
    }

    int add_view(const void* data, size_t bytes, int target) {
        auto& buf = model.buffers[0].data;
        while (buf.size() % 4) buf.push_back(0);  // glTF alignment
        tinygltf::BufferView bv;
        bv.buffer = 0;
        bv.byteOffset = buf.size();
        bv.byteLength = bytes;
        bv.target = target;
        const auto* p = static_cast<const uint8_t*>(data);
        buf.insert(buf.end(), p, p + bytes);
        model.bufferViews.push_back(bv);
        return int(model.bufferViews.size()) - 1;
    }

    template <typename V>
    int add_float_accessor(const std::vector<V>& values, int type, bool with_bounds) {
        tinygltf::Accessor acc;
        acc.bufferView = add_view(values.data(), values.size() * sizeof(V), TINYGLTF_TARGET_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        acc.count = values.size();
        acc.type = type;
        if (with_bounds) {  // glTF requires min/max on POSITION
            constexpr int n = V::length();
            acc.minValues.assign(n, 1e300);
            acc.maxValues.assign(n, -1e300);
            for (const auto& v : values)
                for (int c = 0; c < n; ++c) {
                    acc.minValues[size_t(c)] = std::min(acc.minValues[size_t(c)], double(v[c]));
                    acc.maxValues[size_t(c)] = std::max(acc.maxValues[size_t(c)], double(v[c]));
                }
        }
        model.accessors.push_back(acc);
        return int(model.accessors.size()) - 1;
    }

    // `count` elements of `comps` floats (animation keyframes: no buffer target); with bounds
    // (glTF requires them on a sampler's input).
    int add_keyframe_accessor(const std::vector<float>& values, int comps, int type, bool with_bounds) {
        tinygltf::Accessor acc;
        acc.bufferView = add_view(values.data(), values.size() * sizeof(float), 0);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        acc.count = values.size() / size_t(comps);
        acc.type = type;
        if (with_bounds) {
            acc.minValues.assign(size_t(comps), 1e300);
            acc.maxValues.assign(size_t(comps), -1e300);
            for (size_t i = 0; i < values.size(); ++i) {
                const size_t c = i % size_t(comps);
                acc.minValues[c] = std::min(acc.minValues[c], double(values[i]));
                acc.maxValues[c] = std::max(acc.maxValues[c], double(values[i]));
            }
        }
        model.accessors.push_back(acc);
        return int(model.accessors.size()) - 1;
    }

    int add_index_accessor(const std::vector<uint32_t>& idx) {
        tinygltf::Accessor acc;
        acc.bufferView = add_view(idx.data(), idx.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        acc.count = idx.size();
        acc.type = TINYGLTF_TYPE_SCALAR;
        model.accessors.push_back(acc);
        return int(model.accessors.size()) - 1;
    }
};

tinygltf::Value vec3_value(const glm::vec3& v) {
    return tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(double(v.x)), tinygltf::Value(double(v.y)),
                                                  tinygltf::Value(double(v.z))});
}

std::vector<double> matrix_values(const glm::mat4& m) {
    std::vector<double> out(16);
    for (int i = 0; i < 16; ++i) out[size_t(i)] = double(glm::value_ptr(m)[i]);
    return out;
}

}  // namespace

// Writes `bytes` to `path` and makes sure they reached the file system: every write, the
// fsync and the close are checked, and a failure is an OutputError with its errno.
static void write_file_checked(const std::string& path, const std::string& bytes) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) throw OutputError(path, errno, std::string("cannot open for writing: ") + std::strerror(errno));
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int err = n < 0 ? errno : EIO;
            ::close(fd);
            throw OutputError(path, err, std::string("cannot write the glTF file: ") + std::strerror(err));
        }
        done += size_t(n);
    }
    if (::fsync(fd) != 0 && errno != EINVAL) {
        const int err = errno;
        ::close(fd);
        throw OutputError(path, err, std::string("cannot write the glTF file: ") + std::strerror(err));
    }
    if (::close(fd) != 0) throw OutputError(path, errno, std::string("cannot finish the glTF file: ") + std::strerror(errno));
}

void save_gltf(const Scene& scene, const std::string& path, const std::string& folder) {
    const fs::path out(path);
    const std::string ext = out.extension().string();
    if (ext != ".gltf" && ext != ".glb")
        throw SceneError(path + ": the file name must end in .gltf or .glb");
    if (!out.parent_path().empty() && !fs::is_directory(out.parent_path()))
        throw FileNotFound("folder not found: " + out.parent_path().string());
    const bool binary = ext == ".glb";

    GltfBuilder b;
    auto& model = b.model;

    // Images (PNG in the buffer) and their textures.
    std::map<std::tuple<int, int, int>, int> texture_of;  // (image, wrap_s, wrap_t) -> texture
    std::vector<int> image_index(scene.images.size(), -1);
    auto texture = [&](const TextureRef& ref) -> int {
        if (!ref.valid()) return -1;
        if (image_index[size_t(ref.image)] < 0) {
            const Image& img = scene.images[size_t(ref.image)];
            const std::vector<uint8_t> png = encode_png(img);
            tinygltf::Image gi;
            gi.name = img.name;
            gi.mimeType = "image/png";
            gi.bufferView = b.add_view(png.data(), png.size(), 0);
            model.images.push_back(gi);
            image_index[size_t(ref.image)] = int(model.images.size()) - 1;
        }
        auto key = std::make_tuple(image_index[size_t(ref.image)], ref.wrap_s, ref.wrap_t);
        if (auto it = texture_of.find(key); it != texture_of.end()) return it->second;
        tinygltf::Sampler s;
        s.wrapS = ref.wrap_s;
        s.wrapT = ref.wrap_t;
        s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
        s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
        model.samplers.push_back(s);
        tinygltf::Texture t;
        t.source = image_index[size_t(ref.image)];
        t.sampler = int(model.samplers.size()) - 1;
        model.textures.push_back(t);
        return texture_of[key] = int(model.textures.size()) - 1;
    };

    for (const Material& m : scene.materials) {
        tinygltf::Material gm;
        gm.name = m.name;
        gm.pbrMetallicRoughness.baseColorFactor = {m.base_color.r, m.base_color.g, m.base_color.b, m.base_color.a};
        gm.pbrMetallicRoughness.metallicFactor = m.metallic;
        gm.pbrMetallicRoughness.roughnessFactor = m.roughness;
        // glTF bounds the factor to [0, 1]: a brighter emission is saved as its largest channel
        // in KHR_materials_emissive_strength, which the loader multiplies back.
        const float emissive_peak = std::max({m.emissive.r, m.emissive.g, m.emissive.b});
        const glm::vec3 factor = emissive_peak > 1.0f ? m.emissive / emissive_peak : m.emissive;
        gm.emissiveFactor = {factor.r, factor.g, factor.b};
        if (emissive_peak > 1.0f) {
            tinygltf::Value::Object strength;
            strength["emissiveStrength"] = tinygltf::Value(double(emissive_peak));
            gm.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(strength);
            if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_materials_emissive_strength") ==
                model.extensionsUsed.end())
                model.extensionsUsed.push_back("KHR_materials_emissive_strength");
        }
        gm.doubleSided = m.double_sided;
        auto use_extension = [&](const char* name) {
            if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), name) == model.extensionsUsed.end())
                model.extensionsUsed.push_back(name);
        };
        if (m.ior != 1.5f) {
            tinygltf::Value::Object ior;
            ior["ior"] = tinygltf::Value(double(m.ior));
            gm.extensions["KHR_materials_ior"] = tinygltf::Value(ior);
            use_extension("KHR_materials_ior");
        }
        if (m.alpha_mode != Material::AlphaMode::Opaque) {
            gm.alphaMode = m.alpha_mode == Material::AlphaMode::Mask ? "MASK" : "BLEND";
            gm.alphaCutoff = m.alpha_cutoff;
        }
        // KHR_texture_transform back from the affine rows: its first column is scale.x times the
        // rotation's first column, the second scale.y times its second.
        auto transform = [&](const TextureRef& ref, tinygltf::ExtensionMap& ext) {
            if (!ref.valid() || !ref.transformed()) return;
            const float a = ref.transform_u.x, b = ref.transform_u.y, d = ref.transform_v.x, e = ref.transform_v.y;
            const float rotation = std::atan2(-d, a);
            const float sx = std::sqrt(a * a + d * d), sy = b * std::sin(rotation) + e * std::cos(rotation);
            tinygltf::Value::Object t;
            t["offset"] = tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(double(ref.transform_u.z)),
                                                                 tinygltf::Value(double(ref.transform_v.z))});
            t["rotation"] = tinygltf::Value(double(rotation));
            t["scale"] = tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(double(sx)), tinygltf::Value(double(sy))});
            ext["KHR_texture_transform"] = tinygltf::Value(t);
            use_extension("KHR_texture_transform");
        };
        transform(m.base_color_texture, gm.pbrMetallicRoughness.baseColorTexture.extensions);
        transform(m.metallic_roughness_texture, gm.pbrMetallicRoughness.metallicRoughnessTexture.extensions);
        transform(m.normal_texture, gm.normalTexture.extensions);
        transform(m.emissive_texture, gm.emissiveTexture.extensions);
        gm.pbrMetallicRoughness.baseColorTexture.index = texture(m.base_color_texture);
        gm.pbrMetallicRoughness.baseColorTexture.texCoord = m.base_color_texture.texcoord;
        gm.pbrMetallicRoughness.metallicRoughnessTexture.index = texture(m.metallic_roughness_texture);
        gm.pbrMetallicRoughness.metallicRoughnessTexture.texCoord = m.metallic_roughness_texture.texcoord;
        gm.normalTexture.index = texture(m.normal_texture);
        gm.normalTexture.texCoord = m.normal_texture.texcoord;
        gm.normalTexture.scale = m.normal_scale;
        gm.emissiveTexture.index = texture(m.emissive_texture);
        gm.emissiveTexture.texCoord = m.emissive_texture.texcoord;
        if (m.specular != 1.0f || m.specular_color != glm::vec3(1.0f) || m.specular_texture.valid() ||
            m.specular_color_texture.valid()) {
            tinygltf::Value::Object spec;
            spec["specularFactor"] = tinygltf::Value(double(m.specular));
            spec["specularColorFactor"] = vec3_value(m.specular_color);
            // The extension's textures are glTF textureInfo objects inside it.
            auto info = [&](const TextureRef& ref) {
                tinygltf::Value::Object o;
                o["index"] = tinygltf::Value(texture(ref));
                if (ref.texcoord != 0) o["texCoord"] = tinygltf::Value(ref.texcoord);
                tinygltf::ExtensionMap e;
                transform(ref, e);
                if (!e.empty()) o["extensions"] = tinygltf::Value(tinygltf::Value::Object(e.begin(), e.end()));
                return tinygltf::Value(o);
            };
            if (m.specular_texture.valid()) spec["specularTexture"] = info(m.specular_texture);
            if (m.specular_color_texture.valid()) spec["specularColorTexture"] = info(m.specular_color_texture);
            gm.extensions["KHR_materials_specular"] = tinygltf::Value(spec);
            use_extension("KHR_materials_specular");
        }
        if (!m.auto_reflectivity())
            gm.extras = tinygltf::Value(tinygltf::Value::Object{{"reflectivity", tinygltf::Value(double(m.reflectivity))}});
        model.materials.push_back(gm);
    }

    // Accessors once per mesh; a glTF mesh per (mesh, material) pair that objects use.
    struct Attribs { int pos, nrm, uv, tan, idx, uv1, color; };
    std::vector<Attribs> attribs;
    for (const Mesh& m : scene.meshes) {
        Attribs a{};
        a.pos = b.add_float_accessor(m.positions, TINYGLTF_TYPE_VEC3, true);
        a.nrm = b.add_float_accessor(m.normals, TINYGLTF_TYPE_VEC3, false);
        a.uv = m.uvs.empty() ? -1 : b.add_float_accessor(m.uvs, TINYGLTF_TYPE_VEC2, false);
        a.tan = m.tangents.empty() ? -1 : b.add_float_accessor(m.tangents, TINYGLTF_TYPE_VEC4, false);
        // glTF numbers sets from 0 without gaps: a set 1 without a set 0 gets set 0 as zeros, what
        // the renderer reads for a mesh without it.
        if (!m.uvs1.empty() && m.uvs.empty())
            a.uv = b.add_float_accessor(std::vector<glm::vec2>(m.uvs1.size(), glm::vec2(0.0f)), TINYGLTF_TYPE_VEC2, false);
        a.uv1 = m.uvs1.empty() ? -1 : b.add_float_accessor(m.uvs1, TINYGLTF_TYPE_VEC2, false);
        a.color = m.colors.empty() ? -1 : b.add_float_accessor(m.colors, TINYGLTF_TYPE_VEC4, false);
        a.idx = b.add_index_accessor(m.indices);
        attribs.push_back(a);
    }
    // Objects and lights on a node of an animated file are written in its node tree below.
    std::vector<int> object_node(scene.objects.size(), -1), light_node(scene.lights.size(), -1);
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        for (int o : scene.nodes[i].objects) object_node[size_t(o)] = int(i);
        if (scene.nodes[i].light >= 0 && scene.nodes[i].light < int(scene.lights.size()))
            light_node[size_t(scene.nodes[i].light)] = int(i);
    }
    auto primitive = [&](const Object& o) {
        const Attribs& a = attribs[size_t(o.mesh)];
        tinygltf::Primitive p;
        p.attributes["POSITION"] = a.pos;
        p.attributes["NORMAL"] = a.nrm;
        if (a.uv >= 0) p.attributes["TEXCOORD_0"] = a.uv;
        if (a.tan >= 0) p.attributes["TANGENT"] = a.tan;
        if (a.uv1 >= 0) p.attributes["TEXCOORD_1"] = a.uv1;
        if (a.color >= 0) p.attributes["COLOR_0"] = a.color;
        p.indices = a.idx;
        p.material = o.material;
        p.mode = kModeTriangles;
        return p;
    };
    std::map<std::pair<int, int>, int> gltf_mesh;
    auto single_mesh = [&](const Object& o) {  // a glTF mesh per (mesh, material) pair that objects use
        auto key = std::make_pair(o.mesh, o.material);
        if (!gltf_mesh.count(key)) {
            tinygltf::Mesh gm;
            gm.name = scene.meshes[size_t(o.mesh)].name;
            gm.primitives.push_back(primitive(o));
            model.meshes.push_back(gm);
            gltf_mesh[key] = int(model.meshes.size()) - 1;
        }
        return gltf_mesh[key];
    };
    tinygltf::Scene gs;
    gs.name = scene.name;
    for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
        if (object_node[oi] >= 0) continue;
        const Object& o = scene.objects[oi];
        tinygltf::Node n;
        n.name = o.name;
        n.mesh = single_mesh(o);
        n.matrix = matrix_values(o.transform);
        model.nodes.push_back(n);
        gs.nodes.push_back(int(model.nodes.size()) - 1);
    }

    // A KHR_lights_punctual light; its extras keep the exact vectors for a lossless reload.
    auto add_light = [&](const Light& l) {
        tinygltf::Light gl;
        gl.name = l.name;
        gl.type = l.type == Light::Type::Directional ? "directional" : (l.type == Light::Type::Spot ? "spot" : "point");
        if (l.type == Light::Type::Spot) {
            gl.spot.innerConeAngle = l.inner_cone;
            gl.spot.outerConeAngle = l.outer_cone;
        }
        if (l.type != Light::Type::Directional) gl.range = l.range;
        gl.color = {l.color.r, l.color.g, l.color.b};
        gl.intensity = l.intensity;
        gl.extras = tinygltf::Value(tinygltf::Value::Object{{"cast_shadow", tinygltf::Value(l.cast_shadow)},
                                                            {"direction", vec3_value(l.direction)},
                                                            {"position", vec3_value(l.position)}});
        model.lights.push_back(gl);
        return tinygltf::Value(tinygltf::Value::Object{{"light", tinygltf::Value(int(model.lights.size()) - 1)}});
    };
    for (size_t li = 0; li < scene.lights.size(); ++li) {
        if (light_node[li] >= 0) continue;
        const Light& l = scene.lights[li];
        const tinygltf::Value light = add_light(l);
        // The node carries the light's frame: a light shines down its node's -z.
        glm::vec3 z = -glm::normalize(l.direction);
        glm::vec3 up = std::abs(z.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
        glm::vec3 x = glm::normalize(glm::cross(up, z)), y = glm::cross(z, x);
        glm::mat4 m(glm::vec4(x, 0), glm::vec4(y, 0), glm::vec4(z, 0), glm::vec4(l.position, 1));
        tinygltf::Node n;
        n.name = l.name.empty() ? "light" + std::to_string(model.lights.size() - 1) : l.name;
        n.matrix = matrix_values(m);
        n.extensions["KHR_lights_punctual"] = light;
        model.nodes.push_back(n);
        gs.nodes.push_back(int(model.nodes.size()) - 1);
    }

    // The node trees of animated files, in their current pose, with their animations: a node
    // keeps its objects as the primitives of its mesh (an object moved away from its node by
    // hand becomes a child node holding the difference) and its light.
    if (!scene.nodes.empty()) {
        const std::vector<glm::mat4> world = node_world_transforms(scene);
        std::vector<int> gltf_node(scene.nodes.size(), -1);
        for (size_t i = 0; i < scene.nodes.size(); ++i) {
            const SceneNode& sn = scene.nodes[i];
            tinygltf::Node n;
            n.name = sn.name;
            // The rest pose in the node's fields (what any viewer animates from), the pose the
            // scene stands in, when another, in extras.ssrlab.pose.
            const NodeTransform &t = sn.rest, &c = sn.current;
            if (t.has_matrix) {
                n.matrix = matrix_values(t.matrix);
            } else {
                if (t.translation != glm::vec3(0.0f)) n.translation = {t.translation.x, t.translation.y, t.translation.z};
                if (t.rotation != glm::dquat(1.0, 0.0, 0.0, 0.0))
                    n.rotation = {t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w};
                if (t.scale != glm::vec3(1.0f)) n.scale = {t.scale.x, t.scale.y, t.scale.z};
                if (c.translation != t.translation || c.rotation != t.rotation || c.scale != t.scale) {
                    auto numbers = [](std::initializer_list<double> v) {
                        tinygltf::Value::Array a;
                        for (double x : v) a.emplace_back(x);
                        return tinygltf::Value(a);
                    };
                    tinygltf::Value::Object pose{
                        {"translation", numbers({c.translation.x, c.translation.y, c.translation.z})},
                        {"rotation", numbers({c.rotation.x, c.rotation.y, c.rotation.z, c.rotation.w})},
                        {"scale", numbers({c.scale.x, c.scale.y, c.scale.z})}};
                    n.extras = tinygltf::Value(tinygltf::Value::Object{
                        {"ssrlab", tinygltf::Value(tinygltf::Value::Object{{"pose", tinygltf::Value(pose)}})}});
                }
            }
            tinygltf::Mesh gm;
            std::vector<tinygltf::Node> moved;
            for (int o : sn.objects) {
                const Object& ob = scene.objects[size_t(o)];
                if (ob.transform == world[i]) {
                    gm.primitives.push_back(primitive(ob));
                    continue;
                }
                tinygltf::Node c;
                c.name = ob.name;
                c.mesh = single_mesh(ob);
                c.matrix = matrix_values(glm::inverse(world[i]) * ob.transform);
                moved.push_back(c);
            }
            if (!gm.primitives.empty()) {
                gm.name = sn.name.empty() ? scene.meshes[size_t(scene.objects[size_t(sn.objects[0])].mesh)].name : sn.name;
                model.meshes.push_back(gm);
                n.mesh = int(model.meshes.size()) - 1;
            }
            if (sn.light >= 0 && sn.light < int(scene.lights.size()))
                n.extensions["KHR_lights_punctual"] = add_light(scene.lights[size_t(sn.light)]);
            model.nodes.push_back(n);
            gltf_node[i] = int(model.nodes.size()) - 1;
            for (auto& c : moved) {
                model.nodes.push_back(c);
                model.nodes[size_t(gltf_node[i])].children.push_back(int(model.nodes.size()) - 1);
            }
            if (sn.parent >= 0) {
                model.nodes[size_t(gltf_node[size_t(sn.parent)])].children.push_back(gltf_node[i]);
            } else if (sn.root_transform == glm::mat4(1.0f)) {
                gs.nodes.push_back(gltf_node[i]);
            } else {  // the transform the file was added with, as a parent of its root
                tinygltf::Node parent;
                parent.matrix = matrix_values(sn.root_transform);
                parent.children.push_back(gltf_node[i]);
                model.nodes.push_back(parent);
                gs.nodes.push_back(int(model.nodes.size()) - 1);
            }
        }
        for (const Animation& anim : scene.animations) {
            tinygltf::Animation ga;
            ga.name = anim.name;
            for (const AnimationChannel& ch : anim.channels) {
                const AnimationSampler& s = ch.sampler;
                tinygltf::AnimationSampler gsm;
                gsm.input = b.add_keyframe_accessor(s.times, 1, TINYGLTF_TYPE_SCALAR, true);
                gsm.output = b.add_keyframe_accessor(s.values, s.components,
                                                     s.components == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, false);
                gsm.interpolation = interpolation_name(s.interpolation);
                ga.samplers.push_back(gsm);
                tinygltf::AnimationChannel gc;
                gc.sampler = int(ga.samplers.size()) - 1;
                gc.target_node = gltf_node[size_t(ch.node)];
                gc.target_path = path_name(ch.path);
                ga.channels.push_back(gc);
            }
            model.animations.push_back(ga);
        }
    }
    if (!scene.lights.empty()) model.extensionsUsed.push_back("KHR_lights_punctual");

    if (scene.camera) {
        const CameraDesc& c = *scene.camera;
        tinygltf::Camera gc;
        gc.type = "perspective";
        gc.perspective.yfov = glm::radians(double(c.fov_y_degrees));
        gc.perspective.znear = c.near_plane;
        gc.perspective.zfar = c.far_plane;
        gc.perspective.aspectRatio = 0.0;  // from the image
        model.cameras.push_back(gc);
        tinygltf::Node n;
        n.name = "camera";
        n.camera = 0;
        n.matrix = matrix_values(glm::inverse(glm::lookAt(c.position, c.target, c.up)));
        model.nodes.push_back(n);
        gs.nodes.push_back(int(model.nodes.size()) - 1);
    }

    const Environment& env = scene.environment;
    tinygltf::Value::Object env_obj{
        {"type", tinygltf::Value(std::string(env.type == Environment::Type::Sky ? "sky"
                                             : env.type == Environment::Type::Map ? "map" : "constant"))},
        {"color", vec3_value(env.color)},
        {"zenith", vec3_value(env.sky_zenith)},
        {"horizon", vec3_value(env.sky_horizon)},
        {"ground", vec3_value(env.ground)},
        {"intensity", tinygltf::Value(double(env.intensity))}};
    if (env.type == Environment::Type::Map) {
        // Relative to the saved file when the map lies in its folder, so the pair can be moved
        // and loaded without allow_external_files; absolute otherwise.
        std::error_code ec;
        const fs::path map = fs::weakly_canonical(fs::absolute(env.map_path), ec);
        const fs::path dir = fs::weakly_canonical(fs::absolute(folder.empty() ? out.parent_path() : fs::path(folder)), ec);
        const fs::path rel = map.lexically_relative(dir);
        const bool inside = !ec && !rel.empty() && *rel.begin() != "..";
        env_obj["map"] = tinygltf::Value(inside ? rel.generic_string() : fs::absolute(env.map_path).string());
    }
    tinygltf::Value::Object ssr_obj{{"ambient", vec3_value(scene.ambient)},
                                    {"name", tinygltf::Value(scene.name)},
                                    {"environment", tinygltf::Value(env_obj)}};
    if (scene.camera) {  // the camera node holds the view; extras keep the exact look-at for a lossless reload
        const CameraDesc& c = *scene.camera;
        ssr_obj["camera"] = tinygltf::Value(tinygltf::Value::Object{
            {"position", vec3_value(c.position)}, {"target", vec3_value(c.target)}, {"up", vec3_value(c.up)},
            {"fov_y", tinygltf::Value(double(c.fov_y_degrees))}, {"near", tinygltf::Value(double(c.near_plane))},
            {"far", tinygltf::Value(double(c.far_plane))}});
    }
    gs.extras = tinygltf::Value(tinygltf::Value::Object{{"ssrlab", tinygltf::Value(ssr_obj)}});
    model.scenes.push_back(gs);
    model.defaultScene = 0;

    // tinygltf's file writers leave a stream's close unchecked (a full disk gives a silently
    // truncated file): the model is serialised in memory and every file written and checked here.
    tinygltf::TinyGLTF writer;
    std::ostringstream text;
    if (binary || model.buffers.empty() || model.buffers[0].data.empty()) {
        if (!model.buffers.empty() && model.buffers[0].data.empty()) model.buffers.clear(), model.bufferViews.clear();
        writer.WriteGltfSceneToStream(&model, text, /*prettyPrint=*/true, /*writeBinary=*/binary);
        write_file_checked(path, text.str());
        return;
    }
    // .gltf + .bin: the buffer goes to its own file, and the JSON names it (not a data URI).
    const std::vector<unsigned char> bin = std::move(model.buffers[0].data);
    model.buffers[0].data.clear();
    writer.WriteGltfSceneToStream(&model, text, /*prettyPrint=*/true, /*writeBinary=*/false);
    nlohmann::json doc = nlohmann::json::parse(text.str());
    const std::string bin_name = out.stem().string() + ".bin";
    doc["buffers"][0] = nlohmann::json{{"byteLength", bin.size()}, {"uri", bin_name}};
    write_file_checked((out.parent_path() / bin_name).string(), std::string(bin.begin(), bin.end()));
    write_file_checked(path, doc.dump(2) + "\n");
}

}  // namespace ssr
