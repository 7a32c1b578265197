#include "passes/shadow_map.h"

#include <glm/gtc/matrix_transform.hpp>

namespace ssr {

std::vector<ResourceDesc> ShadowMapPass::outputs(const RenderSettings& s) const {
    return {{"shadow_map", GL_DEPTH_COMPONENT32F, s.shadow_map_size, s.shadow_map_size, 0, 1, Lifetime::Scratch}};
}

ShadowSetup ShadowMapPass::fit(const Scene& scene, const Bounds& bounds, const RenderSettings& s) {
    ShadowSetup setup;
    if (s.shadow_map_size <= 0 || bounds.empty()) return setup;
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        if (scene.lights[i].type == Light::Type::Directional && scene.lights[i].cast_shadow) {
            setup.light = int(i);
            break;
        }
    }
    if (setup.light < 0) return setup;
    const glm::vec3 dir = glm::normalize(scene.lights[size_t(setup.light)].direction);
    const glm::vec3 center = 0.5f * (bounds.min + bounds.max);
    const float radius = std::max(0.5f * glm::length(bounds.max - bounds.min), 1e-3f);
    const glm::vec3 up = std::abs(dir.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    const glm::mat4 view = glm::lookAt(center - dir * (2.0f * radius), center, up);
    // glm::ortho with GLM's default (OpenGL) clip conventions: z_ndc in [-1, 1].
    const glm::mat4 proj = glm::ortho(-radius, radius, -radius, radius, radius * 0.5f, radius * 3.5f);
    setup.enabled = true;
    setup.light_view_proj = proj * view;
    setup.texel_world_size = 2.0f * radius / float(s.shadow_map_size);
    return setup;
}

void ShadowMapPass::execute(FrameContext& ctx) {
    Texture& map = ctx.resources.get("shadow_map");
    // Hardware PCF: a compare sampler with linear filtering gives a 2x2 filtered test per tap.
    glTextureParameteri(map.id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(map.id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    map.set_filter(GL_LINEAR, GL_LINEAR);
    if (!fbo_) fbo_ = Framebuffer::create();
    fbo_.attach(GL_DEPTH_ATTACHMENT, map);
    glNamedFramebufferDrawBuffer(fbo_.id(), GL_NONE);
    fbo_.check_complete("shadow_map");

    const GLuint prog = ctx.shaders.program({"passes/shadow_map.vert"}, ctx.defines);
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "u_light_view_proj"), 1, GL_FALSE, &setup_.light_view_proj[0][0]);
    const GLint loc_object = glGetUniformLocation(prog, "u_object");

    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    glViewport(0, 0, map.width(), map.height());
    // The light's orthographic depth uses GL's standard convention whatever the camera's.
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);  // thin and open geometry must cast shadows too
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);  // slope-scaled bias, complementing the receiver's normal offset
    const float one = 1.0f;
    glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &one);

    ctx.gpu_scene.bind_geometry();
    for (const DrawItem& d : ctx.gpu_scene.draws()) {
        glUniform1i(loc_object, d.object);
        glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace ssr
