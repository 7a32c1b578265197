// GLSL 4.50 programs built from the files under shaders/.
//
// A stage file starts with `#version 450 core`; it may `#include "lib/name.glsl"` shared
// function files (resolved relative to the including file, then to the shader root, each
// file at most once per stage). Variants are chosen by #defines, inserted after #version.
// Compiled programs are cached per (stage files, defines). A generated file (add_generated)
// is included by its name, as if it lay under the shader root. Every file gets its own GLSL
// source-string number through `#line`, so compiler messages are translated back to
// "shaders/<file>:<line>" and raised as ShaderError.
//
// Interface blocks take their binding points from one table (set_block_bindings; the Renderer
// gives cpp/render/buffer_bindings.def): its defines BUFFER_<NAME> precede every program's source,
// and every linked program's active uniform and storage blocks are checked against it once.
#pragma once

#include <GL/gl.h>

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace ssr {

class EglContext;

// Ordered so that the cache key of a variant does not depend on insertion order.
using Defines = std::map<std::string, std::string>;

class ShaderLibrary {
public:
    explicit ShaderLibrary(std::filesystem::path root);
    ~ShaderLibrary();

    // Returns the linked program for these stage files (e.g. {"passes/depth_peel.vert",
    // "passes/depth_peel.frag"} or {"passes/lighting.comp"}) and defines.
    GLuint program(const std::vector<std::string>& stages, const Defines& defines = {});

    const std::filesystem::path& root() const { return root_; }
    // A file made by the program rather than read from the shader folder: `#include "name"`
    // reads `text` (before any program is built; error messages show the file as `name`).
    void add_generated(const std::string& name, std::string text) { generated_[name] = std::move(text); }

    // The binding point of an interface block, by its GLSL block name.
    struct BlockBinding {
        bool storage = true;  // a shader storage block (else a uniform block)
        int binding = 0;
        std::string define;   // what its shaders write for the binding, BUFFER_<NAME>
    };
    // `prelude` (the table's #defines) is put ahead of every program's source, after its own
    // defines; every program linked afterwards must declare each active block listed in `table`
    // at its binding and interface, and may declare no other unless one of its stages lies outside
    // the shader tree (a user pass: its own blocks are its own business). Before any program.
    void set_block_bindings(std::string prelude, std::map<std::string, BlockBinding> table) {
        prelude_ = std::move(prelude);
        block_bindings_ = std::move(table);
    }
    void release();  // deletes every cached program (in the current context)
    size_t cached_programs() const { return cache_.size(); }

    struct Preprocessed {
        std::string text;
        std::vector<std::string> files;  // files[i] is GLSL source-string number i
    };
    // Exposed for tests and tooling: the source handed to the GL compiler.
    Preprocessed preprocess(const std::string& stage, const Defines& defines) const;

private:
    void append_file(const std::filesystem::path& file, const std::filesystem::path& display,
                     Preprocessed& out, std::vector<std::string>& stack) const;
    GLuint compile_stage(const std::string& stage, const Defines& defines) const;

    std::filesystem::path root_;
    std::map<std::string, GLuint> cache_;
    std::map<std::string, std::string> generated_;
    std::string prelude_;
    std::map<std::string, BlockBinding> block_bindings_;
};

// What a linked program's driver made of a uniform or storage block (ARB_program_interface_query):
// its data size and each active member's byte offset, as the driver names them ("Block.member"
// for a uniform block's, "array[0].member" for a storage buffer's records, whose stride is
// top_level_stride). Lets a test hold a generated declaration against the C++ struct it mirrors.
struct BlockLayout {
    bool storage = false;  // a shader storage block (else a uniform block)
    int data_size = 0;
    struct Member {
        std::string name;
        int offset = 0, top_level_stride = 0;
    };
    std::vector<Member> members;
};
// Throws std::invalid_argument when the program has no active block of that name.
BlockLayout block_layout(GLuint program, const std::string& block);

// Turns a driver's info log into "file:line: message" lines (Mesa and NVIDIA formats).
// Returns the translated log; *first_file / *first_line receive the first error's place.
std::string translate_shader_log(const std::string& log, const std::vector<std::string>& files,
                                 std::string* first_file, int* first_line);

}  // namespace ssr
