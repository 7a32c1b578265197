#include "render/gpu_scene.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "render/frame_uniforms.h"
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

GpuScene::GpuScene(const Scene& scene, uint64_t* bvh_builds) : bvh_builds_(bvh_builds), revision_(scene.revision()) {
    std::vector<GpuVertex> verts;
    std::vector<uint32_t> idx;
    struct Range { size_t first_index; GLsizei count; GLint base_vertex; };
    std::vector<Range> ranges;
    for (const Mesh& m : scene.meshes) {
        Range r{idx.size(), GLsizei(m.indices.size()), GLint(verts.size())};
        for (size_t i = 0; i < m.positions.size(); ++i) {
            GpuVertex v{};
            v.position = m.positions[i];
            v.normal = m.normals[i];
            v.uv = m.uvs.empty() ? glm::vec2(0.0f) : m.uvs[i];
            v.tangent = m.tangents.empty() ? glm::vec4(0.0f) : m.tangents[i];
            v.color = m.colors.empty() ? glm::vec4(1.0f) : m.colors[i];
            v.uv1 = m.uvs1.empty() ? v.uv : m.uvs1[i];
            verts.push_back(v);
        }
        idx.insert(idx.end(), m.indices.begin(), m.indices.end());
        ranges.push_back(r);
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

    std::vector<GpuMaterial> mats;
    for (const Material& m : scene.materials) {
        GpuMaterial g{};
        g.base_color = m.base_color;
        g.params = glm::vec4(m.metallic, m.roughness, m.reflectivity, m.normal_scale);
        g.emissive = glm::vec4(m.emissive, m.visibility_cutoff());
        g.flags = glm::ivec4(m.base_color_texture.valid(), m.metallic_roughness_texture.valid(),
                             m.normal_texture.valid(), m.double_sided);
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
        mats.push_back(g);
        material_textures_.push_back({texture_for(scene, m.base_color_texture, true),
                                      texture_for(scene, m.metallic_roughness_texture, false),
                                      texture_for(scene, m.normal_texture, false),
                                      texture_for(scene, m.emissive_texture, true),
                                      texture_for(scene, m.specular_texture, false),
                                      texture_for(scene, m.specular_color_texture, true)});
        int features = m.auto_reflectivity() ? kAutoReflectivityFeature : 0;
        for (int k = 0; k < 6; ++k)
            if (refs[k]->valid()) features |= 1 << k;
        material_features_.push_back(features);
        alpha_tested_.push_back(m.visibility_cutoff() >= 0.0f);
    }
    materials_ = Buffer::create(mats.size() * sizeof(GpuMaterial), mats.data());

    std::vector<GpuObject> objs;
    for (size_t i = 0; i < scene.objects.size(); ++i) {
        const Object& o = scene.objects[i];
        GpuObject g{};
        g.model = o.transform;
        g.normal_matrix = glm::transpose(glm::inverse(o.transform));
        const Range& r = ranges[size_t(o.mesh)];
        g.material = glm::ivec4(o.material, int(r.first_index), r.base_vertex, 0);
        objs.push_back(g);
        draws_.push_back(DrawItem{int(i), o.material, r.count, r.first_index, r.base_vertex});
        triangles_ += size_t(r.count) / 3;
    }
    objects_ = Buffer::create(objs.size() * sizeof(GpuObject), objs.data());
    bounds_ = scene.bounds();
    for (const Object& o : scene.objects) reflective_ = reflective_ || scene.materials[size_t(o.material)].reflectivity != 0.0f;
    for (const Object& o : scene.objects)
        emissive_texture_ = emissive_texture_ || scene.materials[size_t(o.material)].emissive_texture.valid();
    for (const Object& o : scene.objects) {
        const Material& m = scene.materials[size_t(o.material)];
        specular_texture_ = specular_texture_ || m.specular_texture.valid() || m.specular_color_texture.valid();
    }

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
        const Bvh bvh = build_bvh(scene);
        bvh_nodes_ = Buffer::create(bvh.nodes.size() * sizeof(BvhNode), bvh.nodes.data());
        bvh_triangles_ = Buffer::create(bvh.triangles.size() * sizeof(BvhTriangle), bvh.triangles.data());
        bvh_depth_ = bvh.depth;
        bvh_triangle_list_ = bvh.triangles;
        alpha_masks_ = AlphaMasks(scene, bvh.triangles);
        std::vector<uint8_t> texels;
        std::vector<glm::ivec4> info;
        for (const Image& img : scene.images) {
            info.emplace_back(int(texels.size() / 4), img.width, img.height, 0);
            texels.insert(texels.end(), img.rgba.begin(), img.rgba.end());
        }
        image_texels_ = Buffer::create(texels.size(), texels.data());
        image_info_ = Buffer::create(info.size() * sizeof(glm::ivec4), info.data());
        ray_tracing_ready_ = true;
        if (bvh_builds_) ++*bvh_builds_;
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, bvh_nodes_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, bvh_triangles_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, image_texels_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 8, image_info_.id());
    bind_vertex_data();
}

void GpuScene::bind_vertex_data() const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 9, vertices_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 10, indices_.id());
}

const EmbreeTracer& GpuScene::embree_tracer() {
    if (!ray_tracing_ready_) throw std::logic_error("embree_tracer: bind_ray_tracing first");
    if (!embree_) embree_ = std::make_unique<EmbreeTracer>(bvh_triangle_list_, alpha_masks_);
    return *embree_;
}

void GpuScene::bind_geometry() const {
    glBindVertexArray(vao_->id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kObjectsBinding, objects_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMaterialsBinding, materials_.id());
}

void GpuScene::bind_material_textures(int material) const {
    const auto& t = material_textures_[size_t(material)];
    glBindTextureUnit(0, t[0] ? t[0] : white_.id());
    glBindTextureUnit(1, t[1] ? t[1] : white_.id());
    glBindTextureUnit(2, t[2] ? t[2] : flat_normal_.id());
    if (emissive_texture_) glBindTextureUnit(kEmissiveTextureUnit, t[3] ? t[3] : white_.id());
    if (specular_texture_) {
        glBindTextureUnit(kSpecularTextureUnit, t[4] ? t[4] : white_.id());
        glBindTextureUnit(kSpecularColorTextureUnit, t[5] ? t[5] : white_.id());
    }
}

bool GpuScene::has_alpha_tested() const {
    for (const DrawItem& d : draws_)
        if (alpha_tested(d.material)) return true;
    return false;
}

void GpuScene::draw_depth(GLuint prog, GLint object_loc, GLuint alpha_prog, GLint alpha_object_loc) const {
    GLuint current = prog;
    glUseProgram(current);
    for (const DrawItem& d : draws_) {
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
