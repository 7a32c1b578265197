#include "passes/reference.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

#include "passes/compute.h"
#include "passes/depth_peel.h"
#include "passes/shadow_map.h"
#include "passes/reference_cpu.h"

namespace ssr {

namespace {
// Rays per dispatch: about a million, so no single dispatch runs for long on any device.
constexpr long long kRaysPerDispatch = 1 << 20;
}  // namespace

std::vector<std::string> ReferencePass::inputs(const RenderSettings& s, const FrameFacts& f) const {
    std::vector<std::string> in = {"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"};
    if (per_ray_) {
        in.push_back("rays.direction");
        in.push_back("rays.sample");
    }
    if (shadows_ && !traced_shadows_)
        for (const auto& t : ShadowMapPass::reads(f)) in.push_back(t);
    // The pixel's own direct light adds its G-buffer emission (lib/gbuffer_emission.glsl).
    if (!per_ray_ && f.emission_texture) in.push_back("gbuffer.emission");
    if (!per_ray_ && f.specular_texture) in.push_back("gbuffer.specular");  // its F0 (lib/gbuffer_specular.glsl)
    return in;
}

std::vector<ResourceDesc> ReferencePass::outputs(const RenderSettings& s) const {
    if (per_ray_) {
        const int w = s.trace_width(), h = s.trace_height(), r = s.traced_rays();
        return {{"reference.hit", GL_RGBA32F, w, h, r, 1},
                {"reference.position", GL_RGBA32F, w, h, r, 1},
                {"reference.radiance", GL_RGBA32F, w, h, r, 1}};
    }
    return {{"reference.accum", GL_RGBA32F, s.width, s.height, 0, 1},
            {"reference.reflection", GL_RGBA32F, s.width, s.height, 0, 1},
            {"reference.direct", GL_RGBA32F, s.width, s.height, 1, 1}};
}

NamedUnits ReferencePass::units(const FrameContext& ctx) const {
    NamedUnits u{{"linear_depth", "gbuffer.albedo", "gbuffer.normal", "gbuffer.material"}, {}};
    const bool cpu = cpu_tracer_ && !per_ray_;  // reference_gbuffer.comp: the G-buffer decoded only
    if (!cpu && shadows_ && !traced_shadows_)
        for (const auto& m : ShadowMapPass::reads(ctx.facts)) u.textures.push_back(m);
    if (!per_ray_ && ctx.facts.emission_texture) u.textures.push_back("gbuffer.emission");
    if (!per_ray_ && ctx.facts.specular_texture) u.textures.push_back("gbuffer.specular");
    if (cpu) return u;
    if (per_ray_) {
        u.textures.insert(u.textures.end(), {"rays.direction", "rays.sample"});
        u.images = {{"reference.hit", GL_WRITE_ONLY}, {"reference.position", GL_WRITE_ONLY},
                    {"reference.radiance", GL_WRITE_ONLY}};
    } else {
        u.images = {{"reference.accum", GL_READ_WRITE}, {"reference.reflection", GL_WRITE_ONLY},
                    {"reference.direct", GL_WRITE_ONLY}};
    }
    return u;
}

GLuint ReferencePass::program(FrameContext& ctx) const {
    const NamedUnits u = units(ctx);
    Defines d = ctx.defines;
    u.add_unit_defines(d);
    d["MODE"] = per_ray_ ? "0" : "1";
    d["SHADOWS"] = shadows_ && !traced_shadows_ ? "1" : "0";
    d["TRACED_SHADOWS"] = shadows_ && traced_shadows_ ? "1" : "0";
    ShadowMapPass::add_defines(d, ctx.facts);
    d["EXTERNAL_TRACE"] = tracer_ && !per_ray_ ? "1" : "0";
    if (!per_ray_ && ctx.facts.emission_texture) d["EMISSION_TEXTURE"] = "1";
    if (!per_ray_ && ctx.facts.specular_texture) d["SPECULAR_TEXTURE"] = "1";
    if (cpu_tracer_ && !per_ray_) {
        Defines g = ctx.defines;
        u.add_unit_defines(g);
        if (ctx.facts.emission_texture) g["EMISSION_TEXTURE"] = "1";
        if (ctx.facts.specular_texture) g["SPECULAR_TEXTURE"] = "1";
        return ctx.shaders.program({"passes/reference_gbuffer.comp"}, g);
    }
    return ctx.shaders.program({"passes/reference.comp"}, d);
}

void ReferencePass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    const GLuint prog = program(ctx);
    glUseProgram(prog);
    units(ctx).bind_by_name(r, prog, cpu_tracer_ && !per_ray_ ? "passes/reference_gbuffer.comp" : "passes/reference.comp");
    if (cpu_tracer_ && !per_ray_) {
        execute_cpu(ctx, prog);
        return;
    }
    const GLint loc_first = glGetUniformLocation(prog, "u_first_ray");
    const GLint loc_count = glGetUniformLocation(prog, "u_ray_count");
    const GLint loc_last = glGetUniformLocation(prog, "u_last");
    glUniform1i(glGetUniformLocation(prog, "u_viewer"), viewer_is_ray_ ? 1 : 0);
    const RenderSettings& s = ctx.settings;
    if (per_ray_) {
        const long long per_ray = (long long)s.trace_width() * s.trace_height();
        const int chunk = int(std::max(1LL, std::min<long long>(s.traced_rays(), kRaysPerDispatch / per_ray)));
        for (int first = 0; first < s.traced_rays(); first += chunk) {
            const int count = std::min(chunk, s.traced_rays() - first);
            glUniform1i(loc_first, first);
            glUniform1i(loc_count, count);
            glUniform1i(loc_last, first + count >= s.traced_rays());
            dispatch_2d(s.trace_width(), s.trace_height(), count, 8, 8);
        }
    } else {
        if (tracer_) {
            execute_wavefront(ctx, prog);
            return;
        }
        const long long per_ray = (long long)s.width * s.height;
        const int chunk = int(std::max(1LL, std::min<long long>(rays_, kRaysPerDispatch / per_ray)));
        for (int first = 0; first < rays_; first += chunk) {
            const int count = std::min(chunk, rays_ - first);
            glUniform1i(loc_first, first);
            glUniform1i(loc_count, count);
            glUniform1i(loc_last, first + count >= rays_);
            dispatch_2d(s.width, s.height, 1, 8, 8);
            if (progress_ && !progress_(first + count, rays_)) {
                completed_ = false;
                return;
            }
        }
    }
}

