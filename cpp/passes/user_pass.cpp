#include "passes/user_pass.h"

#include <algorithm>

#include "core/errors.h"
#include "passes/compute.h"

namespace ssr {

namespace {

// What the trace's ray generation reads (trace_pass.cpp binds them by name itself, units 0-3).
const std::vector<std::string>& generation_inputs() {
    static const std::vector<std::string> names = {"linear_depth", "gbuffer.albedo", "gbuffer.normal",
                                                   "gbuffer.material"};
    return names;
}

bool contains(const std::vector<std::string>& v, const std::string& x) {
    return std::find(v.begin(), v.end(), x) != v.end();
}

}  // namespace

std::vector<std::string> UserPass::stage_writes(const std::string& stage) {
    if (stage == "trace") return {"rays.hit", "rays.sample", "rays.direction"};
    if (stage == "reflection_filter") return {"reflection"};
    return {};
}

GLenum UserPass::parse_format(const std::string& f) {
    if (f == "rgba8") return GL_RGBA8;
    if (f == "rgba16f") return GL_RGBA16F;
    if (f == "rgba32f") return GL_RGBA32F;
    if (f == "rg16f") return GL_RG16F;
    if (f == "rg32f") return GL_RG32F;
    if (f == "r16f") return GL_R16F;
    if (f == "r32f") return GL_R32F;
    return 0;
}

bool UserPass::image_format(GLenum format) {
    for (const char* f : {"rgba8", "rgba16f", "rgba32f", "rg16f", "rg32f", "r16f", "r32f"})
        if (parse_format(f) == format) return true;
    return false;
}

std::vector<std::string> UserPass::inputs(const RenderSettings& s, const FrameFacts& f) const {
    std::vector<std::string> in;
    if (desc_.stage == "trace")
        for (const auto& g : generation_inputs()) in.push_back(g);
    for (const auto& r : desc_.reads)
        if (!contains(in, r)) in.push_back(r);
    // What a filter or a placed pass rewrites must be there before it: an input too (a trace's
    // writes are its own outputs).
    if (desc_.stage != "trace")
        for (const auto& w : desc_.writes)
            if (!contains(in, w)) in.push_back(w);
    return in;
}

std::vector<ResourceDesc> UserPass::outputs(const RenderSettings& s) const {
    // A trace declares the ray textures as the built-in traces do (trace_pass.h); a filter's
    // in-place writes were declared by the pass that made them.
    std::vector<ResourceDesc> out = desc_.stage == "trace" ? TracePass::outputs(s) : std::vector<ResourceDesc>{};
    for (const auto& c : desc_.creates) {
        ResourceDesc d{c.name, parse_format(c.format), s.width, s.height, 0, 1};
        if (c.size == "trace" || c.size == "rays") {
            d.width = s.trace_width();
            d.height = s.trace_height();
        }
        if (c.size == "rays") d.layers = s.traced_rays();
        out.push_back(d);
    }
    return out;
}

void UserPass::check_device(const RenderSettings& s) const {
    if (desc_.dispatch == "list" && !s.skip)
        throw std::invalid_argument("user pass '" + desc_.name +
                                    "' runs over classify's list (dispatch 'list'): it needs Settings.skip = True");
}

void UserPass::set_params(FrameContext& ctx, GLuint prog) const {
    // Parameters reach the shader as uniforms u_<name>: the value Settings.user_params gives
    // "<pass>.<param>", else the declared default (validated in Python and by the renderer).
    for (const auto& p : desc_.params) {
        double v = p.default_value;
        const auto it = ctx.settings.user.params.find(desc_.name + "." + p.name);
        if (it != ctx.settings.user.params.end()) v = it->second;
        const GLint loc = glGetUniformLocation(prog, ("u_" + p.name).c_str());
        if (loc < 0) continue;  // declared but unused by the shader: the compiler dropped it
        if (p.type == "float")
            glUniform1f(loc, float(v));
        else
            glUniform1i(loc, int(v));
    }
}

void UserPass::execute(FrameContext& ctx) {
    auto& r = ctx.resources;
    if (desc_.stage == "trace") {
        // A user's shader is its own, written to the documented units: trace inputs beyond the
        // ray generation's at texture units 4, 5, ... in declared order, and by imageLoad
        // (FETCH_BY_IMAGE) image units 5, 6, ... (trace_hiz's atlas: unit 4, image 5); its own
        // textures at image units after those. Placed there by name, so the program's check
        // holds the shader to them.
        std::vector<std::string> extra;
        for (const auto& in : desc_.reads)
            if (!contains(generation_inputs(), in)) extra.push_back(in);
        NamedUnits units;
        for (GLuint i = 0; i < GLuint(extra.size()); ++i) {
            glBindTextureUnit(4 + i, r.get(extra[i]).id());
            units.placed_textures.emplace_back(extra[i], 4 + i);
        }
        if (ctx.fetch_by_image()) {
            bind_input_images(r, 5, extra);
            for (GLuint i = 0; i < GLuint(extra.size()); ++i) units.placed_images.emplace_back(extra[i], 5 + i);
        }
        GLuint unit = 5 + GLuint(extra.size());
        for (const auto& c : desc_.creates) {
            units.placed_images.emplace_back(c.name, unit);
            bind_image_layered(unit++, r.get(c.name), GL_WRITE_ONLY);
        }
        run(ctx, desc_.shader, [&](GLuint prog) { set_params(ctx, prog); }, units);
        const auto& s = ctx.settings;
        groups_ = s.skip || desc_.dispatch == "list"
                      ? -1.0
                      : double((s.trace_width() + 7) / 8) * ((s.trace_height() + 7) / 8) * s.traced_rays();
        return;
    }
    // reflection_filter and placed passes: reads at texture units 0, 1, ... in declared order
    // (what it also rewrites from a copy taken now), writes then creates at image units 0, 1, ...
    // (NamedUnits' order, its defines given too), the program held to them.
    copy_rewritten(r);
    NamedUnits units{desc_.reads, {}};
    for (const auto& w : desc_.writes) units.images.emplace_back(w, GL_WRITE_ONLY);
    for (const auto& c : desc_.creates) units.images.emplace_back(c.name, GL_WRITE_ONLY);
    for (const auto& c : copies_)
        if (contains(desc_.reads, c.first)) units.own.emplace_back(c.first, &c.second);
    // The image of a rewritten input is the frame's own texture, its read the copy.
    Defines d = ctx.defines;
    units.add_unit_defines(d);
    const GLuint prog = ctx.shaders.program({desc_.shader}, d);
    glUseProgram(prog);
    set_params(ctx, prog);
    for (size_t i = 0; i < desc_.reads.size(); ++i) glBindTextureUnit(units.texture_unit(i), units.get(r, desc_.reads[i]).id());
    for (size_t i = 0; i < units.images.size(); ++i)
        bind_image_layered(units.image_unit(i), r.get(units.images[i].first), GL_WRITE_ONLY);
    units.check(prog, desc_.shader);
    const auto& s = ctx.settings;
    if (desc_.dispatch == "ray") {
        dispatch_2d(s.trace_width(), s.trace_height(), s.traced_rays(), 8, 8);
        groups_ = double((s.trace_width() + 7) / 8) * ((s.trace_height() + 7) / 8) * s.traced_rays();
    } else {
        dispatch_2d(s.width, s.height, 1, 8, 8);
        groups_ = double((s.width + 7) / 8) * ((s.height + 7) / 8);
    }
}

void UserPass::copy_rewritten(FrameResources& r) {
    for (const auto& w : desc_.writes) {
        if (!contains(desc_.reads, w)) continue;
        const Texture& t = r.get(w);
        Texture& copy = copies_[w];
        if (!copy || copy.width() != t.width() || copy.height() != t.height() || copy.format() != t.format() ||
            copy.target() != t.target() || copy.layers() != t.layers() || copy.levels() != t.levels()) {
            if (t.target() == GL_TEXTURE_2D_ARRAY)
                copy = Texture::create_2d_array(t.format(), t.width(), t.height(), t.layers(), t.levels());
            else if (t.target() == GL_TEXTURE_CUBE_MAP_ARRAY)
                copy = Texture::create_cube_array(t.format(), t.width(), t.layers() / 6, t.levels());
            else
                copy = Texture::create_2d(t.format(), t.width(), t.height(), t.levels());
            // Sampled as the original is (the pre-convolved mips filter linearly between levels).
            GLint min_filter = 0, mag_filter = 0;
            glGetTextureParameteriv(t.id(), GL_TEXTURE_MIN_FILTER, &min_filter);
            glGetTextureParameteriv(t.id(), GL_TEXTURE_MAG_FILTER, &mag_filter);
            copy.set_filter(GLenum(min_filter), GLenum(mag_filter));
        }
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        const int depth = t.target() == GL_TEXTURE_2D ? 1 : t.layers();
        for (int level = 0; level < t.levels(); ++level)
            glCopyImageSubData(t.id(), t.target(), level, 0, 0, 0, copy.id(), copy.target(), level, 0, 0, 0,
                               std::max(1, t.width() >> level), std::max(1, t.height() >> level), depth);
    }
}

void UserPass::report(const RenderSettings&, std::map<std::string, double>& stats) const {
    // The work groups the pass dispatched: its grid's, or over classify's list the trace groups
    // classify counted (the same indirect dispatch as the built-in traces).
    if (groups_ >= 0.0)
        stats[desc_.name + ".groups"] = groups_;
    else if (stats.count("trace_groups"))
        stats[desc_.name + ".groups"] = stats["trace_groups"];
}

}  // namespace ssr
