#include "passes/depth_peel.h"

namespace ssr {

std::vector<ResourceDesc> DepthPeelPass::outputs(const RenderSettings& s) const {
    const int w = s.width, h = s.height, l = s.layers;
    return {
        {"gbuffer.depth", GL_DEPTH_COMPONENT32F, w, h, l, 1},
        {"gbuffer.albedo", GL_SRGB8_ALPHA8, w, h, l, 1},
        {"gbuffer.normal", GL_RGBA16F, w, h, l, 1},
        {"gbuffer.material", GL_RGBA8, w, h, l, 1},
        // Layer i samples layer i-1's depth from this copy: sampling the array that is being
        // rendered into would be a feedback loop in GL's rules, even on another layer.
        {"depth_peel.previous_depth", GL_DEPTH_COMPONENT32F, w, h, 0, 1},
    };
}

void DepthPeelPass::execute(FrameContext& ctx) {
    const RenderSettings& s = ctx.settings;
    Texture& depth = ctx.resources.get("gbuffer.depth");
    Texture& albedo = ctx.resources.get("gbuffer.albedo");
    Texture& normal = ctx.resources.get("gbuffer.normal");
    Texture& material = ctx.resources.get("gbuffer.material");
    Texture& previous = ctx.resources.get("depth_peel.previous_depth");

    const GLuint prog = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, ctx.defines);
    glUseProgram(prog);
    const GLint loc_object = glGetUniformLocation(prog, "u_object");
    const GLint loc_layer = glGetUniformLocation(prog, "u_layer");

    if (!fbo_) fbo_ = Framebuffer::create();
    const GLenum draw_buffers[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glNamedFramebufferDrawBuffers(fbo_.id(), 3, draw_buffers);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, s.width, s.height);
    ctx.depth.apply_gl_state();
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    // gbuffer.albedo is sRGB storage: encode on write (and texel fetches decode on read).
    glEnable(GL_FRAMEBUFFER_SRGB);
    if (s.backface_culling) {
        glEnable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        glFrontFace(GL_CCW);
    } else {
        glDisable(GL_CULL_FACE);
    }
    ctx.gpu_scene.bind_geometry();
    glBindTextureUnit(3, previous.id());

    const float zero[4] = {0, 0, 0, 0};
    const float clear_depth = ctx.depth.clear_depth();
    while (int(queries_.size()) < s.layers) {
        GLuint q = 0;
        glGenQueries(1, &q);
        queries_.push_back(q);
    }
    used_queries_ = s.layers;
    for (int layer = 0; layer < s.layers; ++layer) {
        GpuScope timer(ctx.timer, "depth_peel.layer" + std::to_string(layer));
        if (layer > 0)
            glCopyImageSubData(depth.id(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, layer - 1, previous.id(), GL_TEXTURE_2D, 0, 0,
                               0, 0, s.width, s.height, 1);
        fbo_.attach(GL_DEPTH_ATTACHMENT, depth, 0, layer);
        fbo_.attach(GL_COLOR_ATTACHMENT0, albedo, 0, layer);
        fbo_.attach(GL_COLOR_ATTACHMENT1, normal, 0, layer);
        fbo_.attach(GL_COLOR_ATTACHMENT2, material, 0, layer);
        if (layer == 0) fbo_.check_complete("depth_peel");
        for (int i = 0; i < 3; ++i) glClearNamedFramebufferfv(fbo_.id(), GL_COLOR, i, zero);
        glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &clear_depth);
        glUniform1i(loc_layer, layer);
        // Draw only if the previous layer covered something (its query counted samples).
        if (layer > 0) glBeginConditionalRender(queries_[size_t(layer - 1)], GL_QUERY_WAIT);
        glBeginQuery(GL_SAMPLES_PASSED, queries_[size_t(layer)]);
        for (const DrawItem& d : ctx.gpu_scene.draws()) {
            glUniform1i(loc_object, d.object);
            ctx.gpu_scene.bind_material_textures(d.material);
            glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                     reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
        }
        glEndQuery(GL_SAMPLES_PASSED);
        if (layer > 0) glEndConditionalRender();
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_CULL_FACE);
    glDisable(GL_FRAMEBUFFER_SRGB);
}

void DepthPeelPass::release() {
    if (!queries_.empty()) glDeleteQueries(GLsizei(queries_.size()), queries_.data());
    queries_.clear();
    used_queries_ = 0;
    fbo_.reset();
}

std::vector<uint64_t> DepthPeelPass::layer_samples() {
    std::vector<uint64_t> out;
    for (int i = 0; i < used_queries_; ++i) {
        GLuint64 n = 0;
        glGetQueryObjectui64v(queries_[size_t(i)], GL_QUERY_RESULT, &n);
        out.push_back(n);
    }
    return out;
}

}  // namespace ssr
