// A user pass: a compute shader of the user's (any file, outside the shader tree too) and its
// declaration, made in Python (ssrlab.UserPass, docs/guide/glsl-contract.md) and registered on a
// Renderer, which checks it against the passes it has (Renderer::register_user_pass) and runs it
// where Settings.user_passes names it. Two stages:
//   "trace"             takes the place of the screen-space trace (trace_linear / trace_hiz) and
//                       writes rays.hit, rays.sample, rays.direction as they do (trace_pass.h), run
//                       by the same dispatch (per ray; over classify's list with Settings.skip), so
//                       the resolve, the stats and the per-ray reference read its rays unchanged;
//   "reflection_filter" runs right after the resolve and rewrites `reflection` in place (it reads
//                       a copy taken just before it runs, so it may read any neighbour).
// Its own textures (`creates`) are frame textures sized by the settings.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/gl_resources.h"
#include "passes/trace_pass.h"

namespace ssr {

struct UserResource {
    std::string name;
    std::string format = "rgba16f";  // rgba8, rgba16f, rgba32f, rg16f, rg32f, r16f, r32f
    std::string size = "image";      // image (width x height), trace (the trace resolution), rays (trace x rays)
};

struct UserParam {
    std::string name;
    std::string type = "float";  // float, int, bool: a uniform u_<name> of that type
    double default_value = 0.0;
};

struct UserPassDesc {
    std::string name;
    std::string shader;  // absolute path of the compute shader
    std::string stage;   // "trace" or "reflection_filter"
    std::string dispatch = "pixel";  // pixel, ray, list
    std::vector<std::string> reads, writes;
    std::vector<UserResource> creates;
    std::vector<UserParam> params;
};

class UserPass : public TracePass {
public:
    explicit UserPass(UserPassDesc desc) : desc_(std::move(desc)) {}
    const UserPassDesc& desc() const { return desc_; }
    std::string name() const override { return desc_.name; }
    std::string stage() const override { return desc_.stage; }
    // The renderer puts a user pass into the chain itself (Renderer::build_chain): where
    // Settings.user_passes names it and its stage runs.
    bool runs(const RenderSettings&, const FrameFacts&) const override { return false; }
    std::vector<std::string> inputs(const RenderSettings& s, const FrameFacts& f) const override;
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override;
    // A trace pass runs over classify's ray list with Settings.skip; a filter reads no buffer.
    std::vector<std::string> buffer_inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return desc_.stage == "trace" ? TracePass::buffer_inputs(s, f) : std::vector<std::string>{};
    }
    void check_device(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;
    void report(const RenderSettings& s, std::map<std::string, double>& stats) const override;
    void release() { source_copy_.reset(); }

    // The stage of the built-in pass a user pass of `stage` runs right after ("reflection_filter":
    // the "resolve"), or "" where it takes the place of the built-in pass of its own stage ("trace").
    static std::string after_stage(const std::string& stage) { return stage == "reflection_filter" ? "resolve" : ""; }
    // The resources a stage writes in place (a user pass of that stage may write them).
    static std::vector<std::string> stage_writes(const std::string& stage);
    static GLenum parse_format(const std::string& format);  // 0 when unknown

private:
    void set_params(FrameContext& ctx, GLuint prog) const;
    UserPassDesc desc_;
    Texture source_copy_;  // reflection_filter: the copy of what it rewrites, read while it writes
    double groups_ = -1.0;  // work groups of the last dispatch; -1: indirect
};

}  // namespace ssr
