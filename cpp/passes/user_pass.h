// A user pass: a compute shader of the user's (any file, outside the shader tree too) and its
// declaration, made in Python (ssrlab.UserPass, docs/guide/glsl-contract.md) and registered on a
// Renderer, which checks it against the passes it has (Renderer::register_user_pass) and runs it
// where Settings.user_passes names it. Three kinds:
//   "trace"             takes the place of the screen-space trace (trace_linear / trace_hiz) and
//                       writes rays.hit, rays.sample, rays.direction as they do (trace_pass.h), run
//                       by the same dispatch (per ray; over classify's list with Settings.skip), so
//                       the resolve, the stats and the per-ray reference read its rays unchanged;
//   "reflection_filter" runs right after the resolve and rewrites `reflection` in place;
//   "placed"            runs where the resources it reads and rewrites are (Renderer::build_chain):
//                       right after the last pass that declares one of them, or right after /
//                       before the pass it names (after, before), which the chain check refuses
//                       where an input would not be written yet (naming it). It may rewrite any
//                       texture a pass declares whose format an image store can write.
// A pass that reads what it rewrites reads a copy taken just before it runs (every layer and
// level), so it may read any neighbour. Its own textures (`creates`) are frame textures sized by
// the settings.
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
    std::string stage;   // "trace", "reflection_filter" or "placed"
    std::string dispatch = "pixel";  // pixel, ray, list
    std::string after, before;       // "placed": the pass it runs right after / before ("" : by its resources)
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
    // A trace rewrites classify's rays.sample as the built-in traces do; a filter's or a placed
    // pass's in-place writes are among its inputs (inputs()).
    std::vector<std::string> rewrites(const RenderSettings& s, const FrameFacts& f) const override {
        return desc_.stage == "trace" ? TracePass::rewrites(s, f) : std::vector<std::string>{};
    }
    std::vector<std::string> buffer_inputs(const RenderSettings& s, const FrameFacts& f) const override {
        return desc_.stage == "trace" ? TracePass::buffer_inputs(s, f) : std::vector<std::string>{};
    }
    void check_device(const RenderSettings& s) const override;
    void execute(FrameContext& ctx) override;
    void report(const RenderSettings& s, std::map<std::string, double>& stats) const override;
    void release() override { copies_.clear(); }
    bool placed() const { return desc_.stage == "placed"; }

    // The stage of the built-in pass a user pass of `stage` runs right after ("reflection_filter":
    // the "resolve"), or "" where it takes the place of the built-in pass of its own stage ("trace")
    // or is placed by its resources ("placed").
    static std::string after_stage(const std::string& stage) { return stage == "reflection_filter" ? "resolve" : ""; }
    // The resources a stage writes in place (a user pass of that stage may write them; a placed
    // pass may rewrite any declared texture an image store can write).
    static std::vector<std::string> stage_writes(const std::string& stage);
    static GLenum parse_format(const std::string& format);  // 0 when unknown
    // Whether a compute shader can write a texture of this format as an image (the formats of
    // parse_format): the textures a placed pass may rewrite.
    static bool image_format(GLenum format);

private:
    void set_params(FrameContext& ctx, GLuint prog) const;
    // Copies of the textures it reads and rewrites, taken just before it runs (every layer, level).
    void copy_rewritten(FrameResources& r);
    UserPassDesc desc_;
    std::map<std::string, Texture> copies_;  // what it reads and rewrites: the copy it reads
    double groups_ = -1.0;  // work groups of the last dispatch; -1: indirect
};

}  // namespace ssr
