// The binding point of every uniform and shader storage block of the hand-written shaders, made
// from cpp/render/buffer_bindings.def: the C++ constants the host binds with, the GLSL defines the
// shaders declare with and the table a linked program is checked against come from one row per
// block, so a shader and its host cannot name two different numbers.
#pragma once

#include <string>
#include <vector>

namespace ssr {

// k<Block>Binding: the binding point of GLSL block <Block> (its interface's own numbering).
#define SSR_BUFFER_BINDING(Block, NAME, interface, binding, doc) constexpr int k##Block##Binding = binding;
#include "render/buffer_bindings.def"

// One row of the table.
struct BufferBinding {
    std::string block;   // the GLSL block name
    std::string define;  // BUFFER_<NAME>
    bool storage = true; // a shader storage block (else a uniform block)
    int binding = 0;
    std::string doc;
};
std::vector<BufferBinding> buffer_bindings();

// `#define BUFFER_<NAME> <binding>` for every row, the text the ShaderLibrary puts ahead of every
// program's source (after #version and the program's own defines).
std::string buffer_bindings_glsl();

}  // namespace ssr
