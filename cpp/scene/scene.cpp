#include "scene/scene.h"

#include "scene/scene_limits.h"

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace ssr {

namespace {
uint64_t next_scene_id() {
    static std::atomic<uint64_t> counter{1};
    return counter++;
}
}  // namespace

Scene::Scene() : id_(next_scene_id()) {}
Scene::Scene(const Scene& o) { *this = o; }
Scene& Scene::operator=(const Scene& o) {
    name = o.name;
    meshes = o.meshes;
    materials = o.materials;
    images = o.images;
    objects = o.objects;
    lights = o.lights;
    nodes = o.nodes;
    animations = o.animations;
    ambient = o.ambient;
    environment = o.environment;
    probes = o.probes;
    camera = o.camera;
    revision_ = geometry_revision_ = transforms_revision_ = materials_revision_ = lights_revision_ = 0;
    object_revisions_.clear();
    material_revisions_.clear();
    id_ = next_scene_id();  // a copy is another scene for GPU caches
    return *this;
}

std::vector<glm::vec3> compute_vertex_normals(const std::vector<glm::vec3>& p, const std::vector<uint32_t>& idx) {
    std::vector<glm::vec3> n(p.size(), glm::vec3(0.0f));
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
        const glm::vec3 &a = p[idx[t]], &b = p[idx[t + 1]], &c = p[idx[t + 2]];
        const glm::vec3 face = glm::cross(b - a, c - a);  // length = 2 * area: area weighting
        n[idx[t]] += face;
        n[idx[t + 1]] += face;
        n[idx[t + 2]] += face;
    }
    for (auto& v : n) {
        const float len = glm::length(v);
        v = len > 0.0f ? v / len : glm::vec3(0.0f, 1.0f, 0.0f);
    }
    return n;
}