// The converged reference with its rays traced by Embree (lib/trace_external.glsl): dispatches of
// kBatch ray indices (the GLSL loop's iterations, so each pixel draws the same rays from the same
// RNG streams), each run in phases until no invocation has a ray left to trace. A phase traces the
// next ray of every chain at once (each reflection ray and its shadow rays are one chain). Chain
// 0, the camera ray through the pixel centre, is traced once, first, and answered ever after.
void ReferencePass::execute_wavefront(FrameContext& ctx, GLuint prog) {
    using clock = std::chrono::steady_clock;
    auto ms = [](clock::time_point a, clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    const RenderSettings& s = ctx.settings;
    const size_t n = size_t(s.width) * size_t(s.height);
    // Rays per dispatch: the pixel's set-up (G-buffer, exact point) runs once per phase for all of
    // them; more chains cost read-back bandwidth (48 bytes per chain and pixel per phase).
    constexpr int kBatch = 8;
    // A runaway replay (a shader making ever more queries) stops here instead of growing forever.
    constexpr int kMaxQueries = 256;
    const int batch = std::min(rays_, kBatch), chains = batch + 2;
    const size_t cn = size_t(chains) * n;
    Buffer queries = Buffer::create(cn * sizeof(TraceQuery));
    int slots = 3;
    Buffer answers = Buffer::create(cn * sizeof(TraceAnswer) * size_t(slots));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTraceQueriesBinding, queries.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTraceAnswersBinding, answers.id());
    const GLint loc_known = glGetUniformLocation(prog, "u_trace_known");
    const GLint loc_known0 = glGetUniformLocation(prog, "u_trace_known0");
    glUniform1i(glGetUniformLocation(prog, "u_trace_stride"), int(n));
    glUniform1i(glGetUniformLocation(prog, "u_trace_chains"), chains);
    const GLint loc_first = glGetUniformLocation(prog, "u_first_ray");
    const GLint loc_count = glGetUniformLocation(prog, "u_ray_count");
    const GLint loc_last = glGetUniformLocation(prog, "u_last");
    std::vector<TraceQuery> q(cn);
    std::vector<TraceAnswer> a(cn);
    double shade = 0.0, intersect = 0.0, transfer = 0.0, traced = 0.0;
    // One phase: dispatch, read back chains [c0, chains), trace them; false when none asked.
    auto phase = [&](size_t c0) {
        const auto t0 = clock::now();
        dispatch_2d(s.width, s.height, 1, 8, 8);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glFinish();
        const auto t1 = clock::now();
        const size_t m = (c0 == 0 ? 1 : size_t(chains) - c0) * n;
        glGetNamedBufferSubData(queries.id(), GLintptr(c0 * n * sizeof(TraceQuery)), GLsizeiptr(m * sizeof(TraceQuery)),
                                q.data() + c0 * n);
        size_t active = 0;
        for (size_t i = c0 * n; i < c0 * n + m; ++i) active += q[i].kind != 0;
        const auto t2 = clock::now();
        shade += ms(t0, t1);
        transfer += ms(t1, t2);
        if (active == 0) return size_t(0);
        tracer_->trace(q.data() + c0 * n, m, a.data() + c0 * n);
        intersect += ms(t2, clock::now());
        traced += double(active);
        return m;
    };
    bool primary = false;
    for (int first = 0; first < rays_; first += batch) {
        const int count = std::min(batch, rays_ - first);
        glUniform1i(loc_first, first);
        glUniform1i(loc_count, count);
        glUniform1i(loc_last, first + count >= rays_ ? 1 : 0);
        if (!primary) {  // chain 0 alone: every other chain starts from its hit
            glUniform1i(loc_known0, 0);
            glUniform1i(loc_known, 0);
            if (phase(0)) {
                const auto t = clock::now();
                glNamedBufferSubData(answers.id(), 0, GLsizeiptr(n * sizeof(TraceAnswer)), a.data());
                transfer += ms(t, clock::now());
            }
            primary = true;
            glUniform1i(loc_known0, 1);
        }
        for (int known = 0;; ++known) {
            if (known >= kMaxQueries)
                throw std::runtime_error("reference: a pixel asked for more than " + std::to_string(kMaxQueries) +
                                         " rays in one chain");
            glUniform1i(loc_known, known);
            const size_t m = phase(1);
            if (m == 0) break;
            const auto t3 = clock::now();
            if (known >= slots) {  // room for more answers: keep the earlier slots
                Buffer grown = Buffer::create(answers.size() * 2);
                glCopyNamedBufferSubData(answers.id(), grown.id(), 0, 0, GLsizeiptr(answers.size()));
                answers = std::move(grown);
                slots *= 2;
                glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTraceAnswersBinding, answers.id());
            }
            // Slot `known` of chains 1.. (chain 0's answer in slot 0 stays).
            glNamedBufferSubData(answers.id(), GLintptr((size_t(known) * cn + n) * sizeof(TraceAnswer)),
                                 GLsizeiptr(m * sizeof(TraceAnswer)), a.data() + n);
            transfer += ms(t3, clock::now());
        }
        if (progress_ && !progress_(first + count, rays_)) {
            completed_ = false;
            break;
        }
    }
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    stage_ms_ = {{"reference.shade", shade},
                 {"reference.intersect", intersect},
                 {"reference.transfer", transfer},
                 {"reference.rays_traced", traced}};
}

