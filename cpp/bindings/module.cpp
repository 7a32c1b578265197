// The native module ssrlab._core. Thin bindings: every class is the C++ core's own; the
// Python package (python/ssrlab) adds the documented Settings object, the lazy Frame
// readback, the scene builders and the command line.
#include <pybind11/pybind11.h>

#include "bindings/bindings.h"
#include "core/errors.h"

namespace py = pybind11;

namespace {
// Python type objects of the exceptions, kept for the life of the process.
py::exception<ssr::GLError>* gl_error = nullptr;
py::exception<ssr::ShaderError>* shader_error = nullptr;
py::exception<ssr::DeviceError>* device_error = nullptr;
py::exception<ssr::SceneError>* scene_error = nullptr;
py::exception<ssr::OutputError>* output_error = nullptr;
}  // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "ssrlab native core: EGL/OpenGL 4.5 renderer for screen-space reflections over deep G-buffers";

    // GLError, ShaderError and DeviceError are RuntimeErrors; SceneError is a ValueError
    // (the input is wrong). The type objects are never destroyed at interpreter shutdown.
    gl_error = new py::exception<ssr::GLError>(m, "GLError", PyExc_RuntimeError);
    shader_error = new py::exception<ssr::ShaderError>(m, "ShaderError", PyExc_RuntimeError);
    device_error = new py::exception<ssr::DeviceError>(m, "DeviceError", PyExc_RuntimeError);
    scene_error = new py::exception<ssr::SceneError>(m, "SceneError", PyExc_ValueError);
    output_error = new py::exception<ssr::OutputError>(m, "OutputError", PyExc_OSError);
    output_error->attr("__doc__") =
        "An output file could not be written (a full disk, no permission): an OSError naming the file (.filename) "
        "and the cause (.errno, .strerror).";
    gl_error->attr("__doc__") = "OpenGL reported an error (the message names the call or pass).";
    shader_error->attr("__doc__") = "A GLSL shader failed to compile or link; .file and .line locate the error.";
    device_error->attr("__doc__") = "No EGL device of the kind asked for (e.g. device='gpu' without a GPU).";
    scene_error->attr("__doc__") = "A malformed scene or glTF file; the message names the file and the accessor, image or node.";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const ssr::ShaderError& e) {
            // Carry the shader file and line as attributes as well as in the message.
            py::object type = py::reinterpret_borrow<py::object>(shader_error->ptr());
            py::object err = type(e.what());
            err.attr("file") = e.file;
            err.attr("line") = e.line;
            PyErr_SetObject(shader_error->ptr(), err.ptr());
        } catch (const ssr::GLError& e) {
            PyErr_SetString(gl_error->ptr(), e.what());
        } catch (const ssr::DeviceError& e) {
            PyErr_SetString(device_error->ptr(), e.what());
        } catch (const ssr::SceneError& e) {
            PyErr_SetString(scene_error->ptr(), e.what());
        } catch (const ssr::OutputError& e) {
            // OSError(errno, strerror, filename): str() reads "[Errno 28] No space left on device: 'path'".
            py::object type = py::reinterpret_borrow<py::object>(output_error->ptr());
            py::object err = e.err ? type(e.err, e.cause, e.path) : type(e.what());
            if (!e.err) err.attr("filename") = e.path;
            PyErr_SetObject(output_error->ptr(), err.ptr());
        } catch (const ssr::FileNotFound& e) {
            PyErr_SetString(PyExc_FileNotFoundError, e.what());
        }
    });

    ssr::bind_material(m);
    ssr::bind_light(m);
    ssr::bind_environment(m);
    ssr::bind_camera(m);
    ssr::bind_scene(m);
    ssr::bind_animation(m);
    ssr::bind_render(m);
    ssr::bind_io(m);
}
