// Functions over files and rays: image files read and written, and Embree's closest hits.

#include <cmath>
#include <cstring>

#include "bindings/bindings.h"
#include "scene/embree_scene.h"
#include "scene/image_io.h"

namespace py = pybind11;

namespace ssr {

void bind_io(py::module_& m) {
    m.def(
        "embree_intersect",
        [](const Scene& scene, py::array_t<float, py::array::c_style | py::array::forcecast> origins,
           py::array_t<float, py::array::c_style | py::array::forcecast> directions, float t_min, float t_max) {
            if (origins.ndim() != 2 || origins.shape(1) != 3 || directions.ndim() != 2 || directions.shape(1) != 3 ||
                origins.shape(0) != directions.shape(0))
                throw std::invalid_argument("embree_intersect: origins and directions must both have shape (n, 3)");
            const size_t n = size_t(origins.shape(0));
            std::vector<glm::vec3> o(n), d(n);
            std::memcpy(o.data(), origins.data(), n * 12);
            std::memcpy(d.data(), directions.data(), n * 12);
            // Embree asserts (aborting the process) on a NaN or Inf ray: refuse them here.
            for (size_t i = 0; i < n; ++i)
                if (!std::isfinite(o[i].x + o[i].y + o[i].z) || !std::isfinite(d[i].x + d[i].y + d[i].z) ||
                    glm::dot(d[i], d[i]) == 0.0f)
                    throw std::invalid_argument("embree_intersect: ray " + std::to_string(i) +
                                                " has a non-finite origin or direction, or a zero direction");
            if (!(t_min >= 0.0f) || !(t_max >= t_min))
                throw std::invalid_argument("embree_intersect: need 0 <= t_min <= t_max (t_max may be inf)");
            std::vector<CpuHit> hits;
            {
                py::gil_scoped_release release;
                hits = embree_intersect(scene, o, d, t_min, t_max);
            }
            const py::ssize_t count = py::ssize_t(n);
            py::array_t<float> t{count}, uv{{count, py::ssize_t(2)}};
            py::array_t<int32_t> obj{count}, prim{count};
            for (size_t i = 0; i < n; ++i) {
                t.mutable_at(i) = hits[i].t;
                obj.mutable_at(i) = hits[i].object;
                prim.mutable_at(i) = hits[i].primitive;
                uv.mutable_at(i, 0) = hits[i].u;
                uv.mutable_at(i, 1) = hits[i].v;
            }
            py::dict out;
            out["t"] = t;
            out["object"] = obj;
            out["primitive"] = prim;
            out["uv"] = uv;
            return out;
        },
        py::arg("scene"), py::arg("origins"), py::arg("directions"), py::arg("t_min") = 0.0f,
        py::arg("t_max") = 1e30f,
        "Closest hits of world-space rays with Intel Embree (robust mode), on the CPU: t (inf for a miss), "
        "object (-1 for a miss), primitive and Embree's barycentric uv. A production kernel to check the "
        "GPU reference tracer against.");

    m.def(
        "write_image",
        [](const std::string& path, py::array_t<float, py::array::c_style | py::array::forcecast> pixels,
           std::vector<std::string> channel_names, bool half) {
            if (pixels.ndim() != 3 && pixels.ndim() != 2)
                throw std::invalid_argument("write_image: pixels must have shape (h, w) or (h, w, c)");
            FloatImage img;
            img.height = int(pixels.shape(0));
            img.width = int(pixels.shape(1));
            img.channels = pixels.ndim() == 3 ? int(pixels.shape(2)) : 1;
            img.pixels.assign(pixels.data(), pixels.data() + pixels.size());
            if (!channel_names.empty() && int(channel_names.size()) != img.channels)
                throw std::invalid_argument("write_image: " + std::to_string(channel_names.size()) +
                                            " channel names for " + std::to_string(img.channels) + " channels");
            img.channel_names = std::move(channel_names);
            py::gil_scoped_release release;
            write_float_image(path, img, half);
        },
        py::arg("path"), py::arg("pixels"), py::arg("channel_names") = std::vector<std::string>{},
        py::arg("half") = false,
        "Writes float pixels with OpenImageIO (or ssrlab.io's Python codec); the extension picks the format (EXR keeps floats, "
        "PNG/JPEG get values clamped to [0, 1] and quantised to 8 bits).");
    m.def("image_io_backend", &image_io_backend,
          "Which library reads and writes image files: 'OpenImageIO', or 'python' in an extension built without "
          "it (ssrlab.io then reads and writes PNG and JPEG with Pillow, EXR with the OpenEXR package).");
    m.def(
        "_set_image_codec", [](py::object codec) { set_image_codec(codec.ptr()); }, py::arg("codec"),
        "Registers the Python image codec of an extension built without OpenImageIO (ssrlab.io does).");
    m.def(
        "read_image",
        [](const std::string& path) {
            FloatImage img;
            {
                py::gil_scoped_release release;
                img = read_float_image(path);
            }
            py::array_t<float> out({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(img.channels)});
            std::memcpy(out.mutable_data(), img.pixels.data(), img.pixels.size() * sizeof(float));
            return py::make_tuple(out, img.channel_names);
        },
        py::arg("path"), "Reads an image as float32 (h, w, c) and its channel names.");
}

}  // namespace ssr
