// The user passes' registry (passes/user_pass.h): a user pass's declaration checked against the
// passes the renderer has, the settings that name user passes, and where a placed pass runs in a
// frame's chain. The built-in passes register themselves (render/pass_registry.h); a user pass
// goes through the same ordering once placed.
#include "render/renderer.h"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/errors.h"
#include "passes/compute.h"

namespace ssr {
std::vector<UserPass*> Renderer::check_user_settings(const RenderSettings& s) const {
    std::vector<UserPass*> chosen;
    auto find = [&](const std::string& name) -> UserPass* {
        for (const auto& u : user_passes_)
            if (u->name() == name) return u.get();
        return nullptr;
    };
    auto registered = [&] {
        std::string names;
        for (const auto& u : user_passes_) names += (names.empty() ? "" : ", ") + u->name();
        return names.empty() ? std::string("none: Renderer.register_pass adds one") : names;
    };
    for (const auto& name : s.user.passes) {
        UserPass* u = find(name);
        if (!u)
            throw std::invalid_argument("Settings.user_passes names '" + name +
                                        "', which is not registered on this renderer (registered: " + registered() + ")");
        for (const UserPass* c : chosen)
            if (c->stage() == u->stage() && !u->placed())
                throw std::invalid_argument("Settings.user_passes: '" + c->name() + "' and '" + name +
                                            "' both fill the stage '" + u->stage() + "'");
        if (u->stage() == "trace") {
            if (s.method != TraceMethod::Linear && s.method != TraceMethod::Hiz)
                throw std::invalid_argument("Settings.user_passes: the trace pass '" + name +
                                            "' takes the place of the screen-space trace; Settings.method must be "
                                            "'linear' or 'hiz' (it chooses the passes around it: 'hiz' builds the "
                                            "Hi-Z pyramid)");
            if (s.variance_rays)
                throw std::invalid_argument("Settings.user_passes: the trace pass '" + name +
                                            "' does not serve Settings.variance_rays (its second trace is built in)");
        }
        chosen.push_back(u);
    }
    for (const auto& [key, value] : s.user.params) {
        const size_t dot = key.rfind('.');
        UserPass* u = dot == std::string::npos ? nullptr : find(key.substr(0, dot));
        if (!u)
            throw std::invalid_argument("Settings.user_params['" + key + "']: no registered user pass '" +
                                        key.substr(0, dot == std::string::npos ? key.size() : dot) +
                                        "' (keys are '<pass>.<param>'; registered: " + registered() + ")");
        const auto& params = u->desc().params;
        if (std::none_of(params.begin(), params.end(), [&](const UserParam& p) { return p.name == key.substr(dot + 1); })) {
            std::string names;
            for (const auto& p : params) names += (names.empty() ? "" : ", ") + p.name;
            throw std::invalid_argument("Settings.user_params['" + key + "']: user pass '" + u->name() +
                                        "' has no parameter '" + key.substr(dot + 1) + "' (it has: " +
                                        (names.empty() ? "none" : names) + ")");
        }
    }
    return chosen;
}

void Renderer::register_user_pass(const UserPassDesc& d) {
    auto fail = [&](const std::string& m) { throw std::invalid_argument("user pass '" + d.name + "': " + m); };
    auto join = [](const std::vector<std::string>& v) {
        std::string out;
        for (const auto& x : v) out += (out.empty() ? "'" : ", '") + x + "'";
        return out;
    };
    if (d.name.empty()) throw std::invalid_argument("user pass: the name is empty");
    for (const RenderPass* p : passes_)
        if (p->name() == d.name) fail("a built-in pass has this name");
    for (const auto& u : user_passes_)
        if (u->name() == d.name) fail("a user pass of this name is registered on this renderer already");
    if (d.stage != "trace" && d.stage != "reflection_filter" && d.stage != "placed")
        fail("stage must be 'trace', 'reflection_filter' or 'placed', got '" + d.stage + "'");
    if (d.stage == "trace" && d.dispatch != "ray" && d.dispatch != "list")
        fail("a trace pass dispatches per ray: dispatch must be 'ray' (over classify's list with Settings.skip) "
             "or 'list' (classify's list only), got '" + d.dispatch + "'");
    if (d.stage != "trace" && d.dispatch != "pixel" && d.dispatch != "ray")
        fail("a " + d.stage + " pass dispatches per pixel: dispatch must be 'pixel' or 'ray', got '" + d.dispatch + "'");
    if (d.stage != "placed" && (!d.after.empty() || !d.before.empty()))
        fail("only a placed pass (no stage) names the pass it runs after or before; a " + d.stage +
             " pass has its stage's place");
    if (!d.after.empty() && !d.before.empty())
        fail("names both a pass to run after ('" + d.after + "') and one to run before ('" + d.before +
             "'): name one, the other follows from the chain");
    // Who writes what, in registry order: the union over settings that switch outputs on.
    std::vector<RenderSettings> variants(2);
    variants[1].specular_occlusion = SpecularOcclusion::Horizon;
    variants[1].method = TraceMethod::Hiz;
    struct Owner {
        std::string pass;
        size_t at;      // registry index of the first pass that declares it
        GLenum format;  // its format (0: a user pass's texture, declared with an image format)
        // The last pass that writes or rewrites it (classify clears what the trace and the
        // resolve then write): a reader sees it whole only after that one.
        std::string last_pass;
        size_t last_at;
    };
    std::map<std::string, Owner> owner;
    // The registry index a user pass of `stage` runs at: the place of the built-in pass of its
    // stage, or right after the pass its stage follows (UserPass::after_stage).
    auto place = [&](const std::string& stage) {
        for (size_t i = 0; i < passes_.size(); ++i) {
            const std::string& own = passes_[i]->stage();
            if (own.empty()) continue;
            if (own == stage) return i;
            if (own == UserPass::after_stage(stage)) return i + 1;
        }
        return passes_.size();
    };
    auto registry_index = [&](const std::string& name) -> long {
        for (size_t i = 0; i < passes_.size(); ++i)
            if (passes_[i]->name() == name) return long(i);
        return -1;
    };
    for (size_t i = 0; i < passes_.size(); ++i) {
        const RenderPass* p = passes_[i];
        FrameFacts every;  // the facts that switch outputs on
        every.emission_texture = true;
        every.shadows = true;
        every.shadow_maps = every.shadow_cubes = 1;
        every.specular_texture = true;
        for (const auto& s : variants)
            for (const auto& o : p->outputs(s, every)) {
                const auto [it, fresh] = owner.emplace(o.name, Owner{p->name(), i, o.format, p->name(), i});
                if (!fresh && i > it->second.last_at) it->second.last_pass = p->name(), it->second.last_at = i;
            }
    }
    for (size_t i = 0; i < passes_.size(); ++i)
        for (const auto& s : variants)
            for (const auto& x : passes_[i]->rewrites(s, FrameFacts{})) {
                auto it = owner.find(x);
                if (it != owner.end() && i > it->second.last_at)
                    it->second.last_pass = passes_[i]->name(), it->second.last_at = i;
            }
    // Earlier user passes' own textures: written at their stage's place (a placed pass's: at its
    // anchor's, or anywhere: the chain check decides).
    for (const auto& u : user_passes_) {
        const UserPassDesc& ud = u->desc();
        size_t at = place(ud.stage);
        if (ud.stage == "placed") {
            const long a = registry_index(ud.after.empty() ? ud.before : ud.after);
            at = a < 0 ? 0 : size_t(a) + (ud.after.empty() ? 0 : 1);
        }
        for (const auto& c : ud.creates) owner.emplace(c.name, Owner{u->name(), at, 0, u->name(), at});
    }
    const std::vector<std::string> allowed = UserPass::stage_writes(d.stage);
    if (d.stage == "placed") {
        // The pass it names must exist.
        const std::string& anchor = d.after.empty() ? d.before : d.after;
        const bool anchor_user = std::any_of(user_passes_.begin(), user_passes_.end(),
                                             [&](const auto& u) { return u->name() == anchor; });
        if (!anchor.empty() && registry_index(anchor) < 0 && !anchor_user) {
            std::string names;
            for (const RenderPass* p : passes_) names += (names.empty() ? "" : ", ") + p->name();
            fail("runs " + std::string(d.after.empty() ? "before" : "after") + " '" + anchor +
                 "', which is no pass (passes: " + names + ", and the user passes registered before it)");
        }
        std::vector<std::string> needs = d.reads;
        for (const auto& w : d.writes)
            if (std::find(needs.begin(), needs.end(), w) == needs.end()) needs.push_back(w);
        for (const auto& r : needs) {
            const bool rewrites = std::find(d.writes.begin(), d.writes.end(), r) != d.writes.end();
            auto it = owner.find(r);
            if (it == owner.end())
                fail(std::string(rewrites ? "rewrites" : "reads") + " '" + r + "', which no pass writes" +
                     (rewrites ? ": declare a texture of its own in creates with its format and size" : ""));
            if (rewrites && it->second.format != 0 && !UserPass::image_format(it->second.format))
                fail("rewrites '" + r + "', whose format an image store cannot write (the formats it can: rgba8, "
                     "rgba16f, rgba32f, rg16f, rg32f, r16f, r32f)");
        }
        // Named after or before a built-in pass: a place no chain could give it is refused now,
        // naming the input it would lack (the chains of the techniques' settings, every pass that
        // some scene switches on; a place some chain allows is checked again per frame).
        if (!anchor.empty() && !anchor_user) {
            const UserPass probe(d);
            FrameFacts every;
            every.reflections = every.shadows = every.emission_texture = every.specular_texture = true;
            every.shadow_maps = every.shadow_cubes = 1;
            every.fetch_by_image = fetch_by_image_;
            std::string first;
            bool possible = false;
            for (const RenderSettings& v : placement_variants()) {
                std::vector<RenderPass*> chain;
                for (RenderPass* p : passes_)
                    if (p->runs(v, every)) chain.push_back(p);
                if (std::none_of(chain.begin(), chain.end(), [&](const RenderPass* p) { return p->name() == anchor; }))
                    continue;
                size_t at = 0;
                const std::string why = placement(chain, probe, v, every, at);
                if (why.empty()) {
                    possible = true;
                    break;
                }
                if (first.empty()) first = why.substr(0, why.find(", which no pass of this frame's chain"));
            }
            if (!possible && !first.empty()) fail(first);
        }
    } else {
        const size_t at = place(d.stage);
        for (const auto& r : d.reads) {
            auto it = owner.find(r);
            if (it == owner.end()) fail("reads '" + r + "', which no pass writes");
            const bool own = std::find(allowed.begin(), allowed.end(), r) != allowed.end() &&
                             d.stage == "reflection_filter";
            if (it->second.last_at >= at && !own)
                fail("reads '" + r + "', which no pass before its stage '" + d.stage + "' writes ('" +
                     it->second.last_pass + "' writes it later)");
        }
        if (d.stage == "trace" && d.writes != allowed)
            fail("a trace pass writes exactly " + join(allowed) + " (the ray textures the resolve, the stats and "
                 "the per-ray reference read), got " + (d.writes.empty() ? std::string("none") : join(d.writes)));
        for (const auto& w : d.writes) {
            if (std::find(allowed.begin(), allowed.end(), w) != allowed.end()) continue;
            auto it = owner.find(w);
            if (it != owner.end())
                fail("writes '" + w + "', which pass '" + it->second.pass + "' owns; a " + d.stage + " pass writes " +
                     join(allowed) + " and the textures it creates (a placed pass, without a stage, may rewrite it)");
            fail("writes '" + w + "', which no pass declares: declare it in creates with its format and size");
        }
    }
    std::set<std::string> created;
    for (const auto& c : d.creates) {
        auto it = owner.find(c.name);
        if (it != owner.end()) fail("creates '" + c.name + "', which pass '" + it->second.pass + "' owns already");
        if (!created.insert(c.name).second) fail("creates '" + c.name + "' twice");
        if (!UserPass::parse_format(c.format))
            fail("creates '" + c.name + "' with format '" + c.format +
                 "' (formats: rgba8, rgba16f, rgba32f, rg16f, rg32f, r16f, r32f)");
        if (c.size != "image" && c.size != "trace" && c.size != "rays")
            fail("creates '" + c.name + "' with size '" + c.size + "' (sizes: image, trace, rays)");
    }
    for (const auto& p : d.params)
        if (p.type != "float" && p.type != "int" && p.type != "bool")
            fail("parameter '" + p.name + "' has type '" + p.type + "' (types: float, int, bool)");
    user_passes_.push_back(std::make_unique<UserPass>(d));
}

// Settings whose chains hold every built-in pass somewhere: each trace method, each glossy method, the
// temporal techniques, SVGF, the fallbacks, the variance-guided second trace, skip (classify).
std::vector<RenderSettings> Renderer::placement_variants() {
    std::vector<RenderSettings> out;
    for (TraceMethod method : {TraceMethod::Linear, TraceMethod::Hiz, TraceMethod::Bvh})
        for (Glossy glossy : {Glossy::Stochastic, Glossy::Cone, Glossy::BlurMips})
            for (int extra = 0; extra < 7; ++extra) {
                if (method == TraceMethod::Bvh && (glossy != Glossy::Stochastic || extra > 1)) continue;
                if (glossy != Glossy::Stochastic && extra >= 3) continue;
                RenderSettings s;
                s.method = method;
                s.glossy = glossy;
                if (extra == 1) s.denoise = Denoise::Svgf;
                if (extra == 2) s.skip = true, s.temporal_reflections = true, s.taa = TaaMode::Clamped;
                if (extra == 3) s.fallback = Fallback::Bvh;
                if (extra == 4) s.fallback = Fallback::Probes;
                if (extra == 5) s.variance_rays = s.adaptive_rays = s.skip = true;
                if (extra == 6) s.specular_occlusion = SpecularOcclusion::Horizon;
                out.push_back(s);
            }
    return out;
}

std::vector<UserPassDesc> Renderer::user_passes() const {
    std::vector<UserPassDesc> out;
    for (const auto& u : user_passes_) out.push_back(u->desc());
    return out;
}

// Where a placed user pass runs in `chain`: right after the pass it names (after), right before
// the one it names (before), or, naming none, right after the last pass that declares a texture
// it reads or rewrites (the earliest place where all of them exist). User passes placed at the
// same place keep Settings.user_passes order. Every texture it reads or rewrites must be declared
// by a pass before its place: otherwise the place is impossible, and the answer says why, naming
// that texture ("" when the place is `at`).
std::string Renderer::placement(const std::vector<RenderPass*>& chain, const UserPass& u, const RenderSettings& s,
                                const FrameFacts& facts, size_t& at) const {
    const UserPassDesc& d = u.desc();
    // The last pass that writes or rewrites `r`: what it reads is whole only after that one.
    auto writer = [&](const std::string& r) -> long {
        long last = -1;
        for (size_t i = 0; i < chain.size(); ++i) {
            for (const auto& o : chain[i]->outputs(s, facts))
                if (o.name == r) last = long(i);
            for (const auto& x : chain[i]->rewrites(s, facts))
                if (x == r) last = long(i);
        }
        return last;
    };
    auto names = [&] {
        std::string out;
        for (const RenderPass* p : chain) out += (out.empty() ? "" : ", ") + p->name();
        return out;
    };
    // Who would write a texture in another chain (for the message): the registry's first declarer.
    auto declarer = [&](const std::string& r) -> std::string {
        for (const RenderPass* p : passes_)
            for (const auto& o : p->outputs(s, facts))
                if (o.name == r) return p->name();
        return "";
    };
    const std::vector<std::string> needs = u.inputs(s, facts);
    auto verb = [&](const std::string& r) {
        return std::find(d.writes.begin(), d.writes.end(), r) != d.writes.end() ? "rewrites" : "reads";
    };
    at = 0;
    const std::string& anchor = d.after.empty() ? d.before : d.after;
    const std::string side = d.after.empty() ? "before" : "after";
    if (!anchor.empty()) {
        const auto a = std::find_if(chain.begin(), chain.end(), [&](const RenderPass* p) { return p->name() == anchor; });
        if (a == chain.end())
            return "runs " + side + " '" + anchor + "', which this frame's chain does not run (it runs: " + names() + ")";
        at = size_t(a - chain.begin()) + (d.after.empty() ? 0 : 1);
    } else {
        for (const auto& r : needs) {
            const long w = writer(r);
            if (w >= 0) at = std::max(at, size_t(w) + 1);  // a missing one is named below
        }
    }
    // After the user passes already placed here (Settings.user_passes order).
    if (d.before.empty())
        while (at < chain.size() && dynamic_cast<const UserPass*>(chain[at]) &&
               static_cast<const UserPass*>(chain[at])->placed())
            ++at;
    const std::string lead = anchor.empty() ? "" : "cannot run " + side + " '" + anchor + "': ";
    for (const auto& r : needs) {
        const long w = writer(r);
        if (w >= 0 && size_t(w) < at) continue;
        if (w >= 0)
            return lead + "it " + verb(r) + " '" + r + "', which no pass before that place writes ('" +
                   chain[size_t(w)]->name() + "' writes it" + (!d.before.empty() && size_t(w) == at ? "" : " later") + ")";
        const std::string who = declarer(r);
        return lead + "it " + verb(r) + " '" + r + "', which no pass of this frame's chain writes" +
               (who.empty() ? std::string("") : " ('" + who + "' declares it, and these settings do not run it)") +
               "; the chain runs: " + names();
    }
    return "";
}

void Renderer::place_user_pass(std::vector<RenderPass*>& chain, UserPass& u, const RenderSettings& s,
                               const FrameFacts& facts) const {
    size_t at = 0;
    const std::string why = placement(chain, u, s, facts, at);
    if (!why.empty()) {
        const bool named = why.rfind("runs ", 0) == 0;  // "runs after 'x', which ..." follows the name
        throw std::invalid_argument("Settings.user_passes: user pass '" + u.name() + "'" + (named ? " " : ": ") + why);
    }
    chain.insert(chain.begin() + long(at), &u);
}

}  // namespace ssr
