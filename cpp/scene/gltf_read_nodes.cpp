// Nodes and the scene graph (glTF 2.0, scenes and nodes): the default scene's node tree walked from
// its roots, each node's transform, and the meshes, cameras and lights it places.

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "scene/gltf_reader.h"
#include "scene/scene_limits.h"

namespace ssr::gltf_detail {

namespace {

// A node's local transform as the file gives it: a matrix, or translation, rotation (normalised)
// and scale; NodeTransform::local() composes it.
NodeTransform node_local_transform(const tinygltf::Node& n, const GltfReader& r, const std::string& what) {
    NodeTransform out;
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16) r.fail(what + ": matrix has " + std::to_string(n.matrix.size()) + " values, not 16");
        check_finite_list(r, n.matrix, what + ": matrix");
        glm::mat4 m;
        for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(n.matrix[size_t(i)]);  // column-major
        if (const std::string p = affine_problem(m); !p.empty()) r.fail(what + ": matrix " + p);
        out.has_matrix = true;
        out.matrix = m;
        return out;
    }
    if (!n.translation.empty()) {
        if (n.translation.size() != 3) r.fail(what + ": translation does not have 3 values");
        check_finite_list(r, n.translation, what + ": translation");
        out.translation = glm::vec3(n.translation[0], n.translation[1], n.translation[2]);
    }
    if (!n.rotation.empty()) {  // glTF stores (x, y, z, w)
        if (n.rotation.size() != 4) r.fail(what + ": rotation does not have 4 values");
        check_finite_list(r, n.rotation, what + ": rotation");
        const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
        const double len = glm::length(q);
        if (!(len > 1e-6) || !std::isfinite(len)) r.fail(what + ": rotation quaternion has (near) zero length");
        out.rotation = glm::normalize(q);
    }
    if (!n.scale.empty()) {
        if (n.scale.size() != 3) r.fail(what + ": scale does not have 3 values");
        check_finite_list(r, n.scale, what + ": scale");
        out.scale = glm::vec3(n.scale[0], n.scale[1], n.scale[2]);
    }
    return out;
}

// The pose ssrlab saved an animated node in (extras.ssrlab.pose: translation, rotation, scale,
// written exactly; the node's own fields are its rest pose, what other viewers animate from).
NodeTransform saved_pose(const tinygltf::Value& x, const NodeTransform& rest, const GltfReader& r, const std::string& what) {
    const std::string w = what + ": extras.ssrlab";
    if (!x.IsObject()) r.fail(w + " is not an object");
    if (!x.Has("pose")) return rest;
    const tinygltf::Value& p = x.Get("pose");
    const std::string pw = w + ".pose";
    if (!p.IsObject()) r.fail(pw + " is not an object");
    if (rest.has_matrix) r.fail(pw + ": the node is given by a matrix, which has no pose");
    NodeTransform out = rest;
    auto numbers = [&](const char* key, size_t n) {
        std::vector<double> v;
        const tinygltf::Value& a = p.Get(key);
        if (!a.IsArray() || a.ArrayLen() != n) r.fail(pw + "." + key + " must be an array of " + std::to_string(n) + " numbers");
        for (size_t i = 0; i < n; ++i) {
            const tinygltf::Value& e = a.Get(int(i));
            if (!e.IsNumber() && !e.IsInt()) r.fail(pw + "." + key + " must be an array of " + std::to_string(n) + " numbers");
            const double d = e.GetNumberAsDouble();
            if (!in_range(d, -3.0e38, 3.0e38)) r.fail(pw + "." + key + " holds " + num(d) + ", not a finite float");
            v.push_back(d);
        }
        return v;
    };
    if (p.Has("translation")) {
        const auto v = numbers("translation", 3);
        out.translation = glm::vec3(v[0], v[1], v[2]);
    }
    if (p.Has("rotation")) {  // as saved: already unit, not normalised again
        const auto v = numbers("rotation", 4);
        out.rotation = glm::dquat(v[3], v[0], v[1], v[2]);
        if (!(std::abs(glm::length(out.rotation) - 1.0) < 1e-3)) r.fail(pw + ".rotation is not a unit quaternion");
    }
    if (p.Has("scale")) {
        const auto v = numbers("scale", 3);
        out.scale = glm::vec3(v[0], v[1], v[2]);
    }
    return out;
}

}  // namespace

