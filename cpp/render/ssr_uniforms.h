// Screen-space reflection settings as the shaders see them (uniform buffer kSsrSettingsBinding of
// cpp/render/buffer_bindings.def, std140 with scalars only). The members, their upload and the
// GLSL block the shaders include (shaders/lib/ssr_settings.glsl) are all made from
// cpp/render/settings_fields.def: the settings whose place is UNIFORM, after the derived members.
#pragma once

#include <cstdint>
#include <string>

#include "render/buffer_bindings.h"

namespace ssr {

// The member type of each kind of setting (bool and enum travel as int).
#define SSR_GPU_TYPE_INT int32_t
#define SSR_GPU_TYPE_UINT uint32_t
#define SSR_GPU_TYPE_FLOAT float
#define SSR_GPU_TYPE_BOOL int32_t
#define SSR_GPU_TYPE_ENUM int32_t
#define SSR_UNIFORM_MEMBER_UNIFORM(kind, name) SSR_GPU_TYPE_##kind name;
#define SSR_UNIFORM_MEMBER_PASS(kind, name)

// std140 with 4-byte scalars only: each member at the next 4 bytes, in declaration order; the
// block's size rounds up to 16 bytes, as alignas does here.
struct alignas(16) SsrUniforms {
#define SSR_DERIVED(kind, name, expr, doc) SSR_GPU_TYPE_##kind name;
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) \
    SSR_UNIFORM_MEMBER_##place(kind, name)
#include "render/settings_fields.def"
};
static_assert(sizeof(SsrUniforms) % 16 == 0, "std140 size of SsrUniforms");

struct RenderSettings;
SsrUniforms ssr_uniforms(const RenderSettings& s);

// The GLSL declaration of the SsrSettings block matching SsrUniforms, and an int constant per
// name of every enum setting in it (e.g. SAMPLING_VNDF); shaders include it through
// lib/ssr_settings.glsl (ShaderLibrary's generated file kSsrSettingsGlslName).
std::string ssr_settings_glsl();
constexpr const char* kSsrSettingsGlslName = "generated/ssr_settings_block.glsl";

}  // namespace ssr
