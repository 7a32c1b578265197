#include "render/buffer_bindings.h"

namespace ssr {

std::vector<BufferBinding> buffer_bindings() {
    std::vector<BufferBinding> out;
#define SSR_BUFFER_BINDING(Block, NAME, interface, binding, doc) \
    out.push_back({#Block, "BUFFER_" #NAME, std::string(#interface) == "STORAGE", k##Block##Binding, doc});
#include "render/buffer_bindings.def"
    return out;
}

std::string buffer_bindings_glsl() {
    std::string out = "// cpp/render/buffer_bindings.def: the binding point of every block (buffer_bindings_glsl)\n";
    for (const BufferBinding& b : buffer_bindings())
        out += "#define " + b.define + " " + std::to_string(b.binding) + "\n";
    return out;
}

}  // namespace ssr
