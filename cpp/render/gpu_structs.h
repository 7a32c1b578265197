// The records shared by the host and the shaders (frame constants, the scene's objects and
// materials, lights), made from cpp/render/gpu_structs.def (their binding points are rows of
// cpp/render/buffer_bindings.def, whose k<Block>Binding this header includes): each
// struct's members, the GLSL declaration the shaders include and the layout checks below come
// from one row per member, so the two sides cannot drift apart.
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "render/buffer_bindings.h"

namespace ssr {

// The block layout rules (OpenGL 4.5 core profile, 7.6.2.2) for the member types the table
// allows: each type's base alignment and size under std430; std140 rounds an array element's
// alignment and stride and a struct's alignment up to a vec4's.
enum class GpuLayout { Std140, Std430 };
struct GpuType {
    size_t align, size;
};
namespace gpu_type {
constexpr GpuType float_{4, 4}, int_{4, 4}, uint_{4, 4};
constexpr GpuType vec2{8, 8}, ivec2{8, 8};
constexpr GpuType vec4{16, 16}, ivec4{16, 16}, uvec4{16, 16};
constexpr GpuType mat4{16, 64};  // four vec4 columns
}  // namespace gpu_type
// The C++ member type of each GLSL type.
#define SSR_GPU_CTYPE_float float
#define SSR_GPU_CTYPE_int int32_t
#define SSR_GPU_CTYPE_uint uint32_t
#define SSR_GPU_CTYPE_vec2 glm::vec2
#define SSR_GPU_CTYPE_ivec2 glm::ivec2
#define SSR_GPU_CTYPE_vec4 glm::vec4
#define SSR_GPU_CTYPE_ivec4 glm::ivec4
#define SSR_GPU_CTYPE_uvec4 glm::uvec4
#define SSR_GPU_CTYPE_mat4 glm::mat4
// The GpuType of each (float, int and uint are keywords, hence the underscore).
#define SSR_GPU_TYPE_float gpu_type::float_
#define SSR_GPU_TYPE_int gpu_type::int_
#define SSR_GPU_TYPE_uint gpu_type::uint_
#define SSR_GPU_TYPE_vec2 gpu_type::vec2
#define SSR_GPU_TYPE_ivec2 gpu_type::ivec2
#define SSR_GPU_TYPE_vec4 gpu_type::vec4
#define SSR_GPU_TYPE_ivec4 gpu_type::ivec4
#define SSR_GPU_TYPE_uvec4 gpu_type::uvec4
#define SSR_GPU_TYPE_mat4 gpu_type::mat4

struct GpuField {
    std::string_view name;
    GpuType type;
    size_t count;  // 0: not an array
};

constexpr size_t gpu_round_up(size_t x, size_t a) { return (x + a - 1) / a * a; }
constexpr size_t gpu_field_align(const GpuField& f, GpuLayout l) {
    return f.count && l == GpuLayout::Std140 ? gpu_round_up(f.type.align, 16) : f.type.align;
}
constexpr size_t gpu_field_size(const GpuField& f, GpuLayout l) {
    if (!f.count) return f.type.size;
    const size_t stride = gpu_round_up(f.type.size, gpu_field_align(f, l));
    return stride * f.count;
}
// The offset of member `name` in a block laid out by `l`; the block's end when there is none.
template <size_t N>
constexpr size_t gpu_offset(const GpuField (&fields)[N], GpuLayout l, std::string_view name) {
    size_t at = 0;
    for (const GpuField& f : fields) {
        at = gpu_round_up(at, gpu_field_align(f, l));
        if (f.name == name) return at;
        at += gpu_field_size(f, l);
    }
    return at;
}
template <size_t N>
constexpr size_t gpu_struct_align(const GpuField (&fields)[N], GpuLayout l) {
    size_t a = l == GpuLayout::Std140 ? 16 : 1;
    for (const GpuField& f : fields) a = gpu_field_align(f, l) > a ? gpu_field_align(f, l) : a;
    return a;
}
template <size_t N>
constexpr size_t gpu_struct_size(const GpuField (&fields)[N], GpuLayout l) {
    return gpu_round_up(gpu_offset(fields, l, std::string_view()), gpu_struct_align(fields, l));
}

// Each struct's fields and layout, in namespace gpu_layout::<Cpp>.
#define SSR_GPU_UNIFORM_BLOCK(Cpp, Block, instance, doc) \
    namespace gpu_layout::Cpp {                                    \
    constexpr GpuLayout layout = GpuLayout::Std140;                \
    constexpr GpuField fields[] = {
#define SSR_GPU_STORAGE_ARRAY(Cpp, Struct, Block, array, doc) \
    namespace gpu_layout::Cpp {                                         \
    constexpr GpuLayout layout = GpuLayout::Std430;                     \
    constexpr GpuField fields[] = {
#define SSR_GPU_MEMBER(type, name, doc) {#name, SSR_GPU_TYPE_##type, 0},
#define SSR_GPU_ARRAY(type, name, count, doc) {#name, SSR_GPU_TYPE_##type, count},
#define SSR_GPU_VEC3_INT(name, int_name, doc) {#name, gpu_type::vec4, 0},
#define SSR_GPU_END() \
    }                 \
    ;                 \
    }
#include "render/gpu_structs.def"

// The structs, aligned as their GLSL counterparts.
#define SSR_GPU_UNIFORM_BLOCK(Cpp, Block, instance, doc) \
    struct alignas(gpu_struct_align(gpu_layout::Cpp::fields, gpu_layout::Cpp::layout)) Cpp {
#define SSR_GPU_STORAGE_ARRAY(Cpp, Struct, Block, array, doc) SSR_GPU_UNIFORM_BLOCK(Cpp, , , )
#define SSR_GPU_MEMBER(type, name, doc) SSR_GPU_CTYPE_##type name;
#define SSR_GPU_ARRAY(type, name, count, doc) SSR_GPU_CTYPE_##type name[count];
#define SSR_GPU_VEC3_INT(name, int_name, doc) \
    float name[3];                            \
    int32_t int_name;
#define SSR_GPU_END() \
    }                 \
    ;
#include "render/gpu_structs.def"

// Every member where the GLSL layout puts it, and every struct of the size it has there (an
// array of records steps by it).
#define SSR_GPU_UNIFORM_BLOCK(Cpp, Block, instance, doc) \
    namespace gpu_layout::Cpp {                                    \
    using S = ::ssr::Cpp;                                          \
    static_assert(sizeof(S) == gpu_struct_size(fields, layout), "GLSL size of " #Cpp);
#define SSR_GPU_STORAGE_ARRAY(Cpp, Struct, Block, array, doc) SSR_GPU_UNIFORM_BLOCK(Cpp, , , )
#define SSR_GPU_MEMBER(type, name, doc) \
    static_assert(offsetof(S, name) == gpu_offset(fields, layout, #name), "GLSL offset of " #name);
#define SSR_GPU_ARRAY(type, name, count, doc) SSR_GPU_MEMBER(type, name, doc)
#define SSR_GPU_VEC3_INT(name, int_name, doc)                                                       \
    static_assert(offsetof(S, name) == gpu_offset(fields, layout, #name), "GLSL offset of " #name); \
    static_assert(offsetof(S, int_name) == offsetof(S, name) + 12, "the w of " #name);
#define SSR_GPU_END() }
#include "render/gpu_structs.def"

// The GLSL declaration of each table entry, as (generated file name, text): the Renderer adds
// each to its ShaderLibrary, where lib/frame_uniforms.glsl, lib/lights.glsl and
// lib/scene_data.glsl include them as "generated/<Block>.glsl".
struct GpuStructGlsl {
    std::string file, text;
};
std::vector<GpuStructGlsl> gpu_struct_glsl();

// Each struct's C++ layout (sizeof, offsetof), for comparing with what a GL driver reports for
// the generated GLSL.
struct GpuStructLayout {
    std::string cpp, block, glsl_struct;  // glsl_struct: empty for a uniform block
    std::string layout;                   // "std140" or "std430"
    int binding = 0;
    size_t size = 0;
    struct Member {
        std::string name, type;
        size_t count = 0;  // 0: not an array
        size_t offset = 0;
    };
    std::vector<Member> members;
};
std::vector<GpuStructLayout> gpu_struct_layouts();

}  // namespace ssr
