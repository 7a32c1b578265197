#include "render/ssr_uniforms.h"

#include <cctype>
#include <sstream>

#include "render/settings.h"

namespace ssr {

SsrUniforms ssr_uniforms(const RenderSettings& settings) {
    const RenderSettings s = settings.as_run();
    SsrUniforms su{};
#define SSR_UNIFORM_COPY_UNIFORM(kind, name) su.name = SSR_GPU_TYPE_##kind(s.name);
#define SSR_UNIFORM_COPY_PASS(kind, name)
#define SSR_DERIVED(kind, name, expr, doc) su.name = SSR_GPU_TYPE_##kind(expr);
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) SSR_UNIFORM_COPY_##place(kind, name)
#include "render/settings_fields.def"
#undef SSR_UNIFORM_COPY_UNIFORM
#undef SSR_UNIFORM_COPY_PASS
    return su;
}

namespace {

std::string upper(const std::string& s) {
    std::string u = s;
    for (char& c : u) c = char(std::toupper(static_cast<unsigned char>(c)));
    return u;
}

// One line of a member's meaning: its first sentence or clause, cut at 90 characters.
std::string gist(const std::string& unit, const std::string& doc) {
    std::string d = doc.substr(0, doc.find("; "));
    if (d.size() > 90) d = d.substr(0, 87) + "...";
    return (unit.empty() ? "" : "[" + unit + "] ") + d;
}

template <typename E>
void enum_constants(std::ostringstream& out, const char* field) {
    for (const auto& [value, name] : enum_names<E>())
        out << "const int " << upper(field) << "_" << upper(name) << " = " << int(value) << ";\n";
}

}  // namespace

std::string ssr_settings_glsl() {
    std::ostringstream out;
    out << "// Generated from cpp/render/settings_fields.def (ssr::ssr_settings_glsl): the settings whose\n"
           "// place is UNIFORM, in the layout of SsrUniforms (std140, 4-byte scalars).\n"
           "layout(std140, binding = " << kSsrSettingsBinding << ") uniform SsrSettings {\n";
#define SSR_GLSL_TYPE_INT "int"
#define SSR_GLSL_TYPE_UINT "uint"
#define SSR_GLSL_TYPE_FLOAT "float"
#define SSR_GLSL_TYPE_BOOL "int"
#define SSR_GLSL_TYPE_ENUM "int"
#define SSR_GLSL_MEMBER_UNIFORM(kind, name, unit, doc) \
    out << "    " SSR_GLSL_TYPE_##kind " " #name ";  // " << gist(unit, doc) << "\n";
#define SSR_GLSL_MEMBER_PASS(kind, name, unit, doc)
#define SSR_DERIVED(kind, name, expr, doc) SSR_GLSL_MEMBER_UNIFORM(kind, name, "", doc)
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) \
    SSR_GLSL_MEMBER_##place(kind, name, unit, doc)
#include "render/settings_fields.def"
    out << "} ssr;\n\n";
    // The names of the enum settings in the block, valued as the C++ enums.
#define SSR_ENUM_CONSTANTS_UNIFORM(ctype, name) enum_constants<ctype>(out, #name);
#define SSR_ENUM_CONSTANTS_PASS(ctype, name)
#define SSR_CONSTANTS_INT(ctype, name, place)
#define SSR_CONSTANTS_UINT(ctype, name, place)
#define SSR_CONSTANTS_FLOAT(ctype, name, place)
#define SSR_CONSTANTS_BOOL(ctype, name, place)
#define SSR_CONSTANTS_ENUM(ctype, name, place) SSR_ENUM_CONSTANTS_##place(ctype, name)
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) SSR_CONSTANTS_##kind(ctype, name, place)
#include "render/settings_fields.def"
    return out.str();
}

}  // namespace ssr
