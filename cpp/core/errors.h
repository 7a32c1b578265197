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

// An output file that could not be written (a full disk, no permission, a writer that failed):
// mapped to ssrlab.OutputError, an OSError whose errno, strerror and filename are set, since
// nothing is wrong with the scene or the settings when a disk is full.
struct OutputError : std::runtime_error {
    OutputError(const std::string& path_, int err_, const std::string& cause_)
        : std::runtime_error(path_ + ": " + cause_), path(path_), err(err_), cause(cause_) {}
    std::string path;
    int err = 0;         // the errno of the failed system call, 0 where the writer gave none
    std::string cause;
};

// A file that does not exist (mapped to Python's FileNotFoundError).
struct FileNotFound : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace ssr
