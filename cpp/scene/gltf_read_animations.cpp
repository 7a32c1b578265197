// Animations (glTF 2.0, animations): samplers and channels on translation, rotation and scale.

#include "scene/gltf_reader.h"

namespace ssr::gltf_detail {

// The file's animations, their channels on the nodes of the default scene (scene_node: the
// Scene::nodes index of each file node, -1 for nodes outside it). Every index, accessor and
// keyframe is checked; a message names the animation, the channel, its node and path.
void read_animations(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const std::vector<int>& scene_node,
                     const std::string& path, std::vector<std::string>& warnings) {
    for (size_t a = 0; a < model.animations.size(); ++a) {
        const auto& ga = model.animations[a];
        Animation anim;
        anim.name = ga.name.empty() ? "animation" + std::to_string(a) : ga.name;
        anim.source = path;
        const std::string aw = "animation " + std::to_string(a) + (ga.name.empty() ? "" : " ('" + ga.name + "')");
        std::set<std::pair<int, int>> seen;
        int weights = 0, outside = 0;
        std::set<std::string> other_paths;
        for (size_t c = 0; c < ga.channels.size(); ++c) {
            const auto& ch = ga.channels[c];
            const std::string cw = aw + " channel " + std::to_string(c);
            if (ch.sampler < 0 || ch.sampler >= int(ga.samplers.size()))
                r.fail(cw + ": sampler " + std::to_string(ch.sampler) + " is out of range (the animation has " +
                       std::to_string(ga.samplers.size()) + " samplers)");
            if (ch.target_node < 0) continue;  // a target without a node (extensions): nothing here to move
            if (ch.target_node >= int(model.nodes.size()))
                r.fail(cw + ": target node " + std::to_string(ch.target_node) + " is out of range (the file has " +
                       std::to_string(model.nodes.size()) + " nodes)");
            const auto& gn = model.nodes[size_t(ch.target_node)];
            const std::string nw = cw + " (node " + std::to_string(ch.target_node) +
                                   (gn.name.empty() ? "" : " '" + gn.name + "'") + ", " + ch.target_path + ")";
            AnimationChannel out;
            if (ch.target_path == "translation") out.path = AnimationChannel::Path::Translation;
            else if (ch.target_path == "rotation") out.path = AnimationChannel::Path::Rotation;
            else if (ch.target_path == "scale") out.path = AnimationChannel::Path::Scale;
            else {
                if (ch.target_path == "weights") ++weights;
                else other_paths.insert(ch.target_path);
                continue;
            }
            if (!gn.matrix.empty())
                r.fail(nw + ": the node is given by a matrix, and glTF animates only nodes given by translation, "
                            "rotation and scale");
            if (!seen.insert({ch.target_node, int(out.path)}).second)
                r.fail(nw + ": a second channel for the same node and path (glTF allows one per animation)");
            const auto& gs = ga.samplers[size_t(ch.sampler)];
            const std::string sw = nw + ": sampler " + std::to_string(ch.sampler);
            AnimationSampler& s = out.sampler;
            if (gs.interpolation == "LINEAR" || gs.interpolation.empty()) s.interpolation = AnimationSampler::Interpolation::Linear;
            else if (gs.interpolation == "STEP") s.interpolation = AnimationSampler::Interpolation::Step;
            else if (gs.interpolation == "CUBICSPLINE") s.interpolation = AnimationSampler::Interpolation::CubicSpline;
            else r.fail(sw + ": interpolation '" + gs.interpolation + "' is not LINEAR, STEP or CUBICSPLINE");
            s.components = out.path == AnimationChannel::Path::Rotation ? 4 : 3;
            // Times are float scalars; translation and scale float vectors; rotations float or
            // normalised integers (glTF 2.0, animation samplers).
            const auto& in = r.accessor(gs.input, sw + " input");
            if (in.type != TINYGLTF_TYPE_SCALAR || in.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
                r.fail(sw + ": input accessor " + std::to_string(gs.input) + " must hold float scalars (keyframe times)");
            for (const auto& t : r.read_floats<1>(gs.input, sw + " input")) s.times.push_back(t.x);
            const auto& o = r.accessor(gs.output, sw + " output");
            const bool float_values = o.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
            const bool normalized = o.normalized && (o.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                                                     o.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                                     o.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
                                                     o.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
            if (s.components == 3 && (o.type != TINYGLTF_TYPE_VEC3 || !float_values))
                r.fail(sw + ": output accessor " + std::to_string(gs.output) + " must hold float VEC3 values for " +
                       ch.target_path);
            if (s.components == 4 && (o.type != TINYGLTF_TYPE_VEC4 || !(float_values || normalized)))
                r.fail(sw + ": output accessor " + std::to_string(gs.output) +
                       " must hold VEC4 quaternions, float or normalized integers");
            if (s.components == 3)
                for (const auto& v : r.read_floats<3>(gs.output, sw + " output")) s.values.insert(s.values.end(), {v.x, v.y, v.z});
            else
                for (const auto& v : r.read_floats<4>(gs.output, sw + " output")) s.values.insert(s.values.end(), {v.x, v.y, v.z, v.w});
            if (const std::string p = check_sampler(s); !p.empty()) r.fail(sw + ": " + p);
            out.node = scene_node[size_t(ch.target_node)];
            if (out.node < 0) {
                ++outside;
                continue;
            }
            anim.duration = std::max(anim.duration, s.times.back());
            anim.channels.push_back(std::move(out));
        }
        if (weights)
            warnings.push_back(path + ": " + aw + ": " + std::to_string(weights) +
                               " channel(s) animate morph target weights, which are not rendered (ignored)");
        if (outside)
            warnings.push_back(path + ": " + aw + ": " + std::to_string(outside) +
                               " channel(s) move nodes outside the default scene (ignored)");
        if (!other_paths.empty()) {
            std::string names;
            for (const auto& p : other_paths) names += (names.empty() ? "'" : ", '") + p + "'";
            warnings.push_back(path + ": " + aw + ": channels with target path " + names + " are not rendered (ignored)");
        }
        scene.animations.push_back(std::move(anim));
    }
}

}  // namespace ssr::gltf_detail
