#include "render/gpu_scene.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <limits>
#include <stdexcept>

#include "render/gpu_structs.h"
#include "scene/bvh.h"
#include "scene/image_io.h"

namespace ssr {

GpuScene::VertexArray::~VertexArray() {
    if (id) glDeleteVertexArrays(1, &id);
}

namespace {
Texture solid_texture(uint8_t r, uint8_t g, uint8_t b, uint8_t a) {
    Texture t = Texture::create_2d(GL_RGBA8, 1, 1, 1);
    const uint8_t px[4] = {r, g, b, a};
    glTextureSubImage2D(t.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
    t.set_wrap(GL_REPEAT, GL_REPEAT);
    return t;
}
}  // namespace

namespace {
std::atomic<uint64_t> caster_states{1};
uint64_t next_caster_state() { return caster_states++; }
}  // namespace

GpuScene::GpuScene(const Scene& scene, SceneWork* work)
    : work_(work),
      geometry_revision_(scene.geometry_revision()),
      caster_state_(next_caster_state()),
      caster_log_start_(caster_state_),
      revision_(scene.revision()) {
    std::vector<GpuVertex> verts;
    std::vector<uint32_t> idx;
    for (const Mesh& m : scene.meshes) {
        mesh_ranges_.push_back(MeshRange{idx.size(), GLsizei(m.indices.size()), GLint(verts.size())});
        for (size_t i = 0; i < m.positions.size(); ++i) {
            GpuVertex v{};
            v.position = m.positions[i];
            v.normal = m.normals[i];
            v.uv = m.uvs.empty() ? glm::vec2(0.0f) : m.uvs[i];
            v.tangent = m.tangents.empty() ? glm::vec4(0.0f) : m.tangents[i];
            v.color = m.colors.empty() ? glm::vec4(1.0f) : m.colors[i];
            vertex_colors_ = vertex_colors_ || v.color != glm::vec4(1.0f);
            v.uv1 = m.uvs1.empty() ? v.uv : m.uvs1[i];
            verts.push_back(v);
        }
        idx.insert(idx.end(), m.indices.begin(), m.indices.end());
    }
    vertices_ = Buffer::create(verts.size() * sizeof(GpuVertex), verts.data());
    indices_ = Buffer::create(idx.size() * sizeof(uint32_t), idx.data());

    vao_ = std::make_unique<VertexArray>();
    glCreateVertexArrays(1, &vao_->id);
    glVertexArrayVertexBuffer(vao_->id, 0, vertices_.id(), 0, sizeof(GpuVertex));
    glVertexArrayElementBuffer(vao_->id, indices_.id());
    const GLuint offsets[6] = {offsetof(GpuVertex, position), offsetof(GpuVertex, normal), offsetof(GpuVertex, uv),
                               offsetof(GpuVertex, tangent), offsetof(GpuVertex, color), offsetof(GpuVertex, uv1)};
    const GLint sizes[6] = {3, 3, 2, 4, 4, 2};
    for (GLuint a = 0; a < 6; ++a) {
        glEnableVertexArrayAttrib(vao_->id, a);
        glVertexArrayAttribFormat(vao_->id, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
        glVertexArrayAttribBinding(vao_->id, a, 0);
    }

    white_ = solid_texture(255, 255, 255, 255);
    flat_normal_ = solid_texture(128, 128, 255, 255);

    for (size_t m = 0; m < scene.materials.size(); ++m) set_material(scene, m);
    materials_ = Buffer::create(material_data_.size() * sizeof(GpuMaterial), material_data_.data());

    std::vector<GpuObject> objs;
    for (size_t i = 0; i < scene.objects.size(); ++i) {
        const Object& o = scene.objects[i];
        if (triangles_ > size_t(std::numeric_limits<int>::max()))
            throw std::invalid_argument("scene: more than 2^31 triangles");
        first_triangle_.push_back(int(triangles_));
        objs.push_back(object_entry(scene, i));
        const MeshRange& r = mesh_ranges_[size_t(o.mesh)];
        draws_.push_back(DrawItem{int(i), o.material, r.count, r.first_index, r.base_vertex});
        triangles_ += size_t(r.count) / 3;
        object_transforms_.push_back(o.transform);
        object_bounds_.push_back(compute_object_bounds(scene, i));
    }
    objects_ = Buffer::create(objs.size() * sizeof(GpuObject), objs.data());
    refresh_summary(scene);

    if (scene.environment.type == Environment::Type::Map) {
        const FloatImage img = read_float_image(scene.environment.map_path);
        std::vector<float> rgba(size_t(img.width) * size_t(img.height) * 4, 1.0f);
        for (size_t i = 0; i < size_t(img.width) * size_t(img.height); ++i)
            for (int c = 0; c < 3; ++c)
                rgba[i * 4 + size_t(c)] = img.pixels[i * size_t(img.channels) + size_t(std::min(c, img.channels - 1))];
        environment_map_ = Texture::create_2d(GL_RGBA32F, img.width, img.height, 0);
        // The file's first row is the zenith (v = 0), as environment.glsl samples it.
        glTextureSubImage2D(environment_map_.id(), 0, 0, 0, img.width, img.height, GL_RGBA, GL_FLOAT, rgba.data());
        glGenerateTextureMipmap(environment_map_.id());
        environment_map_.set_filter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
        environment_map_.set_wrap(GL_REPEAT, GL_CLAMP_TO_EDGE);
    }
}

GpuScene::~GpuScene() = default;

void GpuScene::set_material(const Scene& scene, size_t index) {
    const Material& m = scene.materials[index];
    GpuMaterial g{};
    g.base_color = m.base_color;
    g.params = glm::vec4(m.metallic, m.roughness, m.reflectivity, m.normal_scale);
    g.emissive = glm::vec4(m.emissive, m.visibility_cutoff());
    g.flags = glm::ivec4(m.base_color_texture.valid(), m.metallic_roughness_texture.valid(), m.normal_texture.valid(),
                         m.double_sided);
    auto wrap = [](const TextureRef& t) { return t.wrap_s | (t.wrap_t << 16); };
    g.images = glm::ivec4(m.base_color_texture.image, m.metallic_roughness_texture.image, m.normal_texture.image,
                          m.emissive_texture.image);
    g.wraps = glm::ivec4(wrap(m.base_color_texture), wrap(m.metallic_roughness_texture), wrap(m.normal_texture),
                         wrap(m.emissive_texture));
    g.dielectric_f0 = glm::vec4(m.dielectric_f0(), 0.0f);
    const TextureRef* refs[6] = {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture,
                                 &m.emissive_texture, &m.specular_texture, &m.specular_color_texture};
    for (int k = 0; k < 6; ++k) {
        g.uv_transform[2 * k] = glm::vec4(refs[k]->transform_u, refs[k]->texcoord == 1 ? 1.0f : 0.0f);
        g.uv_transform[2 * k + 1] = glm::vec4(refs[k]->transform_v, 0.0f);
    }
    g.specular_images = glm::ivec4(m.specular_texture.image, m.specular_color_texture.image, -1, -1);
    g.specular_wraps = glm::ivec4(wrap(m.specular_texture), wrap(m.specular_color_texture), 0, 0);
    const float r = (m.ior - 1.0f) / (m.ior + 1.0f);  // as Material::dielectric_f0
    g.specular_f0 = glm::vec4(r * r * m.specular_color, m.specular);
    const std::array<GLuint, 6> textures = {texture_for(scene, m.base_color_texture, true),
                                            texture_for(scene, m.metallic_roughness_texture, false),
                                            texture_for(scene, m.normal_texture, false),
                                            texture_for(scene, m.emissive_texture, true),
                                            texture_for(scene, m.specular_texture, false),
                                            texture_for(scene, m.specular_color_texture, true)};
    int features = m.auto_reflectivity() ? kAutoReflectivityFeature : 0;
    for (int k = 0; k < 6; ++k)
        if (refs[k]->valid()) features |= 1 << k;
    if (index == material_data_.size()) {
        material_data_.push_back(g);
        material_textures_.push_back(textures);
        material_features_.push_back(features);
        alpha_tested_.push_back(m.visibility_cutoff() >= 0.0f);
        alpha_keys_.push_back(alpha_key(m));
    } else {
        material_data_[index] = g;
        material_textures_[index] = textures;
        material_features_[index] = features;
        alpha_tested_[index] = m.visibility_cutoff() >= 0.0f;
        alpha_keys_[index] = alpha_key(m);
    }
}

std::vector<float> GpuScene::alpha_key(const Material& m) {
    const float cutoff = m.visibility_cutoff();
    if (cutoff < 0.0f) return {-1.0f};  // opaque: its depth is its geometry's
    const TextureRef& t = m.base_color_texture;
    return {cutoff, m.base_color.a, float(t.image), float(t.wrap_s), float(t.wrap_t), float(t.texcoord),
            t.transform_u.x, t.transform_u.y, t.transform_u.z, t.transform_v.x, t.transform_v.y, t.transform_v.z};
}

GpuObject GpuScene::object_entry(const Scene& scene, size_t i) const {
    const Object& o = scene.objects[i];
    GpuObject g{};
    g.model = o.transform;
    g.normal_matrix = glm::transpose(glm::inverse(o.transform));
    const MeshRange& r = mesh_ranges_[size_t(o.mesh)];
    g.material = glm::ivec4(o.material, int(r.first_index), r.base_vertex, first_triangle_[i]);
    return g;
}

Bounds GpuScene::compute_object_bounds(const Scene& scene, size_t i) const {
    const Object& o = scene.objects[i];
    Bounds b;  // as Scene::bounds, one object
    for (const auto& p : scene.meshes[size_t(o.mesh)].positions) b.extend(glm::vec3(o.transform * glm::vec4(p, 1.0f)));
    return b;
}

void GpuScene::refresh_summary(const Scene& scene) {
    reflective_ = emissive_texture_ = specular_texture_ = false;
    bounds_ = Bounds{};
    for (size_t i = 0; i < scene.objects.size(); ++i) {
        const Material& m = scene.materials[size_t(scene.objects[i].material)];
        reflective_ = reflective_ || m.reflectivity != 0.0f;
        emissive_texture_ = emissive_texture_ || m.emissive_texture.valid();
        specular_texture_ = specular_texture_ || m.specular_texture.valid() || m.specular_color_texture.valid();
        // The union of the objects' bounds is Scene::bounds() exactly (min and max are exact).
        if (!object_bounds_[i].empty()) {
            bounds_.extend(object_bounds_[i].min);
            bounds_.extend(object_bounds_[i].max);
        }
    }
}

bool GpuScene::caster_changes_since(uint64_t since, std::vector<Bounds>& regions) const {
    regions.clear();
    if (since == caster_state_) return true;
    size_t from = 0;
    if (since != caster_log_start_) {
        while (from < caster_log_.size() && caster_log_[from].state != since) ++from;
        if (from == caster_log_.size()) return false;
        ++from;  // the steps after `since`
    }
    for (size_t k = from; k < caster_log_.size(); ++k)
        regions.insert(regions.end(), caster_log_[k].regions.begin(), caster_log_[k].regions.end());
    return true;
}

bool GpuScene::update(const Scene& scene) {
    if (scene.geometry_revision() != geometry_revision_ || scene.objects.size() != draws_.size()) return false;
    if (scene.revision() == revision_) return true;
    // Materials: the edited ones (and any added) get their entries again.
    const size_t old_materials = material_data_.size();
    std::vector<uint8_t> alpha_changed(scene.materials.size(), 0);
    std::vector<size_t> rewritten;
    for (size_t m = 0; m < scene.materials.size(); ++m) {
        if (m < old_materials && scene.material_revision(m) <= revision_) continue;
        const std::vector<float> before = m < old_materials ? alpha_keys_[m] : std::vector<float>{};
        set_material(scene, m);
        if (m < old_materials) {
            rewritten.push_back(m);
            alpha_changed[m] = alpha_keys_[m] != before;
        }
        if (work_) ++work_->material_updates;
    }
    if (material_data_.size() != old_materials)
        materials_ = Buffer::create(material_data_.size() * sizeof(GpuMaterial), material_data_.data());
    else
        for (size_t m : rewritten) materials_.upload(&material_data_[m], sizeof(GpuMaterial), m * sizeof(GpuMaterial));
    // Objects: a new transform or material index rewrites the entry; a move stales the object's
    // BVH part, a change of its alpha test its triangles' flags and masks.
    std::vector<Bounds> regions;  // where depth-only passes draw something else now
    for (size_t i = 0; i < scene.objects.size(); ++i) {
        const Object& o = scene.objects[i];
        const bool entry = scene.object_revision(i) > revision_;
        bool alpha = size_t(o.material) < alpha_changed.size() && alpha_changed[size_t(o.material)];
        if (entry) {
            const GpuObject g = object_entry(scene, i);
            objects_.upload(&g, sizeof(GpuObject), i * sizeof(GpuObject));
            if (o.transform != object_transforms_[i]) {
                object_transforms_[i] = o.transform;
                regions.push_back(object_bounds_[i]);
                object_bounds_[i] = compute_object_bounds(scene, i);
                regions.push_back(object_bounds_[i]);
                if (ray_tracing_ready_) bvh_moved_.push_back(int(i));
            }
            const int before = draws_[i].material;
            draws_[i].material = o.material;
            alpha = alpha || alpha_keys_[size_t(before)] != alpha_keys_[size_t(o.material)];
            if (work_) ++work_->object_updates;
        }
        if (alpha) {
            if (ray_tracing_ready_) bvh_alpha_.push_back(int(i));
            regions.push_back(object_bounds_[i]);
        }
    }
    if (!regions.empty()) {
        caster_state_ = next_caster_state();
        caster_log_.push_back(CasterStep{caster_state_, std::move(regions)});
        if (caster_log_.size() > kCasterLogSteps) {
            caster_log_start_ = caster_log_.front().state;
            caster_log_.pop_front();
        }
    }
    refresh_summary(scene);
    revision_ = scene.revision();
    return true;
}

GLuint GpuScene::texture_for(const Scene& scene, const TextureRef& ref, bool srgb) {
    if (!ref.valid()) return 0;
    auto key = std::make_tuple(ref.image, srgb, ref.wrap_s, ref.wrap_t);
    if (auto it = textures_.find(key); it != textures_.end()) return it->second.id();
    const Image& img = scene.images[size_t(ref.image)];
    Texture t = Texture::create_2d(srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, img.width, img.height, 0);
    // glTF's uv (0,0) is the first row of the image file, which is also GL's first texel row,
    // so the rows go up as they are.
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(t.id(), 0, 0, 0, img.width, img.height, GL_RGBA, GL_UNSIGNED_BYTE, img.rgba.data());
    glGenerateTextureMipmap(t.id());
    t.set_filter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
    t.set_wrap(GLenum(ref.wrap_s), GLenum(ref.wrap_t));
    const GLuint id = t.id();
    textures_.emplace(key, std::move(t));
    return id;
}

void GpuScene::bind_ray_tracing(const Scene& scene) {
    if (!ray_tracing_ready_) {
        bvh_ = std::make_unique<SceneBvh>(scene);
        bvh_->take_changes();
        bvh_depth_ = bvh_->depth();
        alpha_masks_ = AlphaMasks(scene, bvh_->triangles());
        upload_bvh_changes();
        std::vector<uint8_t> texels;
        std::vector<glm::ivec4> info;
        for (const Image& img : scene.images) {
            info.emplace_back(int(texels.size() / 4), img.width, img.height, 0);
            texels.insert(texels.end(), img.rgba.begin(), img.rgba.end());
        }
        image_texels_ = Buffer::create(texels.size(), texels.data());
        image_info_ = Buffer::create(info.size() * sizeof(glm::ivec4), info.data());
        ray_tracing_ready_ = true;
        bvh_moved_.clear();
        bvh_alpha_.clear();
        if (work_) ++work_->bvh_builds;
    } else {
        update_ray_tracing(scene);
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBvhNodesBinding, bvh_nodes_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kBvhTrianglesBinding, bvh_triangles_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kImageTexelsBinding, image_texels_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kImageInfoBinding, image_info_.id());
    bind_vertex_data();
}

void GpuScene::bind_vertex_data() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kVertexDataBinding, vertices_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kIndexDataBinding, indices_.id());
}

void GpuScene::update_ray_tracing(const Scene& scene) {
    if (bvh_moved_.empty() && bvh_alpha_.empty()) return;
    const auto start = std::chrono::steady_clock::now();
    auto unique = [](std::vector<int>& v) {
        std::sort(v.begin(), v.end());
        v.erase(std::unique(v.begin(), v.end()), v.end());
    };
    unique(bvh_moved_);
    unique(bvh_alpha_);
    const size_t rebuilt = bvh_->update(scene, bvh_moved_);
    for (int i : bvh_alpha_) bvh_->set_alpha_tested(i, alpha_tested(scene.objects[size_t(i)].material));
    std::vector<int> changed = bvh_moved_;
    changed.insert(changed.end(), bvh_alpha_.begin(), bvh_alpha_.end());
    unique(changed);
    // The moved objects' triangles changed order within their segments: their masks follow.
    for (int i : changed)
        alpha_masks_.update(scene, bvh_->triangles(), bvh_->first_triangle(i), bvh_->triangle_count(i));
    upload_bvh_changes();
    if (embree_) embree_->update(*bvh_, changed);
    bvh_depth_ = bvh_->depth();
    bvh_moved_.clear();
    bvh_alpha_.clear();
    if (work_) {
        ++work_->bvh_updates;
        work_->bvh_updated_triangles += rebuilt;
        work_->bvh_update_last_triangles = rebuilt;
        work_->bvh_update_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
}

void GpuScene::upload_bvh_changes() {
    const SceneBvh::Changes changes = bvh_->take_changes();
    const auto& nodes = bvh_->nodes();
    const auto& tris = bvh_->triangles();
    const size_t node_bytes = nodes.size() * sizeof(BvhNode);
    if (!bvh_nodes_ || changes.all_nodes || bvh_nodes_.size() < node_bytes) {
        // The whole array (its first upload, or a tree moved to its end): room for growth, so
        // that trees outgrowing their places again do not reallocate every time.
        const size_t capacity = bvh_nodes_ ? node_bytes + node_bytes / 4 : node_bytes;
        bvh_nodes_ = Buffer::create(capacity);
        if (node_bytes) bvh_nodes_.upload(nodes.data(), node_bytes);
    } else {
        for (const BvhRange& r : changes.nodes)
            if (r.count) bvh_nodes_.upload(&nodes[r.first], r.count * sizeof(BvhNode), r.first * sizeof(BvhNode));
    }
    if (!bvh_triangles_) {
        bvh_triangles_ = Buffer::create(tris.size() * sizeof(BvhTriangle), tris.data());
    } else {
        for (const BvhRange& r : changes.triangles)
            if (r.count) bvh_triangles_.upload(&tris[r.first], r.count * sizeof(BvhTriangle), r.first * sizeof(BvhTriangle));
    }
}

const EmbreeTracer& GpuScene::embree_tracer() {
    if (!ray_tracing_ready_) throw std::logic_error("embree_tracer: bind_ray_tracing first");
    if (!embree_) embree_ = std::make_unique<EmbreeTracer>(*bvh_, &alpha_masks_);
    return *embree_;
}

void GpuScene::bind_geometry() const {
    glBindVertexArray(vao_->id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kObjectsBinding, objects_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMaterialsBinding, materials_.id());
}

void GpuScene::bind_material_textures(int material) const {
    const auto& t = material_textures_[size_t(material)];
    glBindTextureUnit(material_texture_unit(0), t[0] ? t[0] : white_.id());
    glBindTextureUnit(material_texture_unit(1), t[1] ? t[1] : white_.id());
    glBindTextureUnit(material_texture_unit(2), t[2] ? t[2] : flat_normal_.id());
    if (emissive_texture_) glBindTextureUnit(material_texture_unit(3), t[3] ? t[3] : white_.id());
    if (specular_texture_) {
        glBindTextureUnit(material_texture_unit(4), t[4] ? t[4] : white_.id());
        glBindTextureUnit(material_texture_unit(5), t[5] ? t[5] : white_.id());
    }
}

bool GpuScene::has_alpha_tested() const {
    for (const DrawItem& d : draws_)
        if (alpha_tested(d.material)) return true;
    return false;
}

void GpuScene::draw_depth(GLuint prog, GLint object_loc, GLuint alpha_prog, GLint alpha_object_loc,
                          const std::vector<uint8_t>* only) const {
    GLuint current = prog;
    glUseProgram(current);
    for (const DrawItem& d : draws_) {
        if (only && !(*only)[size_t(d.object)]) continue;
        const bool alpha = alpha_tested(d.material);
        const GLuint want = alpha ? alpha_prog : prog;
        if (want != current) glUseProgram(current = want);
        glUniform1i(alpha ? alpha_object_loc : object_loc, d.object);
        if (alpha) bind_material_textures(d.material);
        glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
    }
}

}  // namespace ssr
