#include "bindings/bindings.h"
#include "render/renderer.h"

namespace py = pybind11;

namespace ssr {

namespace {

// A readback as a float32 numpy array (layers, height, width, 4) that owns its memory.
py::array to_numpy(Readback&& r) {
    auto* data = new std::vector<float>(std::move(r.data));
    py::capsule owner(data, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    const std::vector<py::ssize_t> shape = {r.layers, r.height, r.width, 4};
    return py::array_t<float>(shape, data->data(), owner);
}

}  // namespace

void bind_render(py::module_& m) {
    py::class_<RenderSettings>(m, "RenderSettings", "Native settings; build them with ssrlab.Settings.")
        .def(py::init<>())
        .def_readwrite("width", &RenderSettings::width)
        .def_readwrite("height", &RenderSettings::height)
        .def_readwrite("layers", &RenderSettings::layers)
        .def_readwrite("backface_culling", &RenderSettings::backface_culling)
        .def_property(
            "depth_mode", [](const RenderSettings& s) { return depth_mode_name(s.depth_mode); },
            [](RenderSettings& s, const std::string& v) { s.depth_mode = parse_depth_mode(v); })
        .def_readwrite("shadow_map_size", &RenderSettings::shadow_map_size)
        .def_readwrite("shadow_normal_offset", &RenderSettings::shadow_normal_offset)
        .def_readwrite("shadow_pcf_radius", &RenderSettings::shadow_pcf_radius)
        .def("validate", &RenderSettings::validate);

    py::class_<Frame, std::shared_ptr<Frame>>(m, "Frame")
        .def(
            "read",
            [](Frame& f, const std::string& name, int level) { return to_numpy(f.read(name, level)); },
            py::arg("name"), py::arg("level") = 0,
            "Reads every layer of a texture's mip level as float32 (layers, height, width, 4); row 0 = top.")
        .def_property_readonly("texture_names", &Frame::texture_names)
        .def("has", &Frame::has)
        .def_readonly("timings", &Frame::timings)
        .def_readonly("wall_ms", &Frame::wall_ms)
        .def_readonly("passes", &Frame::passes)
        .def_readonly("layer_samples", &Frame::layer_samples)
        .def_readonly("camera", &Frame::camera)
        .def_property_readonly("view_matrix", [](const Frame& f) { return f.uniforms.view; })
        .def_property_readonly("projection_matrix", [](const Frame& f) { return f.uniforms.proj; })
        .def_property_readonly("shadow_matrix", [](const Frame& f) { return f.uniforms.view_to_shadow; });

    py::class_<Renderer, std::shared_ptr<Renderer>>(m, "Renderer")
        .def(py::init(&Renderer::create), py::arg("device") = "auto", py::arg("shader_dir"))
        .def("render", &Renderer::render, py::arg("scene"), py::arg("camera"), py::arg("settings"))
        .def("info", [](const Renderer& r) { return r.info().as_dict(); })
        .def("check_gl", &Renderer::check_errors, "Raises GLError if GL reported an error since the last check.")
        .def(
            "compile",
            [](Renderer& r, const std::vector<std::string>& stages, const std::map<std::string, std::string>& defines) {
                return r.compile(stages, defines);
            },
            py::arg("stages"), py::arg("defines") = std::map<std::string, std::string>{},
            "Compiles and links shader stages (paths under the shader folder); raises ShaderError.");
}

}  // namespace ssr
