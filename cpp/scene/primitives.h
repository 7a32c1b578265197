// Procedural meshes for scene builders: plane, box and sphere, with normals and UVs.
#pragma once

#include "scene/scene.h"

namespace ssr {

// A square in the xz plane centred at the origin, normal +y, side 1 (scale it with the
// object transform); `tiles` repeats the UVs.
Mesh make_plane(float uv_tiles = 1.0f);
// A unit cube centred at the origin with flat faces (24 vertices).
Mesh make_box();
// A unit-radius UV sphere centred at the origin.
Mesh make_sphere(int segments = 48, int rings = 24);

}  // namespace ssr