int Scene::add_mesh(Mesh m) {
    const std::string what = "mesh '" + m.name + "'";
    if (m.positions.empty()) throw std::invalid_argument(what + ": no vertices");
    if (m.indices.empty()) {
        if (m.positions.size() % 3 != 0)
            throw std::invalid_argument(what + ": a non-indexed triangle list needs a multiple of 3 vertices, got " +
                                        std::to_string(m.positions.size()));
        m.indices.resize(m.positions.size());
        for (size_t i = 0; i < m.indices.size(); ++i) m.indices[i] = uint32_t(i);
    }
    if (m.indices.size() % 3 != 0)
        throw std::invalid_argument(what + ": index count " + std::to_string(m.indices.size()) +
                                    " is not a multiple of 3");
    for (size_t i = 0; i < m.indices.size(); ++i)
        if (m.indices[i] >= m.positions.size())
            throw std::invalid_argument(what + ": index " + std::to_string(m.indices[i]) + " at position " +
                                        std::to_string(i) + " is out of range (" +
                                        std::to_string(m.positions.size()) + " vertices)");
    for (const auto& p : m.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw std::invalid_argument(what + ": vertex positions contain NaN or Inf");
    if (m.normals.empty()) m.normals = compute_vertex_normals(m.positions, m.indices);
    if (m.normals.size() != m.positions.size())
        throw std::invalid_argument(what + ": " + std::to_string(m.normals.size()) + " normals for " +
                                    std::to_string(m.positions.size()) + " vertices");
    for (auto& n : m.normals) {
        // Renormalise only what is visibly off unit length: dividing an already unit vector
        // by its length changes its last bits, and a saved scene must load back bit-exact.
        const float len = glm::length(n);
        if (!std::isfinite(len) || len < 1e-12f) n = glm::vec3(0.0f, 1.0f, 0.0f);
        else if (std::abs(len - 1.0f) > 1e-5f) n /= len;
    }
    if (!m.uvs.empty() && m.uvs.size() != m.positions.size())
        throw std::invalid_argument(what + ": " + std::to_string(m.uvs.size()) + " texture coordinates for " +
                                    std::to_string(m.positions.size()) + " vertices");
    if (!m.tangents.empty() && m.tangents.size() != m.positions.size())
        throw std::invalid_argument(what + ": " + std::to_string(m.tangents.size()) + " tangents for " +
                                    std::to_string(m.positions.size()) + " vertices");
    if (!m.colors.empty() && m.colors.size() != m.positions.size())
        throw std::invalid_argument(what + ": " + std::to_string(m.colors.size()) + " vertex colours for " +
                                    std::to_string(m.positions.size()) + " vertices");
    for (const auto& c : m.colors)
        for (int k = 0; k < 4; ++k)
            if (!(c[k] >= 0.0f && c[k] <= 1.0f))
                throw std::invalid_argument(what + ": vertex colours must be in [0, 1], got " + std::to_string(c[k]));
    if (!m.uvs1.empty() && m.uvs1.size() != m.positions.size())
        throw std::invalid_argument(what + ": " + std::to_string(m.uvs1.size()) + " texture coordinates (set 1) for " +
                                    std::to_string(m.positions.size()) + " vertices");
    for (const auto& uv : m.uvs1)
        if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
            throw std::invalid_argument(what + ": texture coordinates (set 1) contain NaN or Inf");
    meshes.push_back(std::move(m));
    touch();
    return int(meshes.size()) - 1;
}

int Scene::add_material(const Material& m) {
    validate_material(m, this);
    materials.push_back(m);
    touch_material(int(materials.size()) - 1);  // a new entry of the materials buffer only
    return int(materials.size()) - 1;
}

void Scene::touch_object(int i) {
    transforms_revision_ = ++revision_;
    if (size_t(i) >= object_revisions_.size()) object_revisions_.resize(size_t(i) + 1, 0);
    object_revisions_[size_t(i)] = revision_;
}

void Scene::touch_material(int m) {
    materials_revision_ = ++revision_;
    if (size_t(m) >= material_revisions_.size()) material_revisions_.resize(size_t(m) + 1, 0);
    material_revisions_[size_t(m)] = revision_;
}

void Scene::set_object_transform(int i, const glm::mat4& transform) {
    if (i < 0 || size_t(i) >= objects.size())
        throw std::out_of_range("object index " + std::to_string(i) + " is out of range (the scene has " +
                                std::to_string(objects.size()) + " objects)");
    Object& o = objects[size_t(i)];
    if (const std::string p = transform_problem(transform); !p.empty())
        throw std::invalid_argument("object '" + o.name + "': transform " + p);
    Bounds b;
    for (const auto& q : meshes[size_t(o.mesh)].positions) b.extend(q);
    if (const std::string p = world_bounds_problem(transform, b.min, b.max); !p.empty())
        throw std::invalid_argument("object '" + o.name + "': " + p);
    o.transform = transform;
    touch_object(i);
}

int Scene::add_object(int mesh, int material, const glm::mat4& transform, const std::string& obj_name) {
    if (mesh < 0 || mesh >= int(meshes.size()))
        throw std::invalid_argument("object '" + obj_name + "': mesh index " + std::to_string(mesh) + " out of range");
    if (material < 0 || material >= int(materials.size()))
        throw std::invalid_argument("object '" + obj_name + "': material index " + std::to_string(material) +
                                    " out of range");
    if (const std::string p = transform_problem(transform); !p.empty())
        throw std::invalid_argument("object '" + obj_name + "': transform " + p);
    Bounds b;
    for (const auto& q : meshes[size_t(mesh)].positions) b.extend(q);
    if (!b.empty())
        if (const std::string p = world_bounds_problem(transform, b.min, b.max); !p.empty())
            throw std::invalid_argument("object '" + obj_name + "': " + p);
    objects.push_back(Object{obj_name, mesh, material, transform});
    touch();
    return int(objects.size()) - 1;
}

int Scene::add_light(const Light& l) {
    if (const std::string p = light_problem(l); !p.empty())
        throw std::invalid_argument("light '" + l.name + "': " + p);
    lights.push_back(l);
    touch_lights();
    return int(lights.size()) - 1;
}

int Scene::add_mesh_object(Mesh mesh, const Material& material, const glm::mat4& transform,
                           const std::string& name) {
    validate_material(material, this);
    const int mi = add_mesh(std::move(mesh));
    const int mat = add_material(material);
    return add_object(mi, mat, transform, name);
}

void Scene::check_object(int i) const {
    if (i < 0 || i >= int(objects.size()))
        throw std::out_of_range("object index " + std::to_string(i) + " out of range (scene has " +
                                std::to_string(objects.size()) + " objects)");
}

const Image& Scene::image(int i) const {
    if (i < 0 || i >= int(images.size()))
        throw std::out_of_range("Scene.image: index " + std::to_string(i) + " is out of range (the scene has " +
                                std::to_string(images.size()) + " images)");
    return images[size_t(i)];
}

void Scene::set_material(int i, const Material& m) {
    check_object(i);
    validate_material(m, this);
    int& idx = objects[size_t(i)].material;
    int users = 0;
    for (const auto& o : objects) users += o.material == idx;
    if (users == 1) {  // only this object uses it
        materials[size_t(idx)] = m;
        touch_material(idx);
    } else {  // shared: give this object its own
        idx = add_material(m);
        touch_object(i);
    }
}

void Scene::set_ambient(const glm::vec3& a) {
    if (const std::string p = radiance_problem(a, 1.0f); !p.empty()) throw std::invalid_argument("Scene.ambient " + p);
    ambient = a;
    touch_frame();
}

void Scene::set_probes(const std::vector<glm::vec3>& p) {
    for (size_t i = 0; i < p.size(); ++i)
        if (!std::isfinite(p[i].x) || !std::isfinite(p[i].y) || !std::isfinite(p[i].z))
            throw std::invalid_argument("Scene.probes: probe " + std::to_string(i) + " must have finite coordinates");
    if (p.size() > 64) throw std::invalid_argument("Scene.probes: at most 64 probes, got " + std::to_string(p.size()));
    probes = p;
    touch_frame();
}

void Scene::set_environment(const Environment& e) {
    // What each kind reads, scaled by its intensity (a map's texels are checked on load).
    std::vector<std::pair<const char*, glm::vec3>> terms = {{"intensity", glm::vec3(1.0f)}};
    if (e.type == Environment::Type::Constant) terms = {{"color", e.color}};
    if (e.type == Environment::Type::Sky) terms = {{"zenith", e.sky_zenith}, {"horizon", e.sky_horizon}, {"ground", e.ground}};
    for (const auto& [field, rgb] : terms)
        if (const std::string p = radiance_problem(rgb, e.intensity); !p.empty())
            throw std::invalid_argument(std::string("Scene.environment: ") + field + " " + p);
    // Only a map is a texture of the scene's GPU copy; the rest is read per frame.
    const bool map = e.type == Environment::Type::Map || environment.type == Environment::Type::Map;
    const bool same_map = e.type == environment.type && e.map_path == environment.map_path;
    environment = e;
    if (map && !same_map) touch();
    else touch_frame();
}

size_t Scene::triangle_count() const {
    size_t n = 0;
    for (const auto& o : objects) n += meshes[size_t(o.mesh)].triangle_count();
    return n;
}

namespace {
// FNV-1a over raw bytes: stable across runs and machines of the same endianness.
struct Hasher {
    uint64_t h = 1469598103934665603ull;
    void bytes(const void* p, size_t n) {
        const auto* c = static_cast<const unsigned char*>(p);
        for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
    }
    template <typename T>
    void pod(const T& v) { bytes(&v, sizeof(T)); }
    template <typename T>
    void vec(const std::vector<T>& v) {
        pod(v.size());
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
    void str(const std::string& s) { pod(s.size()); bytes(s.data(), s.size()); }
};
}  // namespace

uint64_t Scene::content_hash() const {
    Hasher h;
    for (const Mesh& m : meshes) {
        h.vec(m.positions);
        h.vec(m.normals);
        h.vec(m.uvs);
        h.vec(m.tangents);
        h.vec(m.colors);
        h.vec(m.uvs1);
        h.vec(m.indices);
    }
    for (const Material& m : materials) {
        h.pod(m.base_color);
        h.pod(m.metallic);
        h.pod(m.roughness);
        h.pod(m.reflectivity);
        h.pod(m.emissive);
        for (const TextureRef* t : {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                                     &m.emissive_texture, &m.specular_texture, &m.specular_color_texture}) {
            h.pod(t->image);
            h.pod(t->wrap_s);
            h.pod(t->wrap_t);
            h.pod(t->transform_u);
            h.pod(t->transform_v);
            h.pod(t->texcoord);
        }
        h.pod(m.normal_scale);
        h.pod(m.double_sided);
        h.pod(m.alpha_mode);
        h.pod(m.alpha_cutoff);
        h.pod(m.ior);
        h.pod(m.specular);
        h.pod(m.specular_color);
    }
    for (const Image& i : images) {
        h.pod(i.width);
        h.pod(i.height);
        h.vec(i.rgba);
    }
    for (const Object& o : objects) {
        h.pod(o.mesh);
        h.pod(o.material);
        h.pod(o.transform);
    }
    for (const Light& l : lights) {
        h.pod(l.type);
        h.pod(l.color);
        h.pod(l.intensity);
        h.pod(l.direction);
        h.pod(l.position);
        h.pod(l.cast_shadow);
        h.pod(l.inner_cone);
        h.pod(l.outer_cone);
        h.pod(l.range);
    }
    h.pod(ambient);
    h.pod(environment.type);
    h.pod(environment.color);
    h.pod(environment.sky_zenith);
    h.pod(environment.sky_horizon);
    h.pod(environment.ground);
    h.pod(environment.intensity);
    h.str(environment.map_path);
    if (camera) h.pod(*camera);
    return h.h;
}

Bounds Scene::bounds() const {
    Bounds b;
    for (const auto& o : objects) {
        for (const auto& p : meshes[size_t(o.mesh)].positions) b.extend(glm::vec3(o.transform * glm::vec4(p, 1.0f)));
    }
    return b;
}

}  // namespace ssr
