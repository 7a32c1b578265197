#include "passes/shadow_map.h"

#include "render/pass_registry.h"
#include "passes/compute.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace ssr {

std::vector<ResourceDesc> ShadowMapPass::outputs(const RenderSettings& s) const {
    FrameFacts f;
    f.shadow_maps = f.shadow_cubes = 1;
    return outputs(s, f);
}

std::vector<ResourceDesc> ShadowMapPass::outputs(const RenderSettings& s, const FrameFacts& f) const {
    const int n = s.shadow_map_size;
    std::vector<ResourceDesc> out;
    if (f.shadow_maps > 0) out.push_back({"shadow_map", GL_DEPTH_COMPONENT32F, n, n, f.shadow_maps, 1, Lifetime::Scratch});
    if (f.shadow_cubes > 0)
        out.push_back({"shadow_cubes", GL_DEPTH_COMPONENT32F, n, n, 6 * f.shadow_cubes, 1, Lifetime::Scratch, true});
    return out;
}

std::vector<std::string> ShadowMapPass::reads(const FrameFacts& f) {
    std::vector<std::string> in;
    if (f.shadow_maps > 0) in.push_back("shadow_map");
    if (f.shadow_cubes > 0) in.push_back("shadow_cubes");
    return in;
}

void ShadowMapPass::add_defines(Defines& d, const FrameFacts& f) {
    d["SHADOW_MAPS"] = f.shadow_maps > 0 ? "1" : "0";
    d["SHADOW_CUBES"] = f.shadow_cubes > 0 ? "1" : "0";
}

ShadowSetup ShadowMapPass::fit(const Scene& scene, const Bounds& bounds, const RenderSettings& s) {
    ShadowSetup setup;
    if (s.shadow_map_size <= 0 || bounds.empty()) return setup;
    const glm::vec3 center = 0.5f * (bounds.min + bounds.max);
    const float radius = std::max(0.5f * glm::length(bounds.max - bounds.min), 1e-3f);
    // Every light that casts a shadow: a directional or spot light a layer of the 2D array, a
    // point light a cube (what it sees in every direction).
    for (size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& light = scene.lights[i];
        if (!light.cast_shadow) continue;
        ShadowCaster c;
        c.light = int(i);
        if (light.type == Light::Type::Point) {
            c.cube = true;
            c.slot = setup.cubes++;
            c.position = light.position;
            // Six 90-degree faces whose depth range holds the scene's bounding sphere as seen from
            // the light; the near plane as far out as the scene allows (depth precision is spent
            // in front of it), but a light inside the scene sees geometry close by.
            const float dist = glm::length(center - light.position);
            c.far_plane = std::max(dist + radius, 1e-3f * radius + 1e-4f);
            c.near_plane = std::max(dist - radius, c.far_plane * 1e-3f);
            setup.casters.push_back(c);
            continue;
        }
        c.slot = setup.maps++;
        const glm::vec3 dir = glm::normalize(light.direction);
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
            c.light_view_proj = proj * view;
            // A texel's world size at the scene's centre, for the receiver's normal offset.
            c.texel_world_size = 2.0f * std::max(dist, near_plane) * std::tan(half) / float(s.shadow_map_size);
        } else {
            const glm::mat4 view = glm::lookAt(center - dir * (2.0f * radius), center, up);
            // glm::ortho with GLM's default (OpenGL) clip conventions: z_ndc in [-1, 1].
            const glm::mat4 proj = glm::ortho(-radius, radius, -radius, radius, radius * 0.5f, radius * 3.5f);
            c.light_view_proj = proj * view;
            c.texel_world_size = 2.0f * radius / float(s.shadow_map_size);
        }
        if (setup.light < 0) {
            setup.light = c.light;
            setup.light_view_proj = c.light_view_proj;
            setup.texel_world_size = c.texel_world_size;
        }
        setup.casters.push_back(c);
    }
    setup.enabled = !setup.casters.empty();
    return setup;
}

