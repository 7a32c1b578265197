// glTF 2.0 (.gltf and .glb) import and export with tinygltf; images through OpenImageIO.
#pragma once

#include <string>
#include <vector>

#include "scene/scene.h"

namespace ssr {

struct GltfLoadOptions {
    // Buffers, images and environment maps may name files outside the model's folder
    // (absolute paths, `..`, symlinks leading out). Off by default: a file from elsewhere
    // must not make the loader read /etc/passwd or /dev/zero.
    bool allow_external_files = false;
};

// Appends the default scene of a glTF file to `scene`, each node's world transform
// premultiplied by `transform`. Returns the index of the first object added.
// Throws FileNotFound or SceneError; messages name the file, the offending object and what
// is wrong. What was skipped (points, lines, skins, morph targets, an empty result) is
// appended to `warnings`, one message per line, each naming the file.
int load_gltf(Scene& scene, const std::string& path, const glm::mat4& transform = glm::mat4(1.0f),
              const GltfLoadOptions& options = {}, std::vector<std::string>* warnings = nullptr);

// Writes `scene` as glTF 2.0: binary (.glb, everything embedded) or JSON (.gltf + a .bin
// beside it, images embedded in the buffer). Lights use KHR_lights_punctual; reflectivity,
// the ambient term and the environment travel in `extras`, so loading gives back the same scene.
// `folder`: where the file will finally live, when it is written elsewhere first (a staging
// folder renamed into place); references to files (an environment map) are made relative to it.
void save_gltf(const Scene& scene, const std::string& path, const std::string& folder = "");

}  // namespace ssr
