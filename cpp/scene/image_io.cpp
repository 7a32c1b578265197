#include "scene/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/errors.h"

namespace ssr {

namespace {

// Largest image decoded (pixels x channels): a header can claim any size.
constexpr uint64_t kMaxImageValues = uint64_t(1) << 28;

void check_image_size(const OIIO::ImageSpec& spec, const std::string& what) {
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.nchannels > 64 ||
        uint64_t(spec.width) * uint64_t(spec.height) * uint64_t(std::max(spec.nchannels, 4)) > kMaxImageValues)
        throw SceneError(what + ": image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" +
                         std::to_string(spec.nchannels) + " is empty or too large");
}

// Image files are opened by path only when they are regular files: OpenImageIO would read a
// device such as /dev/zero for ever, and block on a FIFO.
void check_regular_file(const std::string& path) {
    if (!std::filesystem::exists(path)) throw FileNotFound("image file not found: " + path);
    if (!std::filesystem::is_regular_file(path))
        throw SceneError(path + ": not a regular file (a folder, device, FIFO or socket)");
}

Image to_rgba8(OIIO::ImageInput& in, const std::string& what) {
    const OIIO::ImageSpec& spec = in.spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        throw SceneError(what + ": image has no pixels");
    check_image_size(spec, what);
    std::vector<uint8_t> src(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in.read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, src.data()))
        throw SceneError(what + ": cannot decode image: " + in.geterror());
    Image img;
    img.width = spec.width;
    img.height = spec.height;
    img.rgba.resize(size_t(spec.width) * size_t(spec.height) * 4);
    const int nc = spec.nchannels;
    for (size_t i = 0, n = size_t(spec.width) * size_t(spec.height); i < n; ++i) {
        const uint8_t* s = &src[i * size_t(nc)];
        uint8_t* d = &img.rgba[i * 4];
        if (nc == 1 || nc == 2) {
            d[0] = d[1] = d[2] = s[0];
            d[3] = nc == 2 ? s[1] : 255;
        } else {
            d[0] = s[0];
            d[1] = s[1];
            d[2] = s[2];
            d[3] = nc >= 4 ? s[3] : 255;
        }
    }
    return img;
}

std::string extension_for(const std::string& hint) {
    if (hint == "image/png") return "png";
    if (hint == "image/jpeg") return "jpg";
    if (hint == "image/webp") return "webp";
    if (hint == "image/ktx2") return "ktx2";
    std::string h = hint;
    if (!h.empty() && h[0] == '.') h = h.substr(1);
    return h.empty() ? "png" : h;
}

}  // namespace

const char* image_io_backend() { return "OpenImageIO"; }
void set_image_codec(void*) {}

Image decode_image_file(const std::string& path) {
    check_regular_file(path);
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw SceneError(path + ": cannot open image: " + OIIO::geterror());
    Image img = to_rgba8(*in, path);
    img.source = path;
    img.name = std::filesystem::path(path).filename().string();
    return img;
}

Image decode_image_memory(const uint8_t* data, size_t size, const std::string& hint, const std::string& what) {
    if (!data || size == 0) throw SceneError(what + ": image data is empty");
    OIIO::Filesystem::IOMemReader reader(data, size);
    auto in = OIIO::ImageInput::open("memory." + extension_for(hint), nullptr, &reader);
    if (!in) throw SceneError(what + ": cannot decode image data (" + hint + "): " + OIIO::geterror());
    Image img = to_rgba8(*in, what);
    img.source = what;
    return img;
}

std::vector<uint8_t> encode_png(const Image& image) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput writer(bytes);
    auto out = OIIO::ImageOutput::create("png");
    if (!out) throw SceneError("OpenImageIO has no PNG writer: " + OIIO::geterror());
    OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::UINT8);
    out->set_ioproxy(&writer);
    if (!out->open("memory.png", spec) || !out->write_image(OIIO::TypeDesc::UINT8, image.rgba.data()))
        throw SceneError("cannot encode image '" + image.name + "' as PNG: " + out->geterror());
    out->close();
    return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

FloatImage read_float_image(const std::string& path) {
    check_regular_file(path);
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw SceneError(path + ": cannot open image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    check_image_size(spec, path);
    FloatImage img;
    img.width = spec.width;
    img.height = spec.height;
    img.channels = spec.nchannels;
    img.channel_names = spec.channelnames;
    img.pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, img.pixels.data()))
        throw SceneError(path + ": cannot decode image: " + in->geterror());
    return img;
}

void probe_image_file(const std::string& path, const std::string& what) {
    if (!std::filesystem::is_regular_file(path))
        throw SceneError(what + ": '" + path + "' is not a regular file (a folder, device, FIFO or socket)");
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw SceneError(what + ": '" + path + "' is not an image OpenImageIO can read: " + OIIO::geterror());
    check_image_size(in->spec(), what + " '" + path + "'");
}

void write_float_image(const std::string& path, const FloatImage& image, bool half) {
    // errno is cleared first so that a failure the writer reports can name its system cause
    // (ENOSPC, EACCES...); OpenImageIO's own message is kept beside it.
    auto fail = [&](const std::string& what, const std::string& detail) {
        const int err = errno;
        std::string cause = what;
        if (err) cause += std::string(": ") + std::strerror(err);
        if (!detail.empty()) cause += " (" + detail + ")";
        throw OutputError(path, err, cause);
    };
    auto out = OIIO::ImageOutput::create(path);
    if (!out) throw SceneError(path + ": no image writer for this file type: " + OIIO::geterror());
    const std::string fmt = out->format_name();
    const bool eight_bit = fmt != "openexr" && fmt != "hdr" && fmt != "tiff";
    OIIO::TypeDesc type = eight_bit ? OIIO::TypeDesc::UINT8 : (half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    OIIO::ImageSpec spec(image.width, image.height, image.channels, type);
    if (!image.channel_names.empty()) spec.channelnames = image.channel_names;
    errno = 0;
    if (!out->open(path, spec)) fail("cannot open for writing", out->geterror());
    if (!out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data())) fail("cannot write the image", out->geterror());
    if (!out->close()) fail("cannot finish writing the image", out->geterror());
}

}  // namespace ssr