std::vector<int> read_nodes(const tinygltf::Model& model, const GltfReader& r, Scene& scene, const glm::mat4& transform,
                            PrimitiveReader& primitive, const std::string& path, std::vector<std::string>& warnings) {
    // Nodes: depth-first from the default scene's roots with an explicit stack (a file can
    // chain nodes deeper than the C++ stack), a depth limit, and cycle detection (tinygltf
    // accepts a node that lists itself, or an ancestor, as a child).
    std::vector<int> roots;
    if (!model.scenes.empty()) {
        int s = model.defaultScene >= 0 ? model.defaultScene : 0;
        if (s >= int(model.scenes.size())) r.fail("default scene " + std::to_string(s) + " is out of range");
        roots = model.scenes[size_t(s)].nodes;
    } else {  // no scenes: every node that is nobody's child is a root
        std::set<int> children;
        for (const auto& n : model.nodes) children.insert(n.children.begin(), n.children.end());
        for (int i = 0; i < int(model.nodes.size()); ++i)
            if (!children.count(i)) roots.push_back(i);
    }
    for (size_t i = 0; i < model.meshes.size(); ++i)
        if (model.meshes[i].primitives.empty())
            warnings.push_back(path + ": mesh " + std::to_string(i) + " ('" + model.meshes[i].name + "') has no primitives");
    std::vector<int> state(model.nodes.size(), 0);  // 0 unseen, 1 on the path, 2 done
    struct Visit {
        int node;
        int depth;
        bool leave;  // true: the node's subtree is done
        glm::mat4 parent;
        int parent_node;  // its parent in Scene::nodes (animated files), -1 for a root
    };
    // A file with animations keeps its node tree (Scene::nodes, in this visiting order: parents
    // before children) so that its objects can be posed at any time; scene_node[file index].
    const bool animated = !model.animations.empty();
    std::vector<int> scene_node(model.nodes.size(), -1);
    std::vector<Visit> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, 1, false, transform, -1});
    while (!stack.empty()) {
        const Visit v = stack.back();
        stack.pop_back();
        const int ni = v.node;
        if (v.leave) {
            state[size_t(ni)] = 2;
            continue;
        }
        if (ni < 0 || ni >= int(model.nodes.size()))
            r.fail("node index " + std::to_string(ni) + " is out of range (the file has " +
                   std::to_string(model.nodes.size()) + " nodes)");
        const std::string what = "node " + std::to_string(ni);
        if (state[size_t(ni)] == 1) r.fail("node graph has a cycle through node " + std::to_string(ni));
        if (state[size_t(ni)] == 2) r.fail(what + " has more than one parent");
        if (v.depth > kMaxNodeDepth)
            r.fail(what + " is nested deeper than " + std::to_string(kMaxNodeDepth) + " levels in the node hierarchy");
        state[size_t(ni)] = 1;
        const auto& node = model.nodes[size_t(ni)];
        const NodeTransform local = node_local_transform(node, r, what);
        int me = -1;
        if (animated) {
            SceneNode sn;
            sn.rest = sn.current = local;
            if (node.extras.Has("ssrlab")) sn.current = saved_pose(node.extras.Get("ssrlab"), local, r, what);
            sn.name = node.name;
            sn.file_index = ni;
            sn.parent = v.parent_node;
            if (v.parent_node < 0) sn.root_transform = transform;
            scene.nodes.push_back(std::move(sn));
            me = scene_node[size_t(ni)] = int(scene.nodes.size()) - 1;
        }
        // An animated file saved by ssrlab stands in the pose it was saved in.
        const glm::mat4 world = v.parent * (me >= 0 ? scene.nodes[size_t(me)].current : local).local();
        if (!finite_matrix(world)) r.fail(what + ": its world transform overflows to Inf or NaN");
        if (node.mesh >= 0 || node.mesh < -1) {
            if (node.mesh >= int(model.meshes.size()) || node.mesh < 0)
                r.fail(what + ": mesh index " + std::to_string(node.mesh) +
                       " is out of range (the file has " + std::to_string(model.meshes.size()) + " meshes)");
            const auto& gmesh = model.meshes[size_t(node.mesh)];
            const bool drawable = invertible_transform(world);
            if (!drawable && !gmesh.primitives.empty())
                warnings.push_back(path + ": " + what + ": its world transform is singular or degenerate (a zero scale, or axes scaled more than 1e6 apart); mesh " +
                                   std::to_string(node.mesh) + " skipped");
            for (int p = 0; drawable && p < int(gmesh.primitives.size()); ++p) {
                auto [mesh, material] = primitive(node.mesh, p);
                if (mesh < 0) continue;
                Bounds b;
                for (const auto& q : scene.meshes[size_t(mesh)].positions) b.extend(q);
                for (int k = 0; k < 8; ++k) {
                    const glm::vec3 corner((k & 1) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y,
                                           (k & 4) ? b.max.z : b.min.z);
                    const glm::vec3 w(world * glm::vec4(corner, 1.0f));
                    if (!within_world(w))
                        r.fail(what + ": mesh " + std::to_string(node.mesh) + " reaches (" + num(w.x) + ", " + num(w.y) +
                               ", " + num(w.z) + ") in world space, beyond +-" + num(kMaxWorldCoordinate));
                }
                std::string name = node.name.empty() ? scene.meshes[size_t(mesh)].name : node.name;
                if (gmesh.primitives.size() > 1) name += "/" + std::to_string(p);
                const int object = scene.add_object(mesh, material, world, name);
                if (me >= 0) scene.nodes[size_t(me)].objects.push_back(object);
            }
        }
        if (node.skin >= int(model.skins.size()) || node.skin < -1)
            r.fail(what + ": skin index " + std::to_string(node.skin) + " is out of range");
        read_node_camera(model, r, node, world, what, scene);
        if (const int light = read_node_light(model, r, node, world, what, scene); light >= 0 && me >= 0)
            scene.nodes[size_t(me)].light = light;
        stack.push_back({ni, v.depth, true, glm::mat4(1.0f), -1});
        for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
            stack.push_back({*c, v.depth + 1, false, world, me});
    }
    return scene_node;
}

}  // namespace ssr::gltf_detail
