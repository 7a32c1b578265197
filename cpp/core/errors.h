// Exception types of the native core. The Python bindings map each one to a Python
// exception class (ssrlab.GLError, ssrlab.ShaderError, ssrlab.SceneError, ...), so a
// user always gets an exception that says what failed and where, never a crash.
#pragma once

#include <stdexcept>
#include <string>

namespace ssr {

// An OpenGL error or a GL debug-output message of type ERROR, with the pass that raised it.
struct GLError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A GLSL compile or link error; `file` and `line` name the first error in the shader
// sources (after #include resolution), so the message points at the file to edit.
struct ShaderError : std::runtime_error {
    ShaderError(const std::string& msg, std::string file_, int line_)
        : std::runtime_error(msg), file(std::move(file_)), line(line_) {}
    std::string file;
    int line = 0;
};

// No EGL device/context of the requested kind could be opened.
struct DeviceError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A scene file that is missing, unreadable or malformed: the message names the file and
// the offending object (accessor, image, node...).
struct SceneError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// A file that does not exist (mapped to Python's FileNotFoundError).
struct FileNotFound : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace ssr
