// Image files through OpenImageIO: texture decoding (any format OIIO reads, from a file or
// from memory), PNG encoding for glTF export, and float images for G-buffer EXR output and
// environment maps. An extension built without OpenImageIO (CMake SSRLAB_WITH_OIIO=OFF, or
// where it is not found) does the same through a Python callable that ssrlab.io registers
// (image_io_python.cpp: Pillow for PNG and JPEG, the OpenEXR package for EXR), so that a
// wheel needs no OpenImageIO on the machine it is installed on.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace ssr {

// "OpenImageIO", or "python" where the extension was built without it.
const char* image_io_backend();
// The Python callable that reads and writes images in a "python" build (a PyObject*, kept for
// the life of the process); ignored by an OpenImageIO build.
void set_image_codec(void* callable);

// Decodes a file to RGBA8. Throws FileNotFound / SceneError naming the file.
Image decode_image_file(const std::string& path);
// Decodes bytes (e.g. a glb buffer view) to RGBA8; `hint` is a MIME type or extension.
Image decode_image_memory(const uint8_t* data, size_t size, const std::string& hint, const std::string& what);
// Encodes RGBA8 as PNG bytes.
std::vector<uint8_t> encode_png(const Image& image);

struct FloatImage {
    int width = 0, height = 0, channels = 0;
    std::vector<float> pixels;  // row-major, row 0 = top
    std::vector<std::string> channel_names;
};

FloatImage read_float_image(const std::string& path);
// Checks, by reading its header only, that `path` is a regular image file OpenImageIO can read
// and of a size it will decode; throws SceneError starting with `what` otherwise.
void probe_image_file(const std::string& path, const std::string& what);
// Writes float pixels; the file's extension picks the format. 8-bit formats (PNG, JPEG)
// receive values clamped to [0,1] and quantised; EXR keeps float (half when `half` is true).
void write_float_image(const std::string& path, const FloatImage& image, bool half = false);

}  // namespace ssr
