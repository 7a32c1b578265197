#include "passes/shadow_map.h"

#include <glm/gtc/matrix_transform.hpp>

namespace ssr {

std::vector<ResourceDesc> ShadowMapPass::outputs(const RenderSettings& s) const {
    return {{"shadow_map", GL_DEPTH_COMPONENT32F, s.shadow_map_size, s.shadow_map_size, 0, 1, Lifetime::Scratch}};
}

ShadowSetup ShadowMapPass::fit(const Scene& scene, const Bounds& bounds, const RenderSettings& s) {
    ShadowSetup setup;
    if (s.shadow_map_size <= 0 || bounds.empty()) return setup;
    // The first light that casts a shadow and can have a single 2D map: a directional light
    // (orthographic) or a spot light (perspective, its cone's frustum). A point light would need
    // six faces (a cube map) and is left unshadowed.
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light::Type t = scene.lights[i].type;
        if ((t == Light::Type::Directional || t == Light::Type::Spot) && scene.lights[i].cast_shadow) {
            setup.light = int(i);
            break;
        }
    }
    if (setup.light < 0) return setup;
    const Light& light = scene.lights[size_t(setup.light)];
    const glm::vec3 dir = glm::normalize(light.direction);
    const glm::vec3 center = 0.5f * (bounds.min + bounds.max);
    const float radius = std::max(0.5f * glm::length(bounds.max - bounds.min), 1e-3f);
    const glm::vec3 up = std::abs(dir.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    if (light.type == Light::Type::Spot) {
        // A perspective frustum around the outer cone (nothing outside it is lit), its depth range
        // the part of the scene's bounding sphere in front of the light. glm's default (OpenGL)
        // clip conventions: z_ndc in [-1, 1], as the pass draws it; the lookup divides by w.
        const float half = std::min(light.outer_cone, glm::radians(85.0f));
        const float dist = glm::length(center - light.position);
        const float far_plane = std::max(dist + radius, 1e-3f * radius + 1e-4f);
        // The near plane as far out as the scene allows: depth precision is spent in front of it.
        const float near_plane = std::max(dist - radius, far_plane * 1e-4f);
        const glm::mat4 view = glm::lookAt(light.position, light.position + dir, up);
        const glm::mat4 proj = glm::perspective(2.0f * half, 1.0f, near_plane, far_plane);
        setup.enabled = true;
        setup.light_view_proj = proj * view;
        // A texel's world size at the scene's centre, for the receiver's normal offset.
        setup.texel_world_size = 2.0f * std::max(dist, near_plane) * std::tan(half) / float(s.shadow_map_size);
        return setup;
    }
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
    // Alpha-tested materials (glTF MASK/BLEND) with a fragment stage that discards their holes.
    GLuint alpha_prog = 0;
    GLint loc_alpha_object = -1;
    for (const DrawItem& d : ctx.gpu_scene.draws())
        if (ctx.gpu_scene.alpha_tested(d.material)) {
            alpha_prog = ctx.shaders.program({"passes/shadow_map.vert", "passes/shadow_map.frag"}, ctx.defines);
            glUseProgram(alpha_prog);
            glUniformMatrix4fv(glGetUniformLocation(alpha_prog, "u_light_view_proj"), 1, GL_FALSE,
                               &setup_.light_view_proj[0][0]);
            loc_alpha_object = glGetUniformLocation(alpha_prog, "u_object");
            glUseProgram(prog);
            break;
        }

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
    GLuint current = prog;
    for (const DrawItem& d : ctx.gpu_scene.draws()) {
        const bool alpha = ctx.gpu_scene.alpha_tested(d.material);
        const GLuint want = alpha ? alpha_prog : prog;
        if (want != current) glUseProgram(current = want);
        glUniform1i(alpha ? loc_alpha_object : loc_object, d.object);
        if (alpha) ctx.gpu_scene.bind_material_textures(d.material);
        glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace ssr
