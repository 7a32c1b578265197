#include "render/pass_registry.h"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>
#include <stdexcept>

#include "passes/shadow_map.h"

namespace ssr {

namespace {
std::vector<PassFactory>& factories() {
    static std::vector<PassFactory> all;  // filled before main, at static initialisation
    return all;
}

std::string join(const std::vector<std::string>& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
}
}  // namespace

bool register_pass_factory(PassFactory make) {
    factories().push_back(std::move(make));
    return true;
}

std::vector<std::unique_ptr<RenderPass>> make_registered_passes() {
    std::vector<std::unique_ptr<RenderPass>> out;
    for (const auto& make : factories()) out.push_back(make());
    // Registration follows the link order of the files; the registry's own order is the names'.
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a->name() < b->name(); });
    for (size_t i = 1; i < out.size(); ++i)
        if (out[i]->name() == out[i - 1]->name())
            throw std::logic_error("two registered passes are named '" + out[i]->name() + "'");
    return out;
}

PassDeclaration declaration(const RenderPass& p, const RenderSettings& s, const FrameFacts& f) {
    PassDeclaration d;
    d.reads = p.inputs(s, f);
    for (const auto& o : p.outputs(s, f)) d.writes.push_back(o.name);
    d.rewrites = p.rewrites(s, f);
    d.buffer_reads = p.buffer_inputs(s, f);
    d.buffer_writes = p.buffer_outputs(s, f);
    return d;
}

std::vector<RenderPass*> order_chain(const std::vector<RenderPass*>& passes,
                                     const std::function<PassDeclaration(size_t)>& declared, bool reverse_ties,
                                     bool alternatives) {
    const size_t n = passes.size();
    std::vector<PassDeclaration> d(n);
    for (size_t i = 0; i < n; ++i) d[i] = declared(i);
    // Who writes each texture and buffer: one pass each in a frame's chain. Over the union of
    // alternatives (the registry's order) several may: a reader then follows each of them.
    std::map<std::string, std::vector<size_t>> writer, buffer_writer;
    for (size_t i = 0; i < n; ++i) {
        for (const auto& [names, owners, kind] :
             {std::tuple{&d[i].writes, &writer, "texture"}, std::tuple{&d[i].buffer_writes, &buffer_writer, "buffer"}})
            for (const auto& x : *names) {
                auto& w = (*owners)[x];
                if (!alternatives && !w.empty() && w.front() != i)
                    throw std::invalid_argument(std::string("passes '") + passes[w.front()]->name() + "' and '" +
                                                passes[i]->name() + "' both write the " + kind + " '" + x +
                                                "': one writes it, the other may rewrite it (RenderPass::rewrites)");
                if (std::find(w.begin(), w.end(), i) == w.end()) w.push_back(i);
            }
    }
    std::vector<std::set<size_t>> after(n);  // after[i]: the passes i runs after
    for (size_t i = 0; i < n; ++i) {
        auto follow = [&](const std::vector<std::string>& names, const std::map<std::string, std::vector<size_t>>& owners) {
            for (const auto& x : names) {
                const auto it = owners.find(x);
                if (it == owners.end()) continue;
                for (size_t w : it->second)
                    if (w != i) after[i].insert(w);
            }
        };
        follow(d[i].reads, writer);
        follow(d[i].rewrites, writer);
        follow(d[i].buffer_reads, buffer_writer);
    }
    // Whether `a` runs after `b`, directly or through other passes.
    auto depends = [&](size_t a, size_t b) {
        std::vector<size_t> stack{a};
        std::vector<bool> seen(n, false);
        while (!stack.empty()) {
            const size_t x = stack.back();
            stack.pop_back();
            for (size_t y : after[x]) {
                if (y == b) return true;
                if (!seen[y]) seen[y] = true, stack.push_back(y);
            }
        }
        return false;
    };
    // A reader of a rewritten texture reads it as the rewrite leaves it, unless the rewrite needs
    // the reader's own output first (the variance estimate that chooses the extra rays reads the
    // first trace's rays): then it reads it before. Rewriters follow each other only through what
    // they read or need otherwise (the fallback reads the rays the trace rewrites).
    for (bool added = true; added;) {
        added = false;
        for (size_t r = 0; r < n; ++r)
            for (const auto& x : d[r].rewrites)
                for (size_t q = 0; q < n; ++q) {
                    if (q == r || after[q].count(r)) continue;
                    const auto& qr = d[q].reads;
                    if (std::find(qr.begin(), qr.end(), x) == qr.end() || depends(r, q)) continue;
                    after[q].insert(r);
                    added = true;
                }
    }
    // Two rewrites of one texture that nothing orders would leave the result to the order of
    // their names: refused (over alternatives, the tracers of one stage never run together).
    for (size_t a = 0; a < n && !alternatives; ++a)
        for (size_t b = a + 1; b < n; ++b)
            for (const auto& x : d[a].rewrites) {
                const auto& br = d[b].rewrites;
                if (std::find(br.begin(), br.end(), x) == br.end() || depends(a, b) || depends(b, a)) continue;
                throw std::invalid_argument("passes '" + passes[a]->name() + "' and '" + passes[b]->name() +
                                            "' both rewrite the texture '" + x +
                                            "' and nothing they read orders them: one must read what the other writes");
            }
    // Every pass once its predecessors ran; ties broken by name.
    std::vector<RenderPass*> out;
    std::vector<bool> placed(n, false);
    while (out.size() < n) {
        long next = -1;
        for (size_t i = 0; i < n; ++i) {
            if (placed[i]) continue;
            if (std::any_of(after[i].begin(), after[i].end(), [&](size_t j) { return !placed[j]; })) continue;
            if (next < 0 || (reverse_ties ? passes[i]->name() > passes[size_t(next)]->name()
                                          : passes[i]->name() < passes[size_t(next)]->name()))
                next = long(i);
        }
        if (next < 0) {
            std::vector<std::string> left;
            for (size_t i = 0; i < n; ++i)
                if (!placed[i]) left.push_back(passes[i]->name());
            throw std::invalid_argument("the passes " + join(left) +
                                        " read each other's outputs in a cycle: no order runs each after its inputs");
        }
        placed[size_t(next)] = true;
        out.push_back(passes[size_t(next)]);
    }
    return out;
}

bool reverse_chain_ties() {
    const char* v = std::getenv("SSRLAB_CHAIN_TIES");
    return v && std::string(v) == "reverse";
}

FrameFacts scene_facts(const Scene& scene, const RenderSettings& s, bool fetch_by_image) {
    bool reflective = false, emissive = false, specular = false;
    for (const Object& o : scene.objects) {
        const Material& m = scene.materials[size_t(o.material)];
        reflective = reflective || m.reflectivity != 0.0f;
        emissive = emissive || m.emissive_texture.valid();
        specular = specular || m.specular_texture.valid() || m.specular_color_texture.valid();
    }
    return frame_facts(scene, scene.bounds(), reflective, emissive, specular, s, fetch_by_image);
}

FrameFacts frame_facts(const Scene& scene, const Bounds& bounds, bool reflective, bool emission_texture,
                       bool specular_texture, const RenderSettings& s, bool fetch_by_image) {
    FrameFacts f;
    const ShadowSetup shadow = ShadowMapPass::fit(scene, bounds, s);
    f.shadows = shadow.enabled;
    f.shadow_maps = shadow.maps;
    f.shadow_cubes = shadow.cubes;
    f.reflections = s.method != TraceMethod::Off && reflective;
    f.fetch_by_image = fetch_by_image;
    f.emission_texture = emission_texture;
    f.specular_texture = specular_texture;
    return f;
}

}  // namespace ssr
