#include "passes/compute.h"

#include <map>

#include "core/errors.h"

namespace ssr {

bool is_sampler_type(GLenum t) {
    return (t >= GL_SAMPLER_1D && t <= GL_SAMPLER_2D_RECT_SHADOW) || (t >= GL_SAMPLER_1D_ARRAY && t <= GL_SAMPLER_CUBE_SHADOW) ||
           (t >= GL_INT_SAMPLER_1D && t <= GL_UNSIGNED_INT_SAMPLER_BUFFER) ||
           (t >= GL_SAMPLER_CUBE_MAP_ARRAY && t <= GL_UNSIGNED_INT_SAMPLER_CUBE_MAP_ARRAY) ||
           (t >= GL_SAMPLER_2D_MULTISAMPLE && t <= GL_UNSIGNED_INT_SAMPLER_2D_MULTISAMPLE_ARRAY);
}

bool is_image_type(GLenum t) { return t >= GL_IMAGE_1D && t <= GL_UNSIGNED_INT_IMAGE_2D_MULTISAMPLE_ARRAY; }

void check_bound_units(GLuint prog, const std::string& shader, const std::vector<GLuint>& texture_units,
                       const std::vector<GLuint>& image_units) {
    // A program passes once; its units are fixed at link time (layout(binding) only), so a later
    // frame would find the same. Keyed by the shader too: a released program's id may be reused.
    static std::map<GLuint, std::string> checked;
    const auto it = checked.find(prog);
    if (it != checked.end() && it->second == shader) return;
    GLint count = 0;
    glGetProgramInterfaceiv(prog, GL_UNIFORM, GL_ACTIVE_RESOURCES, &count);
    for (GLint i = 0; i < count; ++i) {
        const GLenum props[] = {GL_TYPE, GL_LOCATION, GL_ARRAY_SIZE};
        GLint v[3] = {0, -1, 1};
        glGetProgramResourceiv(prog, GL_UNIFORM, GLuint(i), 3, props, 3, nullptr, v);
        const bool sampler = is_sampler_type(GLenum(v[0])), image = is_image_type(GLenum(v[0]));
        if ((!sampler && !image) || v[1] < 0) continue;
        const std::vector<GLuint>& bound = sampler ? texture_units : image_units;
        for (GLint e = 0; e < v[2]; ++e) {
            GLint unit = -1;
            glGetUniformiv(prog, v[1] + e, &unit);
            if (std::find(bound.begin(), bound.end(), GLuint(unit)) != bound.end()) continue;
            GLchar name[256] = {0};
            glGetProgramResourceName(prog, GL_UNIFORM, GLuint(i), GLsizei(sizeof(name)), nullptr, name);
            throw ShaderError(shader + ": " + (sampler ? "sampler" : "image") + " uniform '" + name + "' is at " +
                                  (sampler ? "texture" : "image") + " unit " + std::to_string(unit) +
                                  ", which its pass does not bind by name",
                              shader, 0);
        }
    }
    checked[prog] = shader;
}

}  // namespace ssr
