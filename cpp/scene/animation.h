// Animation: the node hierarchy of an animated glTF file, its keyframed channels, and the
// pose of the scene at a time t.
//
// glTF 2.0 animates a node's translation, rotation and scale; a node's world transform is its
// parents' times its own, so an animated parent moves its children. A file with animations
// keeps its node tree in the Scene (Scene::nodes) beside the flattened objects, so the
// objects' world transforms can be computed again at any time. Sampling follows the glTF 2.0
// specification's Appendix C: STEP holds a keyframe's value, LINEAR interpolates linearly
// (rotations by spherical linear interpolation), CUBICSPLINE evaluates the cubic Hermite
// spline with the keyframes' in- and out-tangents scaled by the keyframe interval (rotations
// normalised after it). Outside the keyframes a channel holds its first or last value.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <string>
#include <utility>
#include <vector>

namespace ssr {

class Scene;

// A glTF node's local transform: a matrix, or translation x rotation x scale.
struct NodeTransform {
    bool has_matrix = false;  // glTF forbids animating a node given by a matrix
    glm::mat4 matrix{1.0f};
    glm::vec3 translation{0.0f};
    // Unit (w, x, y, z), kept in double as read and sampled: a saved file gives the same float
    // rotation back when loaded (it is normalised again in double, then rounded).
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
    glm::vec3 scale{1.0f};
    glm::mat4 local() const;
};

// T x R x S as glTF composes a node's transform (scale first), in float.
glm::mat4 trs_matrix(const glm::vec3& translation, const glm::quat& rotation, const glm::vec3& scale);

// A node of a loaded glTF hierarchy (files with animations only).
struct SceneNode {
    std::string name;
    int file_index = -1;              // its index in the file, for messages
    int parent = -1;                  // index into Scene::nodes, -1 for a root
    glm::mat4 root_transform{1.0f};   // a root's parent: the transform the file was added with
    NodeTransform rest;               // as the file gives it
    NodeTransform current;            // the last pose set (rest until an animation plays; a file
                                      // ssrlab saved keeps it in the node's extras.ssrlab.pose)
    std::vector<int> objects;         // Scene::objects drawn at this node (one per primitive)
    int light = -1;                   // Scene::lights at this node (KHR_lights_punctual), or -1
};

struct AnimationSampler {
    enum class Interpolation { Step, Linear, CubicSpline };
    Interpolation interpolation = Interpolation::Linear;
    int components = 3;         // 3 (translation, scale) or 4 (rotation, quaternions x y z w)
    std::vector<float> times;   // seconds, >= 0, strictly increasing
    // `components` floats per keyframe; CUBICSPLINE: in-tangent, value, out-tangent per keyframe.
    std::vector<float> values;
};

struct AnimationChannel {
    enum class Path { Translation, Rotation, Scale };
    int node = -1;  // index into Scene::nodes
    Path path = Path::Translation;
    AnimationSampler sampler;
};

struct Animation {
    std::string name;
    std::string source;  // the file it came from, for messages
    std::vector<AnimationChannel> channels;
    float duration = 0.0f;  // the last keyframe time over its channels
};

const char* interpolation_name(AnimationSampler::Interpolation i);
const char* path_name(AnimationChannel::Path p);

// What is wrong with a sampler's keyframes (times, counts, finite values), in words, or "".
// Rotation keyframes (components 4) must have non-zero length; they are normalised here.
std::string check_sampler(AnimationSampler& s);

// The sampler's value at time t (seconds), clamped to its first and last keyframes
// (glTF 2.0 Appendix C); `out` receives `components` values.
void sample(const AnimationSampler& s, double t, double* out);

// The transforms that playing animations at their times gives the scene: each played
// animation is (index into Scene::animations, its local time in seconds, already wrapped when
// looping). Sets the `current` transform of every node the channels reach (the others keep
// theirs) and returns the world transforms of the objects and the lights those nodes carry,
// with the nodes below them. Throws SceneError naming the animation, node and time when a
// world transform cannot be drawn (a zero scale, beyond the world's limits).
struct ScenePose {
    struct LightPose {
        int light;
        glm::vec3 position, direction;  // the KHR_lights_punctual frame: the node's origin and its -z
    };
    std::vector<std::pair<int, glm::mat4>> objects;
    std::vector<LightPose> lights;
};
ScenePose pose_animations(Scene& scene, const std::vector<std::pair<int, double>>& played);

// Every node's world transform from the nodes' `current` transforms.
std::vector<glm::mat4> node_world_transforms(const Scene& scene);

}  // namespace ssr
