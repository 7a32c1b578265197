// Image files without OpenImageIO: every operation of image_io.h handed to one Python callable
// that ssrlab.io registers at import (ssrlab.io._python_codec: Pillow for PNG and JPEG, the
// OpenEXR package for EXR). Compiled instead of image_io.cpp where the extension is built
// without OpenImageIO (a wheel for machines that have only their GL drivers).
//
// The callable is codec(op, *args):
//   ("decode", path or bytes, hint)            -> uint8 array (h, w, 4), RGBA
//   ("encode_png", uint8 array (h, w, 4))      -> bytes
//   ("read", path)                             -> (float32 array (h, w, c), [channel names])
//   ("probe", path)                            -> (width, height, channels), header only
//   ("write", path, float32 (h, w, c), names, half) -> None
// A Python exception becomes a SceneError naming the file.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <filesystem>

#include "core/errors.h"
#include "scene/image_io.h"

namespace py = pybind11;

namespace ssr {

namespace {

// Largest image decoded (pixels x channels): a header can claim any size.
constexpr uint64_t kMaxImageValues = uint64_t(1) << 28;

// Never released: a py::object destroyed at process exit, after the interpreter, would crash.
PyObject* g_codec = nullptr;

void check_regular_file(const std::string& path) {
    if (!std::filesystem::exists(path)) throw FileNotFound("image file not found: " + path);
    if (!std::filesystem::is_regular_file(path))
        throw SceneError(path + ": not a regular file (a folder, device, FIFO or socket)");
}

void check_size(int64_t w, int64_t h, int64_t c, const std::string& what) {
    if (w <= 0 || h <= 0 || c <= 0 || c > 64 || uint64_t(w) * uint64_t(h) * uint64_t(std::max<int64_t>(c, 4)) >
                                                    kMaxImageValues)
        throw SceneError(what + ": image of " + std::to_string(w) + "x" + std::to_string(h) + "x" +
                         std::to_string(c) + " is empty or too large");
}

// Calls the codec with the GIL held; a Python error becomes a SceneError starting with `what`.
template <typename F>
auto with_codec(const std::string& what, F&& f) -> decltype(f(std::declval<py::object&>())) {
    py::gil_scoped_acquire gil;
    if (!g_codec)
        throw SceneError(what + ": this ssrlab was built without OpenImageIO and no image codec is registered "
                                "(import ssrlab registers one: Pillow and the OpenEXR package)");
    std::string error;
    try {
        py::object codec = py::reinterpret_borrow<py::object>(g_codec);
        return f(codec);
    } catch (py::error_already_set& e) {
        error = e.what();
        if (e.matches(PyExc_FileNotFoundError)) throw FileNotFound(what + ": " + error);
    } catch (const py::cast_error& e) {
        error = std::string("unexpected result from the image codec: ") + e.what();
    }
    throw SceneError(what + ": " + error);
}

Image rgba_from(py::object result, const std::string& what) {
    auto a = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(result);
    if (!a || a.ndim() != 3 || a.shape(2) != 4) throw SceneError(what + ": the image codec did not return RGBA8");
    check_size(a.shape(1), a.shape(0), 4, what);
    Image img;
    img.height = int(a.shape(0));
    img.width = int(a.shape(1));
    img.rgba.assign(a.data(), a.data() + a.size());
    return img;
}

}  // namespace

const char* image_io_backend() { return "python"; }

void set_image_codec(void* callable) {
    PyObject* obj = static_cast<PyObject*>(callable);
    Py_XINCREF(obj);
    g_codec = obj;  // the previous one, if any, stays alive: a call may hold it
}

Image decode_image_file(const std::string& path) {
    check_regular_file(path);
    Image img = with_codec(path, [&](py::object& codec) { return rgba_from(codec("decode", path, ""), path); });
    img.source = path;
    return img;
}

Image decode_image_memory(const uint8_t* data, size_t size, const std::string& hint, const std::string& what) {
    Image img = with_codec(what, [&](py::object& codec) {
        py::bytes bytes(reinterpret_cast<const char*>(data), size);
        return rgba_from(codec("decode", bytes, hint), what);
    });
    img.source = "<embedded>";
    return img;
}

std::vector<uint8_t> encode_png(const Image& image) {
    return with_codec("PNG encoding", [&](py::object& codec) {
        py::array_t<uint8_t> a({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(4)});
        std::memcpy(a.mutable_data(), image.rgba.data(), image.rgba.size());
        std::string bytes = py::bytes(codec("encode_png", a));
        return std::vector<uint8_t>(bytes.begin(), bytes.end());
    });
}

FloatImage read_float_image(const std::string& path) {
    check_regular_file(path);
    return with_codec(path, [&](py::object& codec) {
        py::tuple result = codec("read", path);
        auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(result[0]);
        if (!a || a.ndim() != 3) throw SceneError(path + ": the image codec did not return (h, w, c) floats");
        check_size(a.shape(1), a.shape(0), a.shape(2), path);
        FloatImage img;
        img.height = int(a.shape(0));
        img.width = int(a.shape(1));
        img.channels = int(a.shape(2));
        img.pixels.assign(a.data(), a.data() + a.size());
        img.channel_names = result[1].cast<std::vector<std::string>>();
        return img;
    });
}

void probe_image_file(const std::string& path, const std::string& what) {
    check_regular_file(path);
    with_codec(what + ": '" + path + "'", [&](py::object& codec) {
        py::tuple whc = codec("probe", path);
        check_size(whc[0].cast<int64_t>(), whc[1].cast<int64_t>(), whc[2].cast<int64_t>(), what);
        return 0;
    });
}

void write_float_image(const std::string& path, const FloatImage& image, bool half) {
    // A file the system would not let the codec write (an OSError: no space, no permission) is an
    // OutputError naming the file and its errno, as OpenImageIO's writer reports it.
    int err = 0;
    std::string cause;
    {
        py::gil_scoped_acquire gil;
        try {
            with_codec(path, [&](py::object& codec) {
                py::array_t<float> a(
                    {py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(image.channels)});
                std::memcpy(a.mutable_data(), image.pixels.data(), image.pixels.size() * sizeof(float));
                try {
                    codec("write", path, a, image.channel_names, half);
                } catch (py::error_already_set& e) {
                    if (!e.matches(PyExc_OSError)) throw;
                    py::object value = e.value();
                    py::object no = py::getattr(value, "errno", py::none());
                    err = no.is_none() ? 0 : no.cast<int>();
                    py::object text = py::getattr(value, "strerror", py::none());
                    cause = "cannot write the image: " +
                            (text.is_none() ? std::string(e.what()) : text.cast<std::string>());
                }
                return 0;
            });
        } catch (const FileNotFound& e) {
            cause = std::string("cannot write the image: ") + e.what();
        }
    }
    if (!cause.empty()) throw OutputError(path, err, cause);
}

}  // namespace ssr
