#include "bindings/bindings.h"
#include "core/egl_context.h"
#include "render/auto_choice.h"
#include "render/renderer.h"
#include "render/ssr_uniforms.h"

#include <cctype>
#include <deque>

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

py::dict entry(const char* type, py::object def, py::object native_def, py::object lo, py::object hi,
                const char* name, const char* unit, const char* place, unsigned flags, const char* group,
                const char* doc, py::object choices) {
    py::dict e;
    e["name"] = name;
    e["type"] = type;
    e["default"] = def;
    e["native_default"] = native_def;
    e["lo"] = lo;
    e["hi"] = hi;
    e["off"] = (flags & kOffAtZero) ? py::object(py::int_(0)) : py::object(py::none());
    e["unit"] = unit;
    e["choices"] = choices;
    e["group"] = group;
    e["doc"] = doc;
    std::string where = place;
    for (char& c : where) c = char(std::tolower(static_cast<unsigned char>(c)));
    e["place"] = where;
    e["reference"] = bool(flags & kReference);
    return e;
}

// A row of settings_fields.def as ssrlab.Settings sees it, one function per kind.
py::dict int_entry(const char* name, long long def, long long lo, long long hi, const char* unit, const char* place,
                   unsigned flags, const char* group, const char* doc) {
    return entry("int", py::int_(def), py::int_(def), py::int_(lo), py::int_(hi), name, unit, place, flags, group,
                 doc, py::none());
}
py::dict float_entry(const char* name, double def, double lo, double hi, const char* unit, const char* place,
                     unsigned flags, const char* group, const char* doc) {
    // The declared double, not its float32 rounding: Settings' default 0.002 stays 0.002.
    return entry("float", py::float_(def), py::float_(double(float(def))), py::float_(lo), py::float_(hi), name,
                 unit, place, flags, group, doc, py::none());
}
py::dict bool_entry(const char* name, bool def, int, int, const char* unit, const char* place, unsigned flags,
                    const char* group, const char* doc) {
    if (flags & kAuto)
        return entry("bool | str", py::str("auto"), py::bool_(def), py::none(), py::none(), name, unit, place, flags,
                     group, doc, py::make_tuple("auto"));
    return entry("bool", py::bool_(def), py::bool_(def), py::none(), py::none(), name, unit, place, flags, group, doc,
                 py::none());
}
template <typename E>
py::dict enum_entry(const char* name, E def, int, int, const char* unit, const char* place, unsigned flags,
                    const char* group, const char* doc) {
    py::list choices;
    if (flags & kAuto) choices.append("auto");
    for (const auto& [value, n] : enum_names<E>()) choices.append(n);
    const py::object python_def = (flags & kAuto) ? py::str("auto") : py::str(enum_name(def));
    return entry("str", python_def, py::str(enum_name(def)), py::none(), py::none(), name, unit, place, flags, group,
                 doc, py::tuple(choices));
}

py::list settings_schema() {
    py::list out;
#define SSR_SCHEMA_INT int_entry
#define SSR_SCHEMA_UINT int_entry
#define SSR_SCHEMA_FLOAT float_entry
#define SSR_SCHEMA_BOOL bool_entry
#define SSR_SCHEMA_ENUM enum_entry
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) \
    out.append(SSR_SCHEMA_##kind(#name, def, lo, hi, unit, #place, flags, group, doc));
#include "render/settings_fields.def"
#undef SSR_SCHEMA_INT
#undef SSR_SCHEMA_UINT
#undef SSR_SCHEMA_FLOAT
#undef SSR_SCHEMA_BOOL
#undef SSR_SCHEMA_ENUM
    return out;
}