namespace {
template <class T>
std::vector<T> read_bound_buffer(GLenum target, GLuint index) {
    GLint id = 0;
    glGetIntegeri_v(target == GL_UNIFORM_BUFFER ? GL_UNIFORM_BUFFER_BINDING : GL_SHADER_STORAGE_BUFFER_BINDING, index,
                    &id);
    if (id == 0) return {};
    GLint64 bytes = 0;
    glGetNamedBufferParameteri64v(GLuint(id), GL_BUFFER_SIZE, &bytes);
    std::vector<T> v(size_t(bytes) / sizeof(T));
    if (!v.empty()) glGetNamedBufferSubData(GLuint(id), 0, GLsizeiptr(v.size() * sizeof(T)), v.data());
    return v;
}
}  // namespace

// The converged reference on the CPU (passes/reference_cpu.h): the GLSL decodes the G-buffer,
// the host copies of what the reference shader reads come from the very buffers the renderer
// bound for it (objects, materials, lights, BVH triangles, vertices, indices, images), and the
// outputs are uploaded into reference.accum / .reflection / .direct for the composite.
void ReferencePass::execute_cpu(FrameContext& ctx, GLuint prog) {
    using clock = std::chrono::steady_clock;
    auto ms = [](clock::time_point a, clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    const RenderSettings& s = ctx.settings;
    const size_t n = size_t(s.width) * size_t(s.height);
    const auto t0 = clock::now();
    // With an emissive texture, each pixel's gbuffer.emission follows the decoded samples.
    const bool emission_texture = ctx.facts.emission_texture;
    // With a specular texture, each pixel's gbuffer.specular follows them (reference_gbuffer.comp).
    const bool specular_texture = ctx.facts.specular_texture;
    const size_t extra = (emission_texture ? 1 : 0) + (specular_texture ? 1 : 0);
    Buffer decoded = Buffer::create(n * (sizeof(CpuGbufferTexel) + extra * sizeof(glm::vec4)));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kDecodedBinding, decoded.id());
    dispatch_2d(s.width, s.height, 1, 8, 8);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<CpuGbufferTexel> gbuffer(n);
    glGetNamedBufferSubData(decoded.id(), 0, GLsizeiptr(n * sizeof(CpuGbufferTexel)), gbuffer.data());
    std::vector<glm::vec4> emission;
    if (emission_texture) {
        emission.resize(n);
        glGetNamedBufferSubData(decoded.id(), GLintptr(n * sizeof(CpuGbufferTexel)), GLsizeiptr(n * sizeof(glm::vec4)),
                                emission.data());
    }
    std::vector<glm::vec4> dielectric_f0;
    if (specular_texture) {
        dielectric_f0.resize(n);
        const size_t at = n * (sizeof(CpuGbufferTexel) + (emission_texture ? sizeof(glm::vec4) : 0));
        glGetNamedBufferSubData(decoded.id(), GLintptr(at), GLsizeiptr(n * sizeof(glm::vec4)), dielectric_f0.data());
    }

    CpuReferenceScene scene;
    scene.frame = ctx.uniforms;
    const auto ssr = read_bound_buffer<SsrUniforms>(GL_UNIFORM_BUFFER, kSsrSettingsBinding);
    if (ssr.empty()) throw std::logic_error("reference (cpu): no settings block bound");
    scene.ssr = ssr[0];
    scene.lights = read_bound_buffer<GpuLight>(GL_SHADER_STORAGE_BUFFER, kLightsBinding);
    scene.lights.resize(ctx.scene.lights.size());  // (the buffer keeps room for one when there are none)
    scene.objects = read_bound_buffer<GpuObject>(GL_SHADER_STORAGE_BUFFER, kObjectsBinding);
    scene.materials = read_bound_buffer<GpuMaterial>(GL_SHADER_STORAGE_BUFFER, kMaterialsBinding);
    scene.triangles = read_bound_buffer<BvhTriangle>(GL_SHADER_STORAGE_BUFFER, kBvhTrianglesBinding);
    scene.image_texels = read_bound_buffer<uint32_t>(GL_SHADER_STORAGE_BUFFER, kImageTexelsBinding);
    scene.image_info = read_bound_buffer<glm::ivec4>(GL_SHADER_STORAGE_BUFFER, kImageInfoBinding);
    scene.vertex_data = read_bound_buffer<float>(GL_SHADER_STORAGE_BUFFER, kVertexDataBinding);
    scene.index_data = read_bound_buffer<uint32_t>(GL_SHADER_STORAGE_BUFFER, kIndexDataBinding);
    scene.environment_type = environment_type_;
    if (environment_map_) {
        GLint w = 0, h = 0;
        glGetTextureLevelParameteriv(environment_map_, 0, GL_TEXTURE_WIDTH, &w);
        glGetTextureLevelParameteriv(environment_map_, 0, GL_TEXTURE_HEIGHT, &h);
        scene.environment_map.resize(size_t(w) * size_t(h));
        glGetTextureImage(environment_map_, 0, GL_RGBA, GL_FLOAT, GLsizei(scene.environment_map.size() * sizeof(glm::vec4)),
                          scene.environment_map.data());
        scene.environment_width = w;
        scene.environment_height = h;
    }
    scene.viewer_is_ray = viewer_is_ray_;
    scene.tracer = cpu_tracer_;
    const auto t1 = clock::now();

    CpuReference ref(scene, s.width, s.height, std::move(gbuffer), std::move(emission), std::move(dielectric_f0));
    ref.begin();
    // Rounds of ray indices, for progress and an interruption between them.
    constexpr int kBatch = 8;
    for (int first = 0; first < rays_; first += kBatch) {
        const int count = std::min(kBatch, rays_ - first);
        ref.trace_rays(first, count);
        if (progress_ && !progress_(first + count, rays_)) {
            completed_ = false;
            return;
        }
    }
    ref.finish();
    const auto t2 = clock::now();

    auto& r = ctx.resources;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(r.get("reference.accum").id(), 0, 0, 0, s.width, s.height, GL_RGBA, GL_FLOAT, ref.accum().data());
    glTextureSubImage2D(r.get("reference.reflection").id(), 0, 0, 0, s.width, s.height, GL_RGBA, GL_FLOAT,
                        ref.reflection().data());
    glTextureSubImage3D(r.get("reference.direct").id(), 0, 0, 0, 0, s.width, s.height, 1, GL_RGBA, GL_FLOAT,
                        ref.direct().data());
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    const auto t3 = clock::now();
    stage_ms_ = {{"reference.transfer", ms(t0, t1) + ms(t2, t3)},
                 {"reference.cpu", ms(t1, t2)},
                 {"reference.rays_traced", ref.rays_traced()}};
}

}  // namespace ssr
