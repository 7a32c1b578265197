#include "bindings/bindings.h"
#include "core/egl_context.h"
#include "render/renderer.h"

namespace py = pybind11;

namespace ssr {

namespace {

// A readback as a float32 numpy array (layers, height, width, 4) that owns its memory.
py::array to_numpy(Readback&& r) {
    auto* data = new ReadbackData(std::move(r.data));
    py::capsule owner(data, [](void* p) { delete static_cast<ReadbackData*>(p); });
    const std::vector<py::ssize_t> shape = {r.layers, r.height, r.width, r.channels};
    return py::array_t<float>(shape, data->data(), owner);
}

// Enum settings travel as their names.
template <typename E>
auto enum_getter(E RenderSettings::*field) {
    return [field](const RenderSettings& s) { return enum_name(s.*field); };
}

template <typename E>
auto enum_setter(const char* name, E RenderSettings::*field) {
    return [name, field](RenderSettings& s, const std::string& v) { s.*field = parse_enum<E>(name, v); };
}

}  // namespace

void bind_render(py::module_& m) {
    m.def(
        "devices",
        [](bool probe) {
            py::list out;
            for (const DeviceEntry& d : list_devices(probe)) {
                py::dict e;
                e["index"] = d.index >= 0 ? py::object(py::int_(d.index)) : py::object(py::none());
                e["device"] = d.software ? std::string("cpu") : "gpu:" + std::to_string(d.index);
                e["software"] = d.software;
                e["egl_device_extensions"] = d.extensions;
                e["drm_device"] = d.drm_device;
                e["cuda_device"] = d.cuda_device >= 0 ? py::object(py::int_(d.cuda_device)) : py::object(py::none());
                e["vendor"] = d.gl_vendor;
                e["renderer"] = d.gl_renderer;
                e["gl_version"] = d.gl_version;
                e["error"] = d.error;
                out.append(e);
            }
            return out;
        },
        py::arg("probe") = true,
        "Every EGL device: hardware ones numbered in enumeration order (device='gpu:N'), then software ones; "
        "with probe, each one's OpenGL vendor and renderer from a context made and destroyed at once.");
    py::class_<RenderSettings>(m, "RenderSettings", "Native settings; build them with ssrlab.Settings.")
        .def(py::init<>())
        .def_property(
            "user_passes", [](const RenderSettings& s) { return s.user.passes; },
            [](RenderSettings& s, const std::vector<std::string>& v) { s.user.passes = v; })
        .def_property(
            "user_params", [](const RenderSettings& s) { return s.user.params; },
            [](RenderSettings& s, const std::map<std::string, double>& v) { s.user.params = v; })
        .def_readwrite("width", &RenderSettings::width)
        .def_readwrite("height", &RenderSettings::height)
        .def_readwrite("layers", &RenderSettings::layers)
        .def_readwrite("backface_culling", &RenderSettings::backface_culling)
        .def_property(
            "depth_mode", [](const RenderSettings& s) { return depth_mode_name(s.depth_mode); },
            [](RenderSettings& s, const std::string& v) { s.depth_mode = parse_depth_mode(v); })
        .def_property("deep_gbuffer", enum_getter(&RenderSettings::deep_gbuffer),
                      enum_setter("deep_gbuffer", &RenderSettings::deep_gbuffer))
        .def_readwrite("deep_gbuffer_budget", &RenderSettings::deep_gbuffer_budget)
        .def_readwrite("shadow_map_size", &RenderSettings::shadow_map_size)
        .def_readwrite("shadow_normal_offset", &RenderSettings::shadow_normal_offset)
        .def_readwrite("shadow_pcf_radius", &RenderSettings::shadow_pcf_radius)
        .def_readwrite("rays_per_pixel", &RenderSettings::rays_per_pixel)
        .def_readwrite("hammersley", &RenderSettings::hammersley)
        .def_readwrite("seed", &RenderSettings::seed)
        .def_readwrite("stride", &RenderSettings::stride)
        .def_readwrite("jitter", &RenderSettings::jitter)
        .def_readwrite("max_steps", &RenderSettings::max_steps)
        .def_readwrite("max_distance", &RenderSettings::max_distance)
        .def_readwrite("origin_bias", &RenderSettings::origin_bias)
        .def_readwrite("thickness", &RenderSettings::thickness)
        .def_readwrite("thickness_scale", &RenderSettings::thickness_scale)
        .def_readwrite("refine_steps", &RenderSettings::refine_steps)
        .def_readwrite("hiz_start_level", &RenderSettings::hiz_start_level)
        .def_readwrite("hiz_stop_level", &RenderSettings::hiz_stop_level)
        .def_readwrite("hiz_max_level", &RenderSettings::hiz_max_level)
        .def_readwrite("hiz_linear_steps", &RenderSettings::hiz_linear_steps)
        .def_readwrite("hiz_use_max", &RenderSettings::hiz_use_max)
        .def_readwrite("hiz_crossing_offset", &RenderSettings::hiz_crossing_offset)
        .def_readwrite("downscale", &RenderSettings::downscale)
        .def_readwrite("reuse_radius", &RenderSettings::reuse_radius)
        .def_readwrite("edge_aware", &RenderSettings::edge_aware)
        .def_readwrite("edge_depth_sigma", &RenderSettings::edge_depth_sigma)
        .def_readwrite("edge_normal_power", &RenderSettings::edge_normal_power)
        .def_readwrite("fade_border", &RenderSettings::fade_border)
        .def_readwrite("fade_camera_start", &RenderSettings::fade_camera_start)
        .def_readwrite("fade_camera_end", &RenderSettings::fade_camera_end)
        .def_readwrite("fade_distance_start", &RenderSettings::fade_distance_start)
        .def_readwrite("fade_distance_end", &RenderSettings::fade_distance_end)
        .def_readwrite("roughness_cutoff", &RenderSettings::roughness_cutoff)
        .def_readwrite("temporal_reflections", &RenderSettings::temporal_reflections)
        .def_readwrite("temporal_ray_reuse", &RenderSettings::temporal_ray_reuse)
        .def_readwrite("skip", &RenderSettings::skip)
        .def_readwrite("classify_facing", &RenderSettings::classify_facing)
        .def_readwrite("adaptive_rays", &RenderSettings::adaptive_rays)
        .def_readwrite("variance_rays", &RenderSettings::variance_rays)
        .def_readwrite("variance_threshold", &RenderSettings::variance_threshold)
        .def_readwrite("temporal_max_history", &RenderSettings::temporal_max_history)
        .def_readwrite("reject_depth", &RenderSettings::reject_depth)
        .def_readwrite("reject_normal", &RenderSettings::reject_normal)
        .def_readwrite("temporal_clamp", &RenderSettings::temporal_clamp)
        .def_readwrite("reject_offscreen", &RenderSettings::reject_offscreen)
        .def_readwrite("taa_history_weight", &RenderSettings::taa_history_weight)
        .def_property("taa", enum_getter(&RenderSettings::taa), enum_setter("taa", &RenderSettings::taa))
        .def_property("bounces", enum_getter(&RenderSettings::bounces), enum_setter("bounces", &RenderSettings::bounces))
        .def_property("method", enum_getter(&RenderSettings::method), enum_setter("method", &RenderSettings::method))
        .def_property("fallback", enum_getter(&RenderSettings::fallback), enum_setter("fallback", &RenderSettings::fallback))
        .def_readwrite("fallback_confidence", &RenderSettings::fallback_confidence)
        .def_property("denoise", enum_getter(&RenderSettings::denoise), enum_setter("denoise", &RenderSettings::denoise))
        .def_readwrite("svgf_max_history", &RenderSettings::svgf_max_history)
        .def_readwrite("svgf_iterations", &RenderSettings::svgf_iterations)
        .def_readwrite("svgf_sigma_depth", &RenderSettings::svgf_sigma_depth)
        .def_readwrite("svgf_sigma_normal", &RenderSettings::svgf_sigma_normal)
        .def_readwrite("svgf_sigma_luminance", &RenderSettings::svgf_sigma_luminance)
        .def_property("bvh_shadows", enum_getter(&RenderSettings::bvh_shadows),
                      enum_setter("bvh_shadows", &RenderSettings::bvh_shadows))
        .def_readwrite("probe_size", &RenderSettings::probe_size)
        .def_readwrite("probe_grid", &RenderSettings::probe_grid)
        .def_property("sampling", enum_getter(&RenderSettings::sampling), enum_setter("sampling", &RenderSettings::sampling))
        .def_property("noise", enum_getter(&RenderSettings::noise), enum_setter("noise", &RenderSettings::noise))
        .def_property("thickness_mode", enum_getter(&RenderSettings::thickness_mode),
                      enum_setter("thickness_mode", &RenderSettings::thickness_mode))
        .def_property("reuse_weighting", enum_getter(&RenderSettings::reuse_weighting),
                      enum_setter("reuse_weighting", &RenderSettings::reuse_weighting))
        .def_property("composite", enum_getter(&RenderSettings::composite),
                      enum_setter("composite", &RenderSettings::composite))
        .def_property("glossy", enum_getter(&RenderSettings::glossy), enum_setter("glossy", &RenderSettings::glossy))
        .def_readwrite("cone_max_samples", &RenderSettings::cone_max_samples)
        .def_readwrite("cone_level_bias", &RenderSettings::cone_level_bias)
        .def_readwrite("cone_stretch", &RenderSettings::cone_stretch)
        .def_property("cone_remainder", enum_getter(&RenderSettings::cone_remainder),
                      enum_setter("cone_remainder", &RenderSettings::cone_remainder))
        .def_property("specular_occlusion", enum_getter(&RenderSettings::specular_occlusion),
                      enum_setter("specular_occlusion", &RenderSettings::specular_occlusion))
        .def("validate", &RenderSettings::validate);

    py::class_<Sequence, std::shared_ptr<Sequence>>(m, "Sequence", "The history of a sequence of frames.")
        .def_readonly("frames", &Sequence::frames, "frames rendered in this sequence so far")
        .def_property_readonly("has_history", [](const Sequence& q) { return bool(q.previous); },
                               "True once a frame of the sequence can serve as the next one's history");

    py::class_<Frame, std::shared_ptr<Frame>>(m, "Frame",
                                              "A rendered frame's textures on the GPU; use ssrlab.Frame, which wraps it.")
        .def(
            "read",
            [](Frame& f, const std::string& name, int level) { return to_numpy(f.read(name, level)); },
            py::arg("name"), py::arg("level") = 0,
            "Reads every layer of a texture's mip level as float32 (layers, height, width, 4); row 0 = top.")
        .def_property_readonly("texture_names", &Frame::texture_names, "names of the textures read() can read")
        .def("has", &Frame::has, "True if the frame holds a texture of this name.")
        .def("release", &Frame::release, "Frees the frame's own textures now; later reads raise.")
        .def_property_readonly("released", &Frame::released, "True once release() freed the frame's textures")
        .def_property_readonly("gpu_bytes", &Frame::gpu_bytes, "Bytes of the frame's own textures.")
        .def_readonly("timings", &Frame::timings, "GPU milliseconds per pass (and part), 'total' their sum")
        .def_readonly("wall_ms", &Frame::wall_ms, "CPU milliseconds of the render call, until the GPU finished")
        .def_readonly("warmup_runs", &Frame::warmup_runs,
                      "Untimed runs of the chain before the timed one: 1 when this variant (passes, texture "
                      "sizes, defines, scene) was new to the renderer, so compilation and first-use costs were "
                      "paid outside the timers.")
        .def_readonly("passes", &Frame::passes, "the passes that ran, in order")
        .def_readonly("layer_samples", &Frame::layer_samples, "samples each G-buffer layer wrote (0: an empty layer)")
        .def_readonly("stats", &Frame::stats,
                      "exact work counts read back from the GPU: passes_run; with skip on, "
                      "pixels_classified, pixels_traced (in the ray list), trace_groups (ssrlab.Frame.stats adds rays_traced "
                      "and depth_fetches, summed from rays.sample)")
        .def_readonly("camera", &Frame::camera, "the camera the frame was rendered from")
        .def_property_readonly("view_matrix", [](const Frame& f) { return f.uniforms.view; }, "world -> view matrix (4x4)")
        .def_property_readonly("projection_matrix", [](const Frame& f) { return f.uniforms.proj; },
                               "view -> clip matrix (4x4) in the frame's depth convention")
        .def_property_readonly("shadow_matrix", [](const Frame& f) { return f.uniforms.view_to_shadow; },
                               "view -> shadow-map clip matrix (4x4) of the shadow-casting light");

    py::class_<Renderer, std::shared_ptr<Renderer>>(m, "Renderer",
                                                    "A headless EGL/OpenGL 4.5 renderer; use ssrlab.Renderer, which wraps it.")
        .def(py::init(&Renderer::create), py::arg("device") = "auto", py::arg("shader_dir"), py::arg("input_fetch") = "auto")
        .def(
            "render",
            [](Renderer& r, const Scene& scene, const Camera& camera, const RenderSettings& s,
               std::shared_ptr<Sequence> sequence) { return r.render(scene, camera, s, sequence.get()); },
            py::arg("scene"), py::arg("camera"), py::arg("settings"), py::arg("sequence") = nullptr,
            "Runs the chain of passes; returns the Frame (with a sequence: reads and becomes its history).")
        .def(
            "register_user_pass",
            [](Renderer& r, const std::string& name, const std::string& shader, const std::string& stage,
               const std::string& dispatch, const std::vector<std::string>& reads, const std::vector<std::string>& writes,
               const std::vector<std::tuple<std::string, std::string, std::string>>& creates,
               const std::vector<std::tuple<std::string, std::string, double>>& params) {
                UserPassDesc d;
                d.name = name;
                d.shader = shader;
                d.stage = stage;
                d.dispatch = dispatch;
                d.reads = reads;
                d.writes = writes;
                for (const auto& [n, f, s] : creates) d.creates.push_back({n, f, s});
                for (const auto& [n, ty, v] : params) d.params.push_back({n, ty, v});
                r.register_user_pass(d);
            },
            py::arg("name"), py::arg("shader"), py::arg("stage"), py::arg("dispatch"), py::arg("reads"),
            py::arg("writes"), py::arg("creates"), py::arg("params"),
            "Registers a user pass (ssrlab.UserPass builds the arguments); raises ValueError naming the pass "
            "and the resource it may not read or write.")
        .def(
            "chain",
            [](Renderer& r, const Scene& scene, const RenderSettings& s) {
                py::list out;
                for (const auto& e : r.chain(scene, s))
                    out.append(py::make_tuple(e.pass, e.inputs, e.outputs, e.history, e.scratch));
                return out;
            },
            py::arg("scene"), py::arg("settings"),
            "The passes a render of `scene` runs with `settings`, in order: (pass, inputs, outputs, history inputs, "
            "scratch outputs).")
        .def("begin_sequence", &Renderer::begin_sequence,
             "A new sequence: frames rendered with it read the previous frame's textures (temporal passes); "
             "its history is dropped with it.")
        .def(
            "info",
            [](const Renderer& r) {
                auto d = r.info().as_dict();
                d["readback_rows"] = r.pack_invert() ? "GL_MESA_pack_invert" : "flipped on the CPU";
                d["max_texture_size"] = std::to_string(r.max_texture_size());
                d["input_fetch"] = r.fetch_by_image() ? "imageLoad" : "texelFetch";
                return d;
            },
            "Vendor, renderer, GL version and the device chosen; how float textures' rows are put top first; "
            "the largest texture side the device takes; how the passes read their float inputs.")
        .def(
            "reference",
            [](Renderer& r, const Scene& scene, Frame& frame, const std::string& mode, int rays, uint32_t seed,
               const std::string& sampling, const std::string& viewer, const std::string& shadows,
               const std::string& tracer, py::object progress) {
                if (mode != "per_ray" && mode != "converged")
                    throw std::invalid_argument("reference mode must be 'per_ray' or 'converged', got '" + mode + "'");
                if (viewer != "camera" && viewer != "ray")
                    throw std::invalid_argument("reference viewer must be 'camera' or 'ray', got '" + viewer + "'");
                if (shadows != "map" && shadows != "traced")
                    throw std::invalid_argument("reference shadows must be 'map' or 'traced', got '" + shadows + "'");
                // Between sample rounds: Ctrl-C (a pending signal) and the caller's progress callback,
                // either of which may stop the reference by raising.
                auto between = [progress](int done, int total) {
                    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
                    if (!progress.is_none()) {
                        py::object go = progress(done, total);
                        if (!go.is_none() && !go.cast<bool>()) return false;
                    }
                    return true;
                };
                return r.reference(scene, frame, mode == "per_ray", rays, seed, parse_enum<Sampling>("sampling", sampling),
                                   viewer == "ray", shadows == "traced", tracer, between);
            },
            py::arg("scene"), py::arg("frame"), py::arg("mode"), py::arg("rays") = 256, py::arg("seed") = 0,
            py::arg("sampling") = "vndf", py::arg("viewer") = "ray", py::arg("shadows") = "traced",
            py::arg("tracer") = "auto", py::arg("progress") = py::none(),
            "Traces the reference pass for a frame ('per_ray' or 'converged'); returns its milliseconds per stage. "
            "tracer: 'embree' (Embree on the CPU), 'glsl' or 'auto' (for now 'glsl', the faster one measured) (the converged "
            "reference's rays; per-ray references trace in GLSL). progress(done, total) is called after each "
            "sample round; returning False stops it with an error.")
        .def(
            "specular_albedo_table",
            [](Renderer& r) {
                Readback t = r.specular_albedo_table();
                const int h = t.height, w = t.width;
                return to_numpy(std::move(t)).attr("reshape")(h, w, 2);
            },
            "The split-sum table (A, B) of the GGX directional albedo E = F0 A + B that the pbr composite and "
            "glTF materials' reflectivity use: float32 (32, 32, 2), rows perceptual roughness 0..1, columns "
            "n.v 0..1 (cell centres at both ends), integrated with the tracers' own VNDF sampler.")
        .def_property_readonly("stats", &Renderer::stats,
                               "Work outside the frame chain: scene_uploads, bvh_builds, readbacks, readback_bytes.")
        .def_property_readonly("compiled_programs", &Renderer::compiled_programs,
                               "Shader programs this renderer has compiled (each once per variant).")
        .def_property_readonly("gpu_bytes", &Renderer::gpu_bytes,
                               "Bytes of every frame texture set (live or pooled) and the shared scratch.")
        .def_property_readonly("scratch_bytes", &Renderer::scratch_bytes,
                               "Bytes of the per-renderer scratch textures (shadow map, Hi-Z pyramid)")
        .def("recycle", &Renderer::recycle, py::arg("force") = true,
             "Frees idle texture sets beyond the pool and returns freed heap memory to the OS.")
        .def("check_gl", &Renderer::check_errors, "Raises GLError if GL reported an error since the last check.")
        .def(
            "sample_reflections",
            [](Renderer& r, const std::string& sampling, float alpha, glm::vec3 view, int count, uint32_t seed,
               bool stratified) {
                Readback rb;
                const std::vector<float> samples = r.sample_reflections(sampling, alpha, view, count, seed, stratified);
                rb.data.assign(samples.begin(), samples.end());
                rb.layers = 1;
                rb.height = 1;
                rb.width = count * 2;
                return to_numpy(std::move(rb)).attr("reshape")(count, 8);
            },
            py::arg("sampling"), py::arg("alpha"), py::arg("view"), py::arg("count"), py::arg("seed") = 0,
            py::arg("stratified") = false,
            "Reflection directions from the tracers' GLSL sampler: (count, 8) float32, columns 0-2 l, 3 weight,\n"
            "4 pdf, 5-6 the uniform numbers (see ssrlab.Renderer.sample_reflections).")
        .def("microbenchmark", &Renderer::microbenchmark, py::arg("kernel"), py::arg("width"), py::arg("height"),
             py::arg("iterations"), py::arg("repeats") = 5,
             "Device peak kernels for the roofline (shaders/tools/microbench.comp): 'coherent', 'dependent',\n"
             "'dependent_image', 'store', 'bandwidth', 'copy' or 'copy_image' over a width x height grid, `iterations` operations per texel,\n"
             "run once untimed then `repeats` times; returns each repeat's GPU milliseconds.")
        .def(
            "compile",
            [](Renderer& r, const std::vector<std::string>& stages, const std::map<std::string, std::string>& defines) {
                return r.compile(stages, defines);
            },
            py::arg("stages"), py::arg("defines") = std::map<std::string, std::string>{},
            "Compiles and links shader stages (paths under the shader folder); raises ShaderError.");
}

}  // namespace ssr
