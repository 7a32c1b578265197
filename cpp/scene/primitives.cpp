#include "scene/primitives.h"

#include <cmath>

namespace ssr {

Mesh make_plane(float uv_tiles) {
    Mesh m;
    m.name = "plane";
    m.positions = {{-0.5f, 0, -0.5f}, {-0.5f, 0, 0.5f}, {0.5f, 0, 0.5f}, {0.5f, 0, -0.5f}};
    m.normals.assign(4, glm::vec3(0, 1, 0));
    m.uvs = {{0, 0}, {0, uv_tiles}, {uv_tiles, uv_tiles}, {uv_tiles, 0}};
    m.indices = {0, 1, 2, 0, 2, 3};  // counter-clockwise seen from +y
    return m;
}

Mesh make_box() {
    Mesh m;
    m.name = "box";
    // Each face: normal n, and two axes u, v with u x v = n so the winding is CCW from outside.
    const glm::vec3 faces[6][3] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    for (const auto& f : faces) {
        const glm::vec3 n = f[0], u = f[1], v = f[2];
        const uint32_t base = uint32_t(m.positions.size());
        const float su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
        for (int k = 0; k < 4; ++k) {
            m.positions.push_back(0.5f * (n + su[k] * u + sv[k] * v));
            m.normals.push_back(n);
            m.uvs.push_back({0.5f * (su[k] + 1), 0.5f * (sv[k] + 1)});
        }
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    return m;
}

Mesh make_sphere(int segments, int rings) {
    Mesh m;
    m.name = "sphere";
    const float pi = 3.14159265358979f;
    for (int r = 0; r <= rings; ++r) {
        const float theta = pi * float(r) / float(rings);  // from +y down
        for (int s = 0; s <= segments; ++s) {
            const float phi = 2.0f * pi * float(s) / float(segments);
            const glm::vec3 p(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
            m.positions.push_back(p);
            m.normals.push_back(p);
            m.uvs.push_back({float(s) / float(segments), float(r) / float(rings)});
        }
    }
    const uint32_t row = uint32_t(segments + 1);
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const uint32_t a = uint32_t(r) * row + uint32_t(s), b = a + row;
            if (r != 0) m.indices.insert(m.indices.end(), {a, b, a + 1});
            if (r != rings - 1) m.indices.insert(m.indices.end(), {a + 1, b, b + 1});
        }
    return m;
}

}  // namespace ssr
