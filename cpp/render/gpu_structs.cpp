#include "render/gpu_structs.h"

#include <sstream>

namespace ssr {

namespace {

// A member's comment, broken before 100 columns into lines under its first one.
void comment(std::ostringstream& out, const std::string& indent, const std::string& text) {
    std::istringstream words(text);
    std::string word, line;
    while (words >> word) {
        if (!line.empty() && indent.size() + 3 + line.size() + 1 + word.size() > 100) {
            out << indent << "// " << line << "\n";
            line.clear();
        }
        line += (line.empty() ? "" : " ") + word;
    }
    if (!line.empty()) out << indent << "// " << line << "\n";
}

}  // namespace

std::vector<GpuStructGlsl> gpu_struct_glsl() {
    std::vector<GpuStructGlsl> files;
    std::ostringstream out;
    std::string close;  // what closes the open struct or block
    const auto open = [&](const char* block, const char* doc) {
        files.push_back({std::string("generated/") + block + ".glsl", ""});
        out.str("");
        out << "// Generated from cpp/render/gpu_structs.def (ssr::gpu_struct_glsl), in the layout of the\n"
               "// C++ struct of the same row (cpp/render/gpu_structs.h).\n";
        comment(out, "", doc);
    };
#define SSR_GPU_UNIFORM_BLOCK(Cpp, Block, instance, doc)                           \
    open(#Block, doc);                                                                      \
    out << "layout(std140, binding = " << k##Block##Binding << ") uniform " #Block " {\n"; \
    close = "} " #instance ";\n";
#define SSR_GPU_STORAGE_ARRAY(Cpp, Struct, Block, array, doc)                          \
    open(#Block, doc);                                                                          \
    out << "struct " #Struct " {\n";                                                            \
    close = std::string("};\n\nlayout(std430, binding = ") + std::to_string(k##Block##Binding) + \
            ") readonly buffer " #Block " { " #Struct " " #array "[]; };\n";
#define SSR_GPU_MEMBER(type, name, doc) \
    comment(out, "    ", doc);          \
    out << "    " #type " " #name ";\n";
#define SSR_GPU_ARRAY(type, name, count, doc) \
    comment(out, "    ", doc);                \
    out << "    " #type " " #name "[" << (count) << "];\n";
#define SSR_GPU_VEC3_INT(name, int_name, doc) \
    comment(out, "    ", doc);                \
    out << "    vec4 " #name ";\n";
#define SSR_GPU_END()    \
    out << close;        \
    files.back().text = out.str();
#include "render/gpu_structs.def"
    return files;
}

std::vector<GpuStructLayout> gpu_struct_layouts() {
    std::vector<GpuStructLayout> out;
#define SSR_GPU_UNIFORM_BLOCK(Cpp, Block, instance, doc)                      \
    {                                                                                  \
        using S = Cpp;                                                                 \
        out.push_back({#Cpp, #Block, "", "std140", k##Block##Binding, sizeof(S), {}});
#define SSR_GPU_STORAGE_ARRAY(Cpp, Struct, Block, array, doc) \
    {                                                                  \
        using S = Cpp;                                                 \
        out.push_back({#Cpp, #Block, #Struct, "std430", k##Block##Binding, sizeof(S), {}});
#define SSR_GPU_MEMBER(type, name, doc) out.back().members.push_back({#name, #type, 0, offsetof(S, name)});
#define SSR_GPU_ARRAY(type, name, count, doc) \
    out.back().members.push_back({#name, #type, size_t(count), offsetof(S, name)});
#define SSR_GPU_VEC3_INT(name, int_name, doc) out.back().members.push_back({#name, "vec4", 0, offsetof(S, name)});
#define SSR_GPU_END() }
#include "render/gpu_structs.def"
    return out;
}

}  // namespace ssr
