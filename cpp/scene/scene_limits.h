// What a scene may hold so that every value the pipeline derives from it stays finite in
// float32 and in the half-float lighting buffers. One set of limits for every way a scene is
// made (glTF files, numpy meshes, primitives, lights and environments set from Python): each
// check returns the problem in words, or an empty string, and the caller names the object.
#pragma once

#include <glm/glm.hpp>
#include <string>

namespace ssr {

// World-space coordinates beyond this lose float precision to the point where view-space
// positions, squared distances and depth reconstruction break down (float32 spacing at 1e9 is
// 64 units).
constexpr double kMaxWorldCoordinate = 1e9;
// Light colour x intensity: "lit" and the reflection are RGBA16F (largest finite value 65504),
// so a lit pixel must stay well below it after the BRDF and the sum over lights.
constexpr double kMaxLightPower = 1e4;
// Ambient and environment radiance, for the same buffers.
constexpr double kMaxRadiance = 1e3;
// Axes of one object's transform scaled more than this apart: normals are transformed by the
// inverse transpose, whose columns then differ by the square of it and underflow in float.
constexpr double kMaxScaleRatio = 1e6;
// Tolerance on the bottom row (0, 0, 0, 1) of an affine matrix, for exporters' rounding.
constexpr double kAffineTolerance = 1e-6;

// Finite, with the bottom row (0, 0, 0, 1) glTF 2.0 requires of node matrices.
std::string affine_problem(const glm::mat4& m);
// A world or object transform: finite, affine (glTF 2.0 requires decomposable TRS matrices;
// a projective bottom row turns positions into w-divided values the G-buffer cannot hold),
// and with a well-conditioned, invertible 3x3 part.
std::string transform_problem(const glm::mat4& m);
// Where `m` (already checked by transform_problem) takes an object of object-space bounds
// [lo, hi] beyond kMaxWorldCoordinate: the first corner that does, in words, or "".
std::string world_bounds_problem(const glm::mat4& m, const glm::vec3& lo, const glm::vec3& hi);
// A light's colour, intensity, direction and position.
struct Light;
std::string light_problem(const Light& l);
// An RGB radiance scaled by `intensity` (ambient, environment colours).
std::string radiance_problem(const glm::vec3& rgb, float intensity);
// A world-space point a camera stands at or looks at.
std::string world_point_problem(const glm::vec3& p);
// A number for a message (6 significant digits).
std::string number_text(double v);

}  // namespace ssr
