#include "core/shader_library.h"

#include "core/gl.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "core/errors.h"

namespace fs = std::filesystem;

namespace ssr {

namespace {

std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    if (!in) throw ShaderError("cannot read shader file " + p.string(), p.string(), 0);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

GLenum stage_type(const std::string& file) {
    const std::string ext = fs::path(file).extension().string();
    if (ext == ".vert") return GL_VERTEX_SHADER;
    if (ext == ".frag") return GL_FRAGMENT_SHADER;
    if (ext == ".comp") return GL_COMPUTE_SHADER;
    if (ext == ".geom") return GL_GEOMETRY_SHADER;
    throw ShaderError("unknown shader stage extension '" + ext + "' of " + file, file, 0);
}

// Matches `#include "x"` with optional spaces and a trailing // comment.
const std::regex& include_re() {
    static const std::regex re(R"(^\s*#\s*include\s*"([^"]+)\"\s*(//.*)?$)");
    return re;
}

}  // namespace

ShaderLibrary::ShaderLibrary(fs::path root) : root_(std::move(root)) {
    if (!fs::is_directory(root_))
        throw ShaderError("shader folder not found: " + root_.string(), root_.string(), 0);
}

ShaderLibrary::~ShaderLibrary() {
    // Programs are deleted by release(), called by the Renderer with its context current.
}

void ShaderLibrary::release() {
    for (const auto& [key, prog] : cache_) glDeleteProgram(prog);
    cache_.clear();
}

void ShaderLibrary::append_file(const fs::path& file, const fs::path& display, Preprocessed& out,
                                std::vector<std::string>& stack) const {
    const std::string name = display.generic_string();
    if (std::find(out.files.begin(), out.files.end(), name) != out.files.end()) return;  // once
    const int index = int(out.files.size());
    out.files.push_back(name);
    stack.push_back(name);

    const auto generated = generated_.find(name);
    std::istringstream in(generated != generated_.end() ? generated->second : read_text(file));
    std::string line;
    int line_no = 0;
    out.text += "#line 1 " + std::to_string(index) + "\n";
    while (std::getline(in, line)) {
        ++line_no;
        std::smatch m;
        if (line.rfind("#version", 0) == 0) {
            if (index != 0 || line_no != 1)
                throw ShaderError(name + ":" + std::to_string(line_no) +
                                      ": #version belongs on the first line of a stage file only",
                                  name, line_no);
            out.text += "\n";  // the stage's #version was emitted ahead of the defines
            continue;
        }
        if (std::regex_match(line, m, include_re())) {
            const std::string target = m[1].str();
            if (generated_.count(target)) {
                append_file(fs::path(target), fs::path(target), out, stack);
                out.text += "#line " + std::to_string(line_no + 1) + " " + std::to_string(index) + "\n";
                continue;
            }
            fs::path resolved = file.parent_path() / target;
            fs::path shown = display.parent_path() / target;
            if (!fs::exists(resolved)) {
                resolved = root_ / target;
                shown = fs::path(target);
            }
            if (!fs::exists(resolved))
                throw ShaderError(name + ":" + std::to_string(line_no) + ": #include \"" + target +
                                      "\" not found (looked beside the file and under " +
                                      root_.string() + ")",
                                  name, line_no);
            const std::string shown_name = shown.lexically_normal().generic_string();
            if (std::find(stack.begin(), stack.end(), shown_name) != stack.end())
                throw ShaderError(name + ":" + std::to_string(line_no) + ": #include cycle through " +
                                      shown_name,
                                  name, line_no);
            append_file(resolved.lexically_normal(), shown.lexically_normal(), out, stack);
            out.text += "#line " + std::to_string(line_no + 1) + " " + std::to_string(index) + "\n";
            continue;
        }
        out.text += line;
        out.text += "\n";
    }
    stack.pop_back();
}

ShaderLibrary::Preprocessed ShaderLibrary::preprocess(const std::string& stage, const Defines& defines) const {
    Preprocessed out;
    const fs::path file = root_ / stage;
    {
        std::ifstream probe(file);
        std::string first;
        if (!probe || !std::getline(probe, first))
            throw ShaderError("cannot read shader file " + file.string(), stage, 0);
        if (first.rfind("#version", 0) != 0)
            throw ShaderError(stage + ":1: a stage file must start with #version", stage, 1);
        out.text = first + "\n";
    }
    for (const auto& [name, value] : defines) out.text += "#define " + name + " " + value + "\n";
    out.text += prelude_;
    if (!prelude_.empty() && prelude_.back() != '\n') out.text += "\n";
    std::vector<std::string> stack;
    append_file(file, fs::path(stage), out, stack);
    return out;
}

BlockLayout block_layout(GLuint program, const std::string& block) {
    BlockLayout out;
    GLenum interface = GL_UNIFORM_BLOCK, variables = GL_UNIFORM;
    GLuint index = glGetProgramResourceIndex(program, interface, block.c_str());
    if (index == GL_INVALID_INDEX) {
        interface = GL_SHADER_STORAGE_BLOCK;
        variables = GL_BUFFER_VARIABLE;
        index = glGetProgramResourceIndex(program, interface, block.c_str());
        out.storage = true;
    }
    if (index == GL_INVALID_INDEX) throw std::invalid_argument("the program has no active block '" + block + "'");
    const GLenum block_props[] = {GL_BUFFER_DATA_SIZE, GL_NUM_ACTIVE_VARIABLES};
    GLint values[2] = {0, 0};
    glGetProgramResourceiv(program, interface, index, 2, block_props, 2, nullptr, values);
    out.data_size = values[0];
    std::vector<GLint> members(size_t(std::max(values[1], 0)));
    const GLenum active = GL_ACTIVE_VARIABLES;
    glGetProgramResourceiv(program, interface, index, 1, &active, GLsizei(members.size()), nullptr, members.data());
    for (GLint m : members) {
        char name[256] = {0};
        glGetProgramResourceName(program, variables, GLuint(m), sizeof(name), nullptr, name);
        BlockLayout::Member member;
        member.name = name;
        const GLenum offset_prop = GL_OFFSET;
        glGetProgramResourceiv(program, variables, GLuint(m), 1, &offset_prop, 1, nullptr, &member.offset);
        if (out.storage) {
            const GLenum stride_prop = GL_TOP_LEVEL_ARRAY_STRIDE;
            glGetProgramResourceiv(program, variables, GLuint(m), 1, &stride_prop, 1, nullptr, &member.top_level_stride);
        }
        out.members.push_back(std::move(member));
    }
    return out;
}

std::string translate_shader_log(const std::string& log, const std::vector<std::string>& files,
                                  std::string* first_file, int* first_line) {
    // Mesa:   "0:12(5): error: ..."      NVIDIA: "0(12) : error C1008: ..."
    static const std::regex mesa(R"(^(\d+):(\d+)\((\d+)\):\s*(.*)$)");
    static const std::regex nvidia(R"(^(\d+)\((\d+)\)\s*:\s*(.*)$)");
    std::istringstream in(log);
    std::ostringstream out;
    std::string line;
    bool found = false;
    while (std::getline(in, line)) {
        std::smatch m;
        int src = -1, ln = 0;
        std::string msg;
        if (std::regex_match(line, m, mesa)) {
            src = std::stoi(m[1].str());
            ln = std::stoi(m[2].str());
            msg = m[4].str();
        } else if (std::regex_match(line, m, nvidia)) {
            src = std::stoi(m[1].str());
            ln = std::stoi(m[2].str());
            msg = m[3].str();
        }
        if (src >= 0) {
            const std::string file = src < int(files.size()) ? files[size_t(src)] : ("<source " + std::to_string(src) + ">");
            out << (fs::path(file).is_absolute() ? "" : "shaders/") << file << ":" << ln << ": " << msg << "\n";
            const bool is_error = msg.find("error") != std::string::npos;
            if (is_error && !found) {
                found = true;
                if (first_file) *first_file = file;
                if (first_line) *first_line = ln;
            }
        } else if (!line.empty()) {
            out << line << "\n";
        }
    }
    return out.str();
}

GLuint ShaderLibrary::compile_stage(const std::string& stage, const Defines& defines) const {
    const Preprocessed src = preprocess(stage, defines);
    const GLuint shader = glCreateShader(stage_type(stage));
    const char* text = src.text.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
        std::string log(size_t(std::max(len, 1)), '\0');
        glGetShaderInfoLog(shader, len, nullptr, log.data());
        glDeleteShader(shader);
        std::string file = stage;
        int line = 0;
        const std::string translated = translate_shader_log(log.c_str(), src.files, &file, &line);
        std::string defs;
        for (const auto& [k, v] : defines) defs += " " + k + "=" + v;
        // Files of the shader tree are named as shaders/<file>; a file outside it (a user pass's)
        // by its own path.
        const std::string shown = fs::path(file).is_absolute() ? file : "shaders/" + file;
        throw ShaderError("GLSL compile error in " + shown + ":" + std::to_string(line) +
                              " (stage " + stage + (defs.empty() ? "" : ", defines" + defs) + ")\n" +
                              translated,
                          shown, line);
    }
    return shader;
}

namespace {

// Opaque uniform types that name a texture unit (samplers) or an image unit (images).
bool is_sampler_type(GLenum t) {
    switch (t) {
        case GL_SAMPLER_1D: case GL_SAMPLER_2D: case GL_SAMPLER_3D: case GL_SAMPLER_CUBE:
        case GL_SAMPLER_1D_SHADOW: case GL_SAMPLER_2D_SHADOW: case GL_SAMPLER_1D_ARRAY: case GL_SAMPLER_2D_ARRAY:
        case GL_SAMPLER_1D_ARRAY_SHADOW: case GL_SAMPLER_2D_ARRAY_SHADOW: case GL_SAMPLER_CUBE_SHADOW:
        case GL_SAMPLER_CUBE_MAP_ARRAY: case GL_SAMPLER_CUBE_MAP_ARRAY_SHADOW: case GL_SAMPLER_BUFFER:
        case GL_SAMPLER_2D_RECT: case GL_SAMPLER_2D_MULTISAMPLE: case GL_SAMPLER_2D_MULTISAMPLE_ARRAY:
        case GL_INT_SAMPLER_2D: case GL_INT_SAMPLER_3D: case GL_INT_SAMPLER_2D_ARRAY: case GL_INT_SAMPLER_BUFFER:
        case GL_INT_SAMPLER_CUBE: case GL_UNSIGNED_INT_SAMPLER_2D: case GL_UNSIGNED_INT_SAMPLER_3D:
        case GL_UNSIGNED_INT_SAMPLER_2D_ARRAY: case GL_UNSIGNED_INT_SAMPLER_BUFFER: case GL_UNSIGNED_INT_SAMPLER_CUBE:
            return true;
        default:
            return false;
    }
}

bool is_image_type(GLenum t) {
    switch (t) {
        case GL_IMAGE_2D: case GL_IMAGE_3D: case GL_IMAGE_CUBE: case GL_IMAGE_2D_ARRAY: case GL_IMAGE_BUFFER:
        case GL_INT_IMAGE_2D: case GL_INT_IMAGE_3D: case GL_INT_IMAGE_2D_ARRAY: case GL_INT_IMAGE_BUFFER:
        case GL_UNSIGNED_INT_IMAGE_2D: case GL_UNSIGNED_INT_IMAGE_3D: case GL_UNSIGNED_INT_IMAGE_2D_ARRAY:
        case GL_UNSIGNED_INT_IMAGE_BUFFER:
            return true;
        default:
            return false;
    }
}

// Two active samplers (or images) of one program on the same unit read one texture under two
// names, or raise GL_INVALID_OPERATION at dispatch when their types differ: either way a pass
// reads something it did not mean to (it happened once: the ray-reuse history and the specular
// albedo table shared unit 13). Checked once per linked variant, so every pass and every
// combination of defines the tests and the stress suite build is covered.
void check_unit_collisions(GLuint prog, const std::string& program_name) {
    GLint count = 0;
    glGetProgramInterfaceiv(prog, GL_UNIFORM, GL_ACTIVE_RESOURCES, &count);
    std::map<std::pair<bool, GLint>, std::string> owner;  // (image?, unit) -> uniform
    for (GLint i = 0; i < count; ++i) {
        const GLenum props[] = {GL_TYPE, GL_ARRAY_SIZE, GL_LOCATION};
        GLint values[3] = {0, 0, -1};
        glGetProgramResourceiv(prog, GL_UNIFORM, GLuint(i), 3, props, 3, nullptr, values);
        const GLenum type = GLenum(values[0]);
        const bool image = is_image_type(type);
        if ((!image && !is_sampler_type(type)) || values[2] < 0) continue;
        char name[256] = {0};
        glGetProgramResourceName(prog, GL_UNIFORM, GLuint(i), sizeof(name), nullptr, name);
        for (GLint e = 0; e < std::max(values[1], 1); ++e) {
            GLint unit = -1;
            glGetUniformiv(prog, values[2] + e, &unit);
            const std::string who = values[1] > 1 ? std::string(name) + "[" + std::to_string(e) + "]" : std::string(name);
            const auto [it, fresh] = owner.emplace(std::make_pair(image, unit), who);
            if (!fresh)
                throw ShaderError(program_name + ": " + who + " and " + it->second + " are both bound to " +
                                      (image ? "image unit " : "texture unit ") + std::to_string(unit) +
                                      "; give each its own layout(binding = ...)",
                                  program_name, 0);
        }
    }
}

// Where `block` is declared in these stages' sources, as "shaders/<file>:<line>" (a file outside
// the shader tree by its own path), following the #line directives preprocess() writes; the first
// stage's name where no declaration is found. Only on the error path.
std::pair<std::string, int> locate_block(const ShaderLibrary& lib, const std::vector<std::string>& stages,
                                         const Defines& defines, const std::string& block) {
    const std::regex decl("\\b(buffer|uniform)\\s+" + block + "\\b");
    static const std::regex line_re(R"(^#line (\d+) (\d+)$)");
    for (const auto& stage : stages) {
        const ShaderLibrary::Preprocessed src = lib.preprocess(stage, defines);
        std::istringstream in(src.text);
        std::string line;
        int file = -1, line_no = 0;
        while (std::getline(in, line)) {
            std::smatch m;
            if (std::regex_match(line, m, line_re)) {
                line_no = std::stoi(m[1].str());
                file = std::stoi(m[2].str());
                continue;
            }
            if (file >= 0 && std::regex_search(line, decl)) {
                const std::string& name = src.files[size_t(file)];
                return {fs::path(name).is_absolute() ? name : "shaders/" + name, line_no};
            }
            if (file >= 0) ++line_no;
        }
    }
    const std::string& first = stages.front();
    return {fs::path(first).is_absolute() ? first : "shaders/" + first, 0};
}

// A block at a binding the host does not bind it to reads another pass's buffer or nothing, with
// no error from GL (a binding point is context state, OpenGL 4.5 core profile 7.8, whatever block
// reads it): so each block of the shader tree is at the binding of its row of the table, and a
// block with no row is refused too, since nothing then says what binds it. Checked once per linked
// variant, right after linking, so the frame pays nothing for it.
void check_block_bindings(GLuint prog, const std::string& program_name, bool user_program,
                          const std::map<std::string, ShaderLibrary::BlockBinding>& table,
                          const std::function<std::pair<std::string, int>(const std::string&)>& locate) {
    if (table.empty()) return;
    for (const GLenum interface : {GL_SHADER_STORAGE_BLOCK, GL_UNIFORM_BLOCK}) {
        const bool storage = interface == GL_SHADER_STORAGE_BLOCK;
        const std::string kind = storage ? "storage block " : "uniform block ";
        GLint count = 0;
        glGetProgramInterfaceiv(prog, interface, GL_ACTIVE_RESOURCES, &count);
        for (GLint i = 0; i < count; ++i) {
            char raw[256] = {0};
            glGetProgramResourceName(prog, interface, GLuint(i), sizeof(raw), nullptr, raw);
            std::string name = raw;
            if (const size_t bracket = name.find('['); bracket != std::string::npos) name.resize(bracket);
            const GLenum prop = GL_BUFFER_BINDING;
            GLint binding = -1;
            glGetProgramResourceiv(prog, interface, GLuint(i), 1, &prop, 1, nullptr, &binding);
            const auto row = table.find(name);
            if (row == table.end() && user_program) continue;
            std::string problem;
            if (row == table.end())
                problem = kind + name + " (binding " + std::to_string(binding) +
                          ") is not in cpp/render/buffer_bindings.def, the table of every block's binding "
                          "point: add its row and declare it with binding = BUFFER_<NAME>";
            else if (row->second.storage != storage)
                problem = kind + name + " is a " + (row->second.storage ? "storage" : "uniform") +
                          " block in cpp/render/buffer_bindings.def";
            else if (row->second.binding != binding)
                problem = kind + name + " is at binding " + std::to_string(binding) +
                          ", where cpp/render/buffer_bindings.def puts it at " +
                          std::to_string(row->second.binding) + ": declare it with binding = " + row->second.define;
            if (problem.empty()) continue;
            const auto [file, line] = locate(name);
            throw ShaderError(file + ":" + std::to_string(line) + ": " + problem + " (program " + program_name + ")",
                              file, line);
        }
    }
}

}  // namespace

GLuint ShaderLibrary::program(const std::vector<std::string>& stages, const Defines& defines) {
    std::string key;
    for (const auto& s : stages) key += s + "|";
    for (const auto& [k, v] : defines) key += k + "=" + v + ";";
    if (auto it = cache_.find(key); it != cache_.end()) return it->second;

    std::vector<GLuint> shaders;
    try {
        for (const auto& s : stages) shaders.push_back(compile_stage(s, defines));
    } catch (...) {
        for (GLuint s : shaders) glDeleteShader(s);
        throw;
    }
    const GLuint prog = glCreateProgram();
    for (GLuint s : shaders) glAttachShader(prog, s);
    glLinkProgram(prog);
    for (GLuint s : shaders) {
        glDetachShader(prog, s);
        glDeleteShader(s);
    }
    GLint ok = GL_FALSE;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint len = 0;
        glGetProgramiv(prog, GL_INFO_LOG_LENGTH, &len);
        std::string log(size_t(std::max(len, 1)), '\0');
        glGetProgramInfoLog(prog, len, nullptr, log.data());
        glDeleteProgram(prog);
        std::string joined;
        for (const auto& s : stages) joined += (joined.empty() ? "" : " + ") + ("shaders/" + s);
        throw ShaderError("GLSL link error in " + joined + "\n" + log.c_str(), "shaders/" + stages.front(), 0);
    }
    {
        std::string joined;
        for (const auto& s : stages) joined += (joined.empty() ? "shaders/" : " + shaders/") + s;
        try {
            check_unit_collisions(prog, joined);
            bool user_program = false;
            for (const auto& s : stages) user_program = user_program || fs::path(s).is_absolute();
            check_block_bindings(prog, joined, user_program, block_bindings_, [&](const std::string& block) {
                return locate_block(*this, stages, defines, block);
            });
        } catch (...) {
            glDeleteProgram(prog);
            throw;
        }
    }
    cache_[key] = prog;
    return prog;
}

}  // namespace ssr