// "ssrlab.Settings.name [unit]: meaning (default d; range)": a native property's docstring.
std::string property_doc(const py::dict& e) {
    const std::string unit = e["unit"].cast<std::string>();
    std::string range;
    if (!e["choices"].is_none()) {
        for (const auto& c : e["choices"]) range += (range.empty() ? "one of " : ", ") + py::repr(c).cast<std::string>();
        if (e["type"].cast<std::string>() == "bool | str") range = "True, False or " + range.substr(7);
    } else if (!e["lo"].is_none()) {
        range = "range [" + py::repr(e["lo"]).cast<std::string>() + ", " + py::repr(e["hi"]).cast<std::string>() + "]";
        if (!e["off"].is_none()) range += " or " + py::repr(e["off"]).cast<std::string>() + " (off)";
    }
    return "ssrlab.Settings." + e["name"].cast<std::string>() + (unit.empty() ? "" : " [" + unit + "]") + ": " +
           e["doc"].cast<std::string>() + " (default " + py::repr(e["default"]).cast<std::string>() +
           (range.empty() ? "" : "; " + range) + ")";
}

// A chain as Python's ssrlab.chain.Chain takes it: (pass, inputs, outputs, history inputs, scratch
// outputs, buffer inputs, buffer outputs, formats and channels of the textures it creates) per pass.
py::list chain_tuples(const std::vector<Renderer::ChainEntry>& chain) {
    py::list out;
    for (const auto& e : chain)
        out.append(py::make_tuple(e.pass, e.inputs, e.outputs, e.history, e.scratch, e.buffer_inputs, e.buffer_outputs,
                                  e.formats, e.channels));
    return out;
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
    py::class_<RenderSettings> settings(m, "RenderSettings", "Native settings; build them with ssrlab.Settings.");
    settings.def(py::init<>())
        .def("validate", &RenderSettings::validate,
             "Raises ValueError naming the first field out of its range, then the first rule between fields "
             "that fails (check_rules).")
        .def("as_run", &RenderSettings::as_run,
             "These settings as the chain runs them: what a technique overrides written in (glossy 'cone' and "
             "'blur_mips' trace one mirror ray per pixel: rays_per_pixel 1, sampling 'mirror').")
        .def("check_rules", &RenderSettings::check_rules,
             "Raises ValueError naming the first rule between fields (settings_rules()) that fails, with the "
             "fields' values and why: the message ssrlab.Settings raises.");
    // One property per settings_fields.def row, documented from the same row.
    static std::deque<std::string> docs;  // pybind11 keeps the pointers
    const py::list schema = settings_schema();
    size_t row = 0;
#define SSR_BIND_INT(name) settings.def_readwrite(#name, &RenderSettings::name, docs.back().c_str());
#define SSR_BIND_UINT SSR_BIND_INT
#define SSR_BIND_FLOAT SSR_BIND_INT
#define SSR_BIND_BOOL SSR_BIND_INT
#define SSR_BIND_ENUM(name)                                                                                  \
    settings.def_property(#name, enum_getter(&RenderSettings::name), enum_setter(#name, &RenderSettings::name), \
                          docs.back().c_str());
#define SSR_FIELD(kind, ctype, name, def, lo, hi, unit, place, flags, group, doc) \
    docs.push_back(property_doc(schema[row++].cast<py::dict>()));                 \
    SSR_BIND_##kind(name)
#include "render/settings_fields.def"
#undef SSR_BIND_INT
#undef SSR_BIND_UINT
#undef SSR_BIND_FLOAT
#undef SSR_BIND_BOOL
#undef SSR_BIND_ENUM
    settings.def_property(
        "user_passes", [](const RenderSettings& s) { return s.user.passes; },
        [](RenderSettings& s, const std::vector<std::string>& v) { s.user.passes = v; },
        "the user passes (ssrlab.UserPass) a render runs, by name");
    settings.def_property(
        "user_params", [](const RenderSettings& s) { return s.user.params; },
        [](RenderSettings& s, const std::map<std::string, double>& v) { s.user.params = v; },
        "the user passes' parameters, by '<pass>.<param>'");
    m.def(
        "builtin_chain",
        [](const Scene& scene, const RenderSettings& s, bool fetch_by_image) {
            return chain_tuples(Renderer::builtin_chain(scene, s, fetch_by_image));
        },
        py::arg("scene"), py::arg("settings"), py::arg("fetch_by_image"),
        "The built-in passes a render of `scene` with `settings` runs, in order, as Renderer.chain lists them, "
        "without a renderer: no GL context is made. fetch_by_image: the CPU device's input fetch.");
    m.def("settings_schema", &settings_schema,
          "Every setting as declared once in cpp/render/settings_fields.def, in order: a dict per field with "
          "name, type (as ssrlab.Settings annotates it), default (ssrlab.Settings' default; 'auto' where it "
          "takes one), native_default, lo, hi (None for bool and str), off (the value outside [lo, hi] that "
          "switches the feature off, or None), unit, choices (a tuple of names, or None), group, doc, place "
          "('uniform': in the shaders' SsrSettings block; 'pass': read by the C++ passes) and reference "
          "(True: it changes a converged reference). ssrlab.Settings is made from it.");
    m.def(
        "settings_rules",
        [] {
            py::list out;
            for (const SettingsRule& r : settings_rules()) {
                py::dict e;
                e["fields"] = py::tuple(py::cast(r.fields));
                e["rule"] = r.rule;
                e["why"] = r.why;
                out.append(e);
            }
            return out;
        },
        "Every rule between settings as declared once in cpp/render/settings_rules.def, in order: a dict per "
        "rule with fields (the settings it ties), rule (as users read it) and why (what breaks otherwise). "
        "RenderSettings.check_rules() tests them.");
    m.def("check_setting_value", &check_setting_value, py::arg("field"), py::arg("value"),
          "Raises ValueError unless `value` (compared with the bounds as declared) is in the numeric setting "
          "`field`'s range, or its 'off' value (downscale: 1, 2 or 4): the message ssrlab.Settings raises.");
    m.def("check_setting_choice", &check_setting_choice, py::arg("field"), py::arg("value"),
          "Raises ValueError unless `value` names a choice of the enumerated setting `field` ('auto' where it "
          "takes one): the message ssrlab.Settings raises.");
    m.def(
        "decide_auto",
        [](const std::string& field, const std::string& device) {
            RenderSettings s;
            decide_auto(s, field, device);
            const py::object native = py::cast(s);
            return py::object(native.attr(field.c_str()));
        },
        py::arg("field"), py::arg("device"),
        "What the setting `field`'s 'auto' is on `device` ('cpu' or 'gpu'): skip True on the CPU device, "
        "False on a GPU; deep_gbuffer 'peel' where no renderer has measured the constructions.");
    m.def(
        "deep_gbuffer_candidates",
        [](bool cpu_device, int layers) {
            std::vector<std::string> out;
            for (DeepGBuffer d : deep_gbuffer_candidates(cpu_device, layers)) out.push_back(enum_name(d));
            return out;
        },
        py::arg("cpu_device"), py::arg("layers"),
        "The constructions deep_gbuffer 'auto' measures for `layers` layers on the CPU device or a GPU; a "
        "single one is taken without measuring.");
    m.def(
        "choose_deep_gbuffer",
        [](const py::dict& measured) {
            std::vector<std::pair<DeepGBuffer, Spread>> m;  // in the dict's order: the first of equal medians wins
            for (const auto& [name, spread] : measured) {
                const auto at = [&spread](const char* key) { return spread[py::str(key)].cast<double>(); };
                m.push_back({parse_enum<DeepGBuffer>("deep_gbuffer", name.cast<std::string>()),
                             {at("median"), at("min"), at("max")}});
            }
            return enum_name(choose_deep_gbuffer(m));
        },
        py::arg("measured"),
        "The construction deep_gbuffer 'auto' takes from its measurements {method: {median, min, max}} in "
        "GPU ms: the smallest median, unless its [min, max] overlaps peeling's (a difference within the "
        "spread decides nothing); 'peel' where nothing was measured.");
    m.def("ssr_settings_glsl", &ssr_settings_glsl,
          "The GLSL the shaders include as lib/ssr_settings.glsl: the SsrSettings uniform block (the settings "
          "whose place is 'uniform', derived members first) and an int constant per enum value.");
    m.def(
        "gpu_struct_glsl",
        [] {
            py::dict out;
            for (const GpuStructGlsl& g : gpu_struct_glsl()) out[py::str(g.file)] = g.text;
            return out;
        },
        "The GLSL of every record shared with the host, declared once in cpp/render/gpu_structs.def, by the "
        "generated file the shaders include it as ('generated/FrameUniforms.glsl', ...).");
    m.def(
        "gpu_struct_layouts",
        [] {
            py::list out;
            for (const GpuStructLayout& s : gpu_struct_layouts()) {
                py::list members;
                for (const auto& mb : s.members)
                    members.append(py::dict(py::arg("name") = mb.name, py::arg("type") = mb.type,
                                            py::arg("count") = mb.count, py::arg("offset") = mb.offset));
                out.append(py::dict(py::arg("cpp") = s.cpp, py::arg("block") = s.block,
                                    py::arg("glsl_struct") = s.glsl_struct, py::arg("layout") = s.layout,
                                    py::arg("binding") = s.binding, py::arg("size") = s.size,
                                    py::arg("members") = members));
            }
            return out;
        },
        "The C++ layout of every record in cpp/render/gpu_structs.def: a dict per struct with cpp (its C++ "
        "name), block, glsl_struct (the record's GLSL struct; '' for a uniform block), layout ('std140' or "
        "'std430'), binding, size (sizeof) and members (name, type, count: 0 when not an array, offset).");
    m.def(
        "buffer_bindings",
        [] {
            py::list out;
            for (const BufferBinding& b : buffer_bindings())
                out.append(py::dict(py::arg("block") = b.block, py::arg("define") = b.define,
                                    py::arg("interface") = b.storage ? "storage" : "uniform",
                                    py::arg("binding") = b.binding, py::arg("doc") = b.doc));
            return out;
        },
        "The binding point of every uniform and storage block of the shaders, declared once in "
        "cpp/render/buffer_bindings.def: a dict per block with block (its GLSL name), define (BUFFER_<NAME>, "
        "what its shaders write), interface ('uniform' or 'storage'), binding and doc.");
    m.def("buffer_bindings_glsl", &buffer_bindings_glsl,
          "The #defines BUFFER_<NAME> of cpp/render/buffer_bindings.def, put ahead of every program's source.");

    py::class_<Sequence, std::shared_ptr<Sequence>>(m, "Sequence", "The history of a sequence of frames.")
        .def_readonly("frames", &Sequence::frames, "frames rendered in this sequence so far")
        .def_property_readonly("has_history", [](const Sequence& q) { return bool(q.previous); },
                               "True once a frame of the sequence can serve as the next one's history");

    py::class_<Frame, std::shared_ptr<Frame>>(m, "Frame",
                                              "A rendered frame's textures on the GPU; use ssrlab.Frame, which wraps it.")
        .def(
            "read",
            [](Frame& f, const std::string& name, int level) {
                Readback data;
                {
                    py::gil_scoped_release release;  // the GL context's own lock serialises GL calls
                    data = f.read(name, level);
                }
                return to_numpy(std::move(data));
            },
            py::arg("name"), py::arg("level") = 0,
            "Reads every layer of a texture's mip level as float32 (layers, height, width, 4); row 0 = top.")
        .def(
            "display_bytes",
            [](Frame& f, const std::string& name, float exposure, const std::vector<float>& thresholds) {
                DisplayBytes bytes;
                {
                    py::gil_scoped_release release;
                    bytes = f.display_bytes(name, exposure, thresholds);
                }
                using Bytes = decltype(bytes.rgb);
                auto* data = new Bytes(std::move(bytes.rgb));
                py::capsule owner(data, [](void* p) { delete static_cast<Bytes*>(p); });
                return py::array_t<uint8_t>({bytes.height, bytes.width, 3}, data->data(), owner);
            },
            py::arg("name"), py::arg("exposure"), py::arg("thresholds"),
            "A float colour texture as 8-bit sRGB codes, uint8 (height, width, 3), row 0 = top: channel "
            "code k where thresholds[k - 1] <= exposure * value < thresholds[k] (use ssrlab.Frame.srgb8).")
        .def_property_readonly("texture_names", &Frame::texture_names, "names of the textures read() can read")
        .def_property_readonly(
            "channels",
            [](const Frame& f) {
                py::list out;
                for (const auto& [texture, c] : f.channels()) {
                    py::dict e;
                    e["texture"] = texture->name;
                    e["layered"] = texture->layers > 0;
                    e["view"] = c.view;
                    e["name"] = c.name;
                    e["first"] = c.first;
                    e["count"] = c.count;
                    e["decode"] = decode_name(c.decode);
                    e["doc"] = c.doc;
                    out.append(e);
                }
                return out;
            },
            "What the channels of the frame's textures mean, as the passes that wrote them declared: one dict "
            "per channel (texture, layered, view, name, first, count, decode, doc; layered: the texture has layers)")
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
                               "view -> shadow-map texture matrix (4x4) of the first directional or spot light that casts a shadow");

    py::class_<Renderer, std::shared_ptr<Renderer>>(m, "Renderer",
                                                    "A headless EGL/OpenGL 4.5 renderer; use ssrlab.Renderer, which wraps it.")
        .def(py::init(&Renderer::create), py::arg("device") = "auto", py::arg("shader_dir"), py::arg("input_fetch") = "auto")
        .def(
            "render",
            [](Renderer& r, const Scene& scene, const Camera& camera, const RenderSettings& s,
               std::shared_ptr<Sequence> sequence) {
                // Other Python threads run while the frame renders (a viewer's server, a notebook's
                // kernel); the GL context's own lock keeps any other call into it waiting.
                py::gil_scoped_release release;
                return r.render(scene, camera, s, sequence.get());
            },
            py::arg("scene"), py::arg("camera"), py::arg("settings"), py::arg("sequence") = nullptr,
            "Runs the chain of passes; returns the Frame (with a sequence: reads and becomes its history).")
        .def(
            "register_user_pass",
            [](Renderer& r, const std::string& name, const std::string& shader, const std::string& stage,
               const std::string& dispatch, const std::vector<std::string>& reads, const std::vector<std::string>& writes,
               const std::vector<std::tuple<std::string, std::string, std::string>>& creates,
               const std::vector<std::tuple<std::string, std::string, double>>& params, const std::string& after,
               const std::string& before) {
                UserPassDesc d;
                d.name = name;
                d.shader = shader;
                d.stage = stage;
                d.dispatch = dispatch;
                d.reads = reads;
                d.writes = writes;
                d.after = after;
                d.before = before;
                for (const auto& [n, f, s] : creates) d.creates.push_back({n, f, s});
                for (const auto& [n, ty, v] : params) d.params.push_back({n, ty, v});
                r.register_user_pass(d);
            },
            py::arg("name"), py::arg("shader"), py::arg("stage"), py::arg("dispatch"), py::arg("reads"),
            py::arg("writes"), py::arg("creates"), py::arg("params"), py::arg("after") = "", py::arg("before") = "",
            "Registers a user pass (ssrlab.UserPass builds the arguments); raises ValueError naming the pass "
            "and the resource it may not read or write, or the place it cannot run at.")
        .def(
            "chain", [](Renderer& r, const Scene& scene, const RenderSettings& s) { return chain_tuples(r.chain(scene, s)); },
            py::arg("scene"), py::arg("settings"),
            "The passes a render of `scene` runs with `settings`, in order: (pass, inputs, outputs, history inputs, "
            "scratch outputs, buffer inputs, buffer outputs).")
        .def_property("readback_path", &Renderer::readback_path, &Renderer::set_readback_path,
                      "How textures reach numpy: 'auto' (staged on a GPU, download on the CPU device), 'download' "
                      "(the driver's glGetTextureSubImage for float formats), or 'staged' (a copy pass into a "
                      "buffer, a DMA copy into pinned client memory, a parallel copy into the array). All three "
                      "give the same values.")
        .def_property("clear_path", &Renderer::clear_path, &Renderer::set_clear_path,
                      "How the passes clear textures: 'auto' (compute on a GPU, gl on the CPU device), 'gl' "
                      "(glClearTexSubImage and framebuffer clears) or 'compute' (image stores). The images are "
                      "the same either way.")
        .def_property("visibility_tiles", &Renderer::visibility_tiles, &Renderer::set_visibility_tiles,
                      "Whether the visibility constructions of the deep G-buffer mark each layer's covered tiles "
                      "and rebuild attributes over those only: 'auto' (on the CPU device), 'on' or 'off'. The "
                      "images are the same either way.")
        .def("begin_sequence", &Renderer::begin_sequence,
             "A new sequence: frames rendered with it read the previous frame's textures (temporal passes); "
             "its history is dropped with it.")
        .def(
            "info",
            [](const Renderer& r) {
                auto d = r.info().as_dict();
                d["readback_rows"] = r.pack_invert() ? "GL_MESA_pack_invert" : "flipped on the CPU";
                d["max_texture_size"] = std::to_string(r.max_texture_size());
                d["max_array_layers"] = std::to_string(r.max_array_layers());
                d["input_fetch"] = r.fetch_by_image() ? "imageLoad" : "texelFetch";
                d["readback_path"] = r.readback_staged() ? "staged" : "download";
                d["clear_path"] = r.clear_by_compute() ? "compute" : "gl";
                d["visibility_tiles"] = r.marks_visibility_tiles() ? "on" : "off";
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
            "tracer: 'cpu' (Embree and C++ shading on every core), 'embree' (Embree for the GLSL shading), 'glsl' or 'auto' "
            "('cpu' on the CPU device with traced shadows, else 'glsl') (the converged reference's rays; per-ray "
            "references trace in GLSL). progress(done, total) is called after each "
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
                               "Work outside the frame chain: scene_uploads, scene_updates, object_updates, material_updates, "
                               "bvh_builds, bvh_updates, bvh_updated_triangles, bvh_update_ms, "
                               "bvh_update_last_triangles, readbacks, readback_bytes.")
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
        .def("raster_floor", &Renderer::raster_floor, py::arg("scene"), py::arg("camera"), py::arg("settings"),
             py::arg("repeats") = 7,
             "The device's floors under the deep G-buffer on the scene's own triangles (shaders/tools/raster_floor.*):\n"
             "{floor: GPU ms of each repeat} after one untimed run, and 'count.*' keys of one value each\n"
             "(see ssrlab.Renderer.raster_floor).")
        .def(
            "compile",
            [](Renderer& r, const std::vector<std::string>& stages, const std::map<std::string, std::string>& defines) {
                return r.compile(stages, defines);
            },
            py::arg("stages"), py::arg("defines") = std::map<std::string, std::string>{},
            "Compiles and links shader stages (paths under the shader folder); raises ShaderError.")
        .def(
            "block_layout",
            [](Renderer& r, unsigned program, const std::string& block) {
                const BlockLayout b = r.block_layout(program, block);
                py::dict members;
                for (const auto& mb : b.members)
                    members[py::str(mb.name)] = py::dict(py::arg("offset") = mb.offset,
                                                         py::arg("top_level_stride") = mb.top_level_stride);
                return py::dict(py::arg("storage") = b.storage, py::arg("data_size") = b.data_size,
                                py::arg("members") = members);
            },
            py::arg("program"), py::arg("block"),
            "A compiled program's uniform or storage block as the driver laid it out: storage (a storage "
            "block), data_size and members, {driver's name: {offset, top_level_stride}}; ValueError when the "
            "program has no active block of that name.");
}

}  // namespace ssr