namespace {
// A cube face's view from `eye`: GL's face order (+X, -X, +Y, -Y, +Z, -Z) and, per face, the up
// vector that makes the rendered image the face as a lookup by direction reads it (the GL
// specification's cube-map face table: each face's t axis points down for the side faces, so
// the side faces are rendered with -Y up, the top and bottom with +Z and -Z).
glm::mat4 cube_face_view(const glm::vec3& eye, int face) {
    static const glm::vec3 axis[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const glm::vec3 up[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    return glm::lookAt(eye, eye + axis[face], up[face]);
}
}  // namespace

void ShadowMapPass::draw_scene(FrameContext& ctx, const glm::mat4& light_view_proj, GLuint prog, GLint loc_vp,
                               GLint loc_object, GLuint alpha_prog, GLint loc_alpha_vp, GLint loc_alpha_object,
                               const std::vector<uint8_t>* only) {
    const float one = 1.0f;
    glClearNamedFramebufferfv(fbo_.id(), GL_DEPTH, 0, &one);
    glUseProgram(prog);
    glUniformMatrix4fv(loc_vp, 1, GL_FALSE, &light_view_proj[0][0]);
    if (alpha_prog) {
        glUseProgram(alpha_prog);
        glUniformMatrix4fv(loc_alpha_vp, 1, GL_FALSE, &light_view_proj[0][0]);
        glUseProgram(prog);
    }
    ctx.gpu_scene.draw_depth(prog, loc_object, alpha_prog, loc_alpha_object, only);
}

void ShadowMapPass::begin_frame() {
    maps_at_start_ = maps_;
    cubes_at_start_ = cubes_;
}

void ShadowMapPass::report(const RenderSettings&, std::map<std::string, double>& stats) const {
    stats["shadow_maps_reused"] = double(reused_);
    stats["shadow_maps_updated"] = double(updated_);
    stats["shadow_maps_rendered"] = double(rendered_);
}

uint64_t ShadowMapPass::frustum_key(const ShadowCaster& c, int size) {
    // FNV-1a over what decides where a slot's texels look: the map's size and the frustum (a
    // layer's matrix; a cube's position and depth range). The light's colour, intensity and
    // range and the receivers' settings (PCF, normal offset) change nothing a map stores.
    uint64_t h = 1469598103934665603ull;
    auto bytes = [&h](const void* p, size_t n) {
        const auto* b = static_cast<const unsigned char*>(p);
        for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    };
    bytes(&size, sizeof size);
    const int cube = c.cube ? 1 : 0;
    bytes(&cube, sizeof cube);
    if (c.cube) {
        bytes(&c.position, sizeof c.position);
        bytes(&c.near_plane, sizeof c.near_plane);
        bytes(&c.far_plane, sizeof c.far_plane);
    } else {
        bytes(&c.light_view_proj, sizeof c.light_view_proj);
    }
    return h ? h : 1;
}

namespace {
// The texels of a size x size view through `vp` that a world box can cover: the bounding
// rectangle of its corners' projections, widened by a texel for rasterisation (a box with a
// corner behind the light's eye: the whole view). Returns false when it covers none.
struct TexelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
    bool empty() const { return x1 <= x0 || y1 <= y0; }
};
TexelRect texel_rect(const glm::mat4& vp, const Bounds& b, int size) {
    TexelRect r;
    if (b.empty()) return r;
    float lo_x = 1e30f, lo_y = 1e30f, hi_x = -1e30f, hi_y = -1e30f;
    for (int k = 0; k < 8; ++k) {
        const glm::vec3 corner((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 4) ? b.max.z : b.min.z);
        const glm::vec4 clip = vp * glm::vec4(corner, 1.0f);
        if (!(clip.w > 1e-6f)) return TexelRect{0, 0, size, size};
        const float x = (clip.x / clip.w * 0.5f + 0.5f) * float(size), y = (clip.y / clip.w * 0.5f + 0.5f) * float(size);
        lo_x = std::min(lo_x, x);
        lo_y = std::min(lo_y, y);
        hi_x = std::max(hi_x, x);
        hi_y = std::max(hi_y, y);
    }
    auto clamp = [size](float v) { return int(std::clamp(v, 0.0f, float(size))); };
    r.x0 = clamp(std::floor(lo_x) - 1.0f);
    r.y0 = clamp(std::floor(lo_y) - 1.0f);
    r.x1 = clamp(std::ceil(hi_x) + 1.0f);
    r.y1 = clamp(std::ceil(hi_y) + 1.0f);
    return r;
}
bool overlap(const TexelRect& a, const TexelRect& b) {
    return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}
}  // namespace

void ShadowMapPass::execute(FrameContext& ctx) {
    Texture* map = setup_.maps > 0 ? &ctx.resources.get("shadow_map") : nullptr;
    Texture* cubes = setup_.cubes > 0 ? &ctx.resources.get("shadow_cubes") : nullptr;
    const GpuScene& gs = ctx.gpu_scene;
    // What each slot holds, in this texture allocation (a replaced texture holds nothing known).
    auto track = [&ctx](Held& held, const char* name, int slots) {
        const uint64_t generation = ctx.resources.has(name) ? ctx.resources.generation(name) : 0;
        if (held.generation != generation) held = Held{generation, {}};
        held.slots.resize(size_t(slots));
    };
    track(maps_, "shadow_map", setup_.maps);
    track(cubes_, "shadow_cubes", setup_.cubes);
    reused_ = updated_ = rendered_ = 0;
    // Hardware PCF: a compare sampler with linear filtering gives a 2x2 filtered test per tap.
    // The cubes compare the point's depth in the face its direction selects (lib/shadow_map.glsl):
    // the same vertex-only program as the layers (a distance written as gl_FragDepth would give
    // every opaque draw a fragment stage and lose early depth), the same slope-scaled bias, and
    // hardware compare filtering as for the layers.
    for (Texture* t : {map, cubes}) {
        if (!t) continue;
        glTextureParameteri(t->id(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
        glTextureParameteri(t->id(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
        t->set_filter(GL_LINEAR, GL_LINEAR);
    }
    if (!fbo_) fbo_ = Framebuffer::create();
    glNamedFramebufferDrawBuffer(fbo_.id(), GL_NONE);

    const GLuint prog = ctx.shaders.program({"passes/shadow_map.vert"}, ctx.defines);
    const GLint loc_vp = glGetUniformLocation(prog, "u_light_view_proj");
    const GLint loc_object = glGetUniformLocation(prog, "u_object");
    // Alpha-tested materials (glTF MASK/BLEND) with a fragment stage that discards their holes.
    GLuint alpha_prog = 0;
    GLint loc_alpha_vp = -1, loc_alpha_object = -1;
    if (gs.has_alpha_tested()) {
        // The base colour's alpha, by name at the unit GpuScene binds it to.
        NamedUnits units;
        units.placed_textures = GpuScene::material_texture_units();
        Defines d = ctx.defines;
        units.add_unit_defines(d);
        alpha_prog = ctx.shaders.program({"passes/shadow_map.vert", "passes/shadow_map.frag"}, d);
        units.check(alpha_prog, "passes/shadow_map.frag");
        loc_alpha_vp = glGetUniformLocation(alpha_prog, "u_light_view_proj");
        loc_alpha_object = glGetUniformLocation(alpha_prog, "u_object");
    }

    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.id());
    // The lights' depth uses GL's standard convention whatever the camera's.
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);  // thin and open geometry must cast shadows too
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);  // slope-scaled bias, complementing the receiver's normal offset
    gs.bind_geometry();
    std::vector<Bounds> regions;
    std::vector<uint8_t> drawn(gs.draws().size());
    for (const ShadowCaster& c : setup_.casters) {
        Texture& t = c.cube ? *cubes : *map;
        Held& held = c.cube ? cubes_ : maps_;
        const int size = t.width();
        const Slot want{frustum_key(c, size), gs.caster_state()};
        // What the slot held as the frame began (so that the timed run draws what the untimed
        // first-use run drew): the same allocation, the same frustum, the scene's casters then.
        const Held& start = c.cube ? cubes_at_start_ : maps_at_start_;
        const Slot was = start.generation == held.generation && size_t(c.slot) < start.slots.size()
                             ? start.slots[size_t(c.slot)]
                             : Slot{};
        if (was.frustum == want.frustum && was.state == want.state) {
            ++reused_;
            continue;
        }
        // The same frustum and a scene whose changes since are known (moved objects, alpha tests):
        // only the texels those changes can reach are cleared and drawn again, by the objects that
        // reach them. Depth testing keeps the nearest fragment whatever the draw order, and each
        // fragment's depth and bias are its own triangle's, so those texels get the very values
        // a full redraw writes and the others hold them already.
        const bool partial = was.frustum == want.frustum && gs.caster_changes_since(was.state, regions);
        held.slots[size_t(c.slot)] = Slot{};  // unknown until drawn
        glViewport(0, 0, size, size);
        // A layer: one view. A cube: its six faces, layer-faces 6 slot + face of the array, each
        // a 90-degree square frustum from the light.
        const int faces = c.cube ? 6 : 1;
        const glm::mat4 face_proj = glm::perspective(glm::radians(90.0f), 1.0f, c.near_plane, c.far_plane);
        bool any = false;
        for (int face = 0; face < faces; ++face) {
            const glm::mat4 vp = c.cube ? face_proj * cube_face_view(c.position, face) : c.light_view_proj;
            TexelRect rect;
            if (partial) {
                for (const Bounds& b : regions) {
                    const TexelRect r = texel_rect(vp, b, size);
                    if (r.empty()) continue;
                    rect = rect.empty() ? r
                                        : TexelRect{std::min(rect.x0, r.x0), std::min(rect.y0, r.y0),
                                                    std::max(rect.x1, r.x1), std::max(rect.y1, r.y1)};
                }
                if (rect.empty()) continue;  // nothing that changed reaches this face
                for (size_t i = 0; i < drawn.size(); ++i)
                    drawn[i] = overlap(rect, texel_rect(vp, gs.world_bounds(int(i)), size)) ? 1 : 0;
            }
            any = true;
            fbo_.attach(GL_DEPTH_ATTACHMENT, t, 0, c.cube ? 6 * c.slot + face : c.slot);
            fbo_.check_complete("shadow_map");
            if (partial) {
                glEnable(GL_SCISSOR_TEST);  // the clear and the draws stay inside the rectangle
                glScissor(rect.x0, rect.y0, rect.x1 - rect.x0, rect.y1 - rect.y0);
            }
            draw_scene(ctx, vp, prog, loc_vp, loc_object, alpha_prog, loc_alpha_vp, loc_alpha_object,
                       partial ? &drawn : nullptr);
            if (partial) glDisable(GL_SCISSOR_TEST);
        }
        held.slots[size_t(c.slot)] = want;
        if (!partial) ++rendered_;
        else if (any) ++updated_;
        else ++reused_;  // nothing that changed is seen by this light
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

SSR_REGISTER_PASS(ShadowMapPass());

}  // namespace ssr
