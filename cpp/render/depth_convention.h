// Every depth convention of the renderer in one place: the projection matrix, the clip
// control, the clear value, the depth compare function, and the GLSL defines that select
// the matching linearisation and "farther than" test in shaders/lib/depth_convention.glsl.
//
// Standard (OpenGL default, the thesis's convention, seed 000 section 2.3.4): NDC z in
// [-1, 1], window depth d = (z_ndc + 1)/2, near -> 0, far -> 1, clear 1, compare LESS.
// Linearisation is the thesis's formula z = 2fn / (z_s(f - n) - (f + n)) with z_s = 2d - 1.
//
// Reversed-Z (float depth): glClipControl(LOWER_LEFT, ZERO_TO_ONE), near -> 1, far -> 0,
// clear 0, compare GREATER. A float's dense precision near 0 then lands on the far range,
// which nearly equalises the relative depth precision over the whole frustum.
#pragma once

#include <glm/glm.hpp>
#include <string>

#include "core/gl.h"
#include "core/shader_library.h"

namespace ssr {

enum class DepthMode { Standard, ReversedZ };

DepthMode parse_depth_mode(const std::string& name);
std::string depth_mode_name(DepthMode m);

struct DepthConvention {
    DepthMode mode = DepthMode::Standard;

    glm::mat4 projection(float fov_y_radians, float aspect, float near_plane, float far_plane) const;
    float clear_depth() const { return mode == DepthMode::Standard ? 1.0f : 0.0f; }
    GLenum compare() const { return mode == DepthMode::Standard ? GL_LESS : GL_GREATER; }
    // The same test passing equal depths too: a later fragment at the kept depth replaces it.
    GLenum compare_or_equal() const { return mode == DepthMode::Standard ? GL_LEQUAL : GL_GEQUAL; }
    // Applies clip control, depth function and clear value to the GL state.
    void apply_gl_state() const;
    // Shader defines for shaders/lib/depth_convention.glsl.
    void add_defines(Defines& d) const;
    // View-space depth (positive distance along the view axis) of window depth `d`.
    float linearize(float d, float near_plane, float far_plane) const;
};

}  // namespace ssr
