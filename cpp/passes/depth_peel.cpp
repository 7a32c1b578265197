#include "passes/depth_peel.h"

#include <algorithm>
#include <vector>

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

    // Each layer is drawn twice. The depth pass rasterises the layer's depth with a
    // shader that only peels (one fetch; nothing for layer 0); the shading pass then evaluates the
    // material only where the depth test finds the depth the depth pass kept (GL_EQUAL, early
    // tests). One shader doing both ran the whole material for every fragment the peel discards
    // or the depth test rejects afterwards: llvmpipe tests depth late in a shader that may discard,
    // and deeper layers cost as much as layer 0 whatever they cover. Both programs share the
    // vertex shader, whose `invariant gl_Position` makes the two depths bit-identical.
    Defines peel_defines = ctx.defines;
    peel_defines["PEEL_DEPTH_ONLY"] = "1";
    peel_defines["PEEL_TEST"] = "0";
    const GLuint depth_first = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, peel_defines);
    peel_defines["PEEL_TEST"] = "1";
    const GLuint depth_peeled = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, peel_defines);
    // The shading pass per material kind (bit 0: textures, bit 1: auto reflectivity).
    GLuint shade[4] = {0, 0, 0, 0};
    for (const DrawItem& d : ctx.gpu_scene.draws()) {
        const int kind = ctx.gpu_scene.material_features(d.material);
        if (shade[kind]) continue;
        Defines shade_defines = ctx.defines;
        shade_defines["PEEL_DEPTH_ONLY"] = "0";
        shade_defines["MATERIAL_TEXTURES"] = kind & 1 ? "1" : "0";
        shade_defines["MATERIAL_AUTO_R"] = kind & 2 ? "1" : "0";
        shade[kind] = ctx.shaders.program({"passes/depth_peel.vert", "passes/depth_peel.frag"}, shade_defines);
    }

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
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);  // the clears below obey the write masks
    // The covered-tile flags the shading pass sets (shaders/lib/covered_tiles.glsl), cleared,
    // with the header the lighting pass's compaction counts into.
    const int tiles = covered_tiles_per_layer(s) * s.layers;
    // Flags and list per layer, then layer 0's reflective regions: dispatch arguments, flags, list.
    const size_t regions = size_t(classify_regions(s));
    const size_t tile_bytes = sizeof(GLuint) * (4 + 2 * size_t(tiles) + 4 + 2 * regions);
    if (tiles_.size() < tile_bytes) tiles_ = Buffer::create(tile_bytes);
    const GLuint header[4] = {0, 1, 1, 0};
    tiles_.upload(header, sizeof(header));
    const GLuint zero_flag = 0;
    glClearNamedBufferSubData(tiles_.id(), GL_R32UI, sizeof(header), sizeof(GLuint) * size_t(tiles), GL_RED_INTEGER,
                              GL_UNSIGNED_INT, &zero_flag);
    const GLuint region_header[4] = {0, 1, 1, 0};  // no region listed yet; a 1 x 1 dispatch layer
    glNamedBufferSubData(tiles_.id(), GLintptr(classify_regions_offset(s)), sizeof(region_header), region_header);
    glClearNamedBufferSubData(tiles_.id(), GL_R32UI, GLintptr(classify_regions_offset(s) + sizeof(region_header)),
                              sizeof(GLuint) * regions, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero_flag);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCoveredTilesBinding, tiles_.id());
    tiles_layers_ = s.layers;
    tiles_width_ = s.width;
    tiles_height_ = s.height;
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
    const bool scissor_deeper = ctx.gl.info().chosen == "cpu";
    const int grid_x = (s.width + 7) / 8, grid_y = (s.height + 7) / 8;
    std::vector<GLuint> flags(size_t(grid_x) * size_t(grid_y));
    glDisable(GL_SCISSOR_TEST);
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
        // On the CPU device, layer i > 0 rasterises only the bounding box of layer i-1's covered
        // tiles (where alone a fragment can be behind it): llvmpipe bins and runs the peel test
        // for every fragment of every triangle, so a nearly empty deep layer cost as much as the
        // first. Exact (a scissor, after the clears). Reading the flags waits for layer i-1; a GPU
        // would stall on that, so it rasterises the whole frame.
        if (layer > 0 && scissor_deeper) {
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            glGetNamedBufferSubData(tiles_.id(), GLintptr(sizeof(GLuint) * (4 + size_t(layer - 1) * flags.size())),
                                    GLsizeiptr(sizeof(GLuint) * flags.size()), flags.data());
            int x0 = grid_x, y0 = grid_y, x1 = -1, y1 = -1;
            for (int ty = 0; ty < grid_y; ++ty)
                for (int tx = 0; tx < grid_x; ++tx)
                    if (flags[size_t(ty * grid_x + tx)]) {
                        x0 = std::min(x0, tx), x1 = std::max(x1, tx);
                        y0 = std::min(y0, ty), y1 = std::max(y1, ty);
                    }
            glEnable(GL_SCISSOR_TEST);
            if (x1 < 0) glScissor(0, 0, 0, 0);
            else glScissor(x0 * 8, y0 * 8, (x1 - x0 + 1) * 8, (y1 - y0 + 1) * 8);
        }
        // Draw only if the previous layer covered something (its query counted samples).
        if (layer > 0) glBeginConditionalRender(queries_[size_t(layer - 1)], GL_QUERY_WAIT);
        // Depth pass: the samples it counts are the depth-test-passing fragments of the layer.
        const GLuint depth_prog = layer > 0 ? depth_peeled : depth_first;
        glUseProgram(depth_prog);
        const GLint loc_depth_object = glGetUniformLocation(depth_prog, "u_object");
        // No colour attachment drawn at all (a colour mask alone left llvmpipe a colour stage).
        glNamedFramebufferDrawBuffer(fbo_.id(), GL_NONE);
        glDepthMask(GL_TRUE);
        ctx.depth.apply_gl_state();
        glBeginQuery(GL_SAMPLES_PASSED, queries_[size_t(layer)]);
        for (const DrawItem& d : ctx.gpu_scene.draws()) {
            glUniform1i(loc_depth_object, d.object);
            glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                     reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
        }
        glEndQuery(GL_SAMPLES_PASSED);
        // Shading pass: only fragments at the kept depth. Of objects meeting at exactly equal
        // depth the last drawn one's colour stays, where the depth test alone kept the first:
        // the draws go in reverse order, so the same object wins (triangles within one draw
        // still go in order).
        glNamedFramebufferDrawBuffers(fbo_.id(), 3, draw_buffers);
        glDepthMask(GL_FALSE);
        glDepthFunc(GL_EQUAL);
        const auto& draws = ctx.gpu_scene.draws();
        GLuint current = 0;
        GLint loc_object = -1;
        for (auto it = draws.rbegin(); it != draws.rend(); ++it) {
            const DrawItem& d = *it;
            const int kind = ctx.gpu_scene.material_features(d.material);
            if (shade[kind] != current) {
                current = shade[kind];
                glUseProgram(current);
                loc_object = glGetUniformLocation(current, "u_object");
                glUniform1i(glGetUniformLocation(current, "u_layer"), layer);
            }
            glUniform1i(loc_object, d.object);
            if (kind & 1) ctx.gpu_scene.bind_material_textures(d.material);
            glDrawElementsBaseVertex(GL_TRIANGLES, d.index_count, GL_UNSIGNED_INT,
                                     reinterpret_cast<const void*>(d.first_index * sizeof(uint32_t)), d.base_vertex);
        }
        if (layer > 0) glEndConditionalRender();
        glDisable(GL_SCISSOR_TEST);
        glDepthMask(GL_TRUE);
        ctx.depth.apply_gl_state();
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDisable(GL_CULL_FACE);
    glDisable(GL_FRAMEBUFFER_SRGB);
    // With skip, the later per-layer passes (Hi-Z build, traces, pre-convolution,
    // pre-integration) work on the layers the peeling filled only. Reading the occlusion
    // queries waits for the peeling (the lighting pass does the same).
    if (s.skip) {
        const std::vector<uint64_t> samples = layer_samples();
        int used = 0;
        while (used < int(samples.size()) && samples[size_t(used)] > 0) ++used;
        ctx.layers_used = used;
    }
}

void DepthPeelPass::release() {
    tiles_.reset();
    tiles_layers_ = 0;
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
