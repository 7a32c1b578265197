// ssrlab.Scene's native half: its objects, images, lights and edits. The edits' checks are the
// scene's own (Scene::set_material, set_environment, ...); what is Python's alone stays here: numpy
// arrays turned into mesh attributes, refused where forcecast would change their meaning.

#include <cstdio>
#include <cstring>

#include "bindings/bindings.h"
#include "render/camera.h"
#include "scene/gltf_io.h"
#include "scene/image_io.h"
#include "scene/primitives.h"
#include "scene/scene.h"

namespace py = pybind11;

namespace ssr {

namespace {

// The last line behind ssrlab.Scene.add_mesh's own checks: forcecast would turn bool,
// complex (dropping the imaginary part), strings and dates into numbers without a word.
void require_real(const py::handle& obj, const char* what) {
    if (!py::isinstance<py::array>(obj)) return;  // lists etc.: forcecast parses them or fails
    const char kind = py::reinterpret_borrow<py::array>(obj).dtype().kind();
    if (kind != 'i' && kind != 'u' && kind != 'f')
        throw py::type_error(std::string(what) + " must hold real numbers (integer or float), got dtype kind '" +
                             kind + "'");
}

template <typename T, int N>
std::vector<glm::vec<N, float>> rows_of(const py::handle& obj, const char* what, size_t expect = 0) {
    require_real(obj, what);
    auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a || a.ndim() != 2 || a.shape(1) != N)
        throw std::invalid_argument(std::string(what) + " must be an array of shape (n, " + std::to_string(N) + ")");
    if (expect && size_t(a.shape(0)) != expect)
        throw std::invalid_argument(std::string(what) + " has " + std::to_string(a.shape(0)) + " rows, expected " +
                                    std::to_string(expect) + " (one per vertex)");
    std::vector<glm::vec<N, float>> out(size_t(a.shape(0)));
    auto r = a.template unchecked<2>();
    for (py::ssize_t i = 0; i < a.shape(0); ++i)
        for (int c = 0; c < N; ++c) out[size_t(i)][c] = r(i, c);
    return out;
}

std::vector<uint32_t> indices_of(const py::handle& obj) {
    require_real(obj, "indices");
    // Fractional or NaN indices would be truncated by the cast below: refuse them first.
    if (auto f = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj)) {
        const double* q = f.data();
        for (py::ssize_t i = 0; i < f.size(); ++i)
            if (!std::isfinite(q[i]) || q[i] != std::floor(q[i]))
                throw std::invalid_argument("indices must be whole numbers: " + std::to_string(q[i]) +
                                            " at position " + std::to_string(i));
    }
    auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a) throw std::invalid_argument("indices must be an integer array of shape (m, 3) or (3m,)");
    if (a.size() == 0) throw std::invalid_argument("indices is empty; pass None for a non-indexed triangle list");
    if (!(a.ndim() == 1 || (a.ndim() == 2 && a.shape(1) == 3)))
        throw std::invalid_argument("indices must have shape (m, 3) or (3m,)");
    std::vector<uint32_t> out(size_t(a.size()));
    const int64_t* p = a.data();
    for (size_t i = 0; i < out.size(); ++i) {
        if (p[i] < 0 || p[i] > int64_t(UINT32_MAX))
            throw std::invalid_argument("indices: value " + std::to_string(p[i]) + " at position " + std::to_string(i) +
                                        " is out of range");
        out[i] = uint32_t(p[i]);
    }
    return out;
}

}  // namespace

void bind_scene(py::module_& m) {
    py::class_<Scene>(m, "Scene", py::dynamic_attr(), "The native scene; use ssrlab.Scene, which wraps it.")
        .def(py::init<>())
        .def_readwrite("name", &Scene::name, "the scene's name")
        .def_property_readonly("revision", &Scene::revision, "counts changes; GPU copies are refreshed when it moves")
        .def_property_readonly("geometry_revision", &Scene::geometry_revision,
                               "the revision of the last change that rebuilds GPU copies (geometry, images, objects "
                               "added, the environment map)")
        .def_property_readonly("transforms_revision", &Scene::transforms_revision,
                               "the revision of the last change of an object's transform or material index")
        .def_property_readonly("materials_revision", &Scene::materials_revision,
                               "the revision of the last change of a material's parameters")
        .def_property_readonly("lights_revision", &Scene::lights_revision, "the revision of the last change of the lights")
        .def_property_readonly("object_count", [](const Scene& s) { return s.objects.size(); }, "objects (mesh instances)")
        .def_property_readonly("mesh_count", [](const Scene& s) { return s.meshes.size(); }, "distinct meshes")
        .def_property_readonly("material_count", [](const Scene& s) { return s.materials.size(); }, "materials")
        .def_property_readonly("image_count", [](const Scene& s) { return s.images.size(); }, "texture images")
        .def("content_hash", [](const Scene& s) {
            char buf[17];
            std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(s.content_hash()));
            return std::string(buf);
        }, "A hex digest of everything that changes an image of the scene (cache key).")
        .def_property_readonly("triangle_count", &Scene::triangle_count,
                               "Triangles over all objects (an instanced mesh counts once per instance).")
        .def_property_readonly("bounds",
                               [](const Scene& s) {
                                   Bounds b = s.bounds();
                                   return py::make_tuple(b.min, b.max);
                               },
                               "world-space axis-aligned bounds ((min x, y, z), (max x, y, z))")
        .def_property(
            "ambient", [](const Scene& s) { return s.ambient; },
            [](Scene& s, glm::vec3 a) { s.set_ambient(a); },
            "ambient radiance, linear RGB >= 0, added to every surface's diffuse term")
        .def_property(
            "probes", [](const Scene& s) { return s.probes; },
            [](Scene& s, const std::vector<glm::vec3>& p) { s.set_probes(p); },
            "reflection-probe positions (world space) for fallback 'probes'; each must lie inside the scene "
            "bounds (checked at render); empty: placed by Settings.probe_grid")
        .def_property(
            "environment", [](const Scene& s) { return s.environment; },
            [](Scene& s, const Environment& e) { s.set_environment(e); },
            "what the background and rays that leave the screen see")
        .def_property(
            "camera", [](const Scene& s) -> py::object {
                if (!s.camera) return py::none();
                return py::cast(Camera(*s.camera));
            },
            [](Scene& s, py::object c) {
                if (c.is_none()) s.camera.reset();
                else {
                    Camera cam = c.cast<Camera>();
                    cam.validate();
                    s.camera = static_cast<CameraDesc>(cam);
                }
                s.touch_frame();
            },
            "the scene's own camera (a copy), or None")
        .def(
            "_add_mesh",
            [](Scene& s, py::object positions, py::object indices, py::object normals, py::object uvs,
               py::object tangents, const Material& material, const glm::mat4& transform, const std::string& name,
               py::object colors, py::object uvs1) {
                Mesh mesh;
                mesh.name = name;
                mesh.positions = rows_of<float, 3>(positions, "positions");
                const size_t n = mesh.positions.size();
                if (!indices.is_none()) mesh.indices = indices_of(indices);
                if (!normals.is_none()) mesh.normals = rows_of<float, 3>(normals, "normals", n);
                if (!uvs.is_none()) mesh.uvs = rows_of<float, 2>(uvs, "uvs", n);
                if (!tangents.is_none()) mesh.tangents = rows_of<float, 4>(tangents, "tangents", n);
                if (!colors.is_none()) mesh.colors = rows_of<float, 4>(colors, "colors", n);
                if (!uvs1.is_none()) mesh.uvs1 = rows_of<float, 2>(uvs1, "uvs1", n);
                return s.add_mesh_object(std::move(mesh), material, transform, name);
            },
            py::arg("positions"), py::arg("indices"), py::arg("normals"), py::arg("uvs"), py::arg("tangents"),
            py::arg("material"), py::arg("transform"), py::arg("name"), py::arg("colors") = py::none(),
            py::arg("uvs1") = py::none())
        .def(
            "_add_primitive",
            [](Scene& s, const std::string& kind, const Material& material, const glm::mat4& transform,
               const std::string& name, float uv_tiles, int segments) {
                Mesh mesh;
                if (kind == "plane") mesh = make_plane(uv_tiles);
                else if (kind == "box") mesh = make_box();
                else if (kind == "sphere") mesh = make_sphere(std::max(segments, 3), std::max(segments / 2, 2));
                else throw std::invalid_argument("unknown primitive '" + kind + "'");
                const std::string object_name = name.empty() ? kind : name;
                mesh.name = object_name;
                return s.add_mesh_object(std::move(mesh), material, transform, object_name);
            },
            py::arg("kind"), py::arg("material"), py::arg("transform"), py::arg("name"), py::arg("uv_tiles") = 1.0f,
            py::arg("segments") = 48)
        .def(
            "_add_gltf",
            [](Scene& s, const std::string& path, const glm::mat4& transform, bool allow_external_files) {
                GltfLoadOptions options;
                options.allow_external_files = allow_external_files;
                std::vector<std::string> warnings;
                const int first = load_gltf(s, path, transform, options, &warnings);
                std::vector<int> ids;
                for (int i = first; i < int(s.objects.size()); ++i) ids.push_back(i);
                return py::make_tuple(ids, warnings);  // the Python wrapper emits the warnings
            },
            py::arg("path"), py::arg("transform"), py::arg("allow_external_files") = false)
        .def("_save", [](const Scene& s, const std::string& path, const std::string& folder) { save_gltf(s, path, folder); },
             py::arg("path"), py::arg("folder") = "")
        .def(
            "add_image",
            [](Scene& s, py::array_t<uint8_t, py::array::c_style | py::array::forcecast> rgba, const std::string& name) {
                if (rgba.ndim() != 3 || (rgba.shape(2) != 4 && rgba.shape(2) != 3))
                    throw std::invalid_argument("add_image: expected a uint8 array of shape (h, w, 3 or 4)");
                Image img;
                img.name = name;
                img.source = "<array>";
                img.height = int(rgba.shape(0));
                img.width = int(rgba.shape(1));
                const int c = int(rgba.shape(2));
                img.rgba.resize(size_t(img.width) * size_t(img.height) * 4);
                const uint8_t* p = rgba.data();
                for (size_t i = 0; i < size_t(img.width) * size_t(img.height); ++i)
                    for (int k = 0; k < 4; ++k) img.rgba[i * 4 + size_t(k)] = k < c ? p[i * size_t(c) + size_t(k)] : 255;
                s.images.push_back(std::move(img));
                s.touch();
                return int(s.images.size()) - 1;
            },
            py::arg("rgba"), py::arg("name") = "image",
            "Adds an 8-bit image (row 0 = top, uv (0,0) = top-left as in glTF); returns its index for Material textures.")
        .def(
            "image",
            [](const Scene& s, int i) {
                const Image& img = s.image(i);
                py::array_t<uint8_t> out({img.height, img.width, 4});
                std::memcpy(out.mutable_data(), img.rgba.data(), img.rgba.size());
                return out;
            },
            py::arg("index"), "A copy of image `index` as (h, w, 4) uint8 RGBA, row 0 = top.")
        .def(
            "load_image",
            [](Scene& s, const std::string& path) {
                s.images.push_back(decode_image_file(path));
                s.touch();
                return int(s.images.size()) - 1;
            },
            py::arg("path"), "Decodes an image file with OpenImageIO; returns its index for Material textures.")
        .def(
            "material",
            [](const Scene& s, int obj) {
                s.check_object(obj);
                return s.materials[size_t(s.objects[size_t(obj)].material)];
            },
            py::arg("object"), "A copy of an object's material.")
        .def(
            "set_material",
            [](Scene& s, int obj, const Material& m) { s.set_material(obj, m); },
            py::arg("object"), py::arg("material"), "Gives an object a copy of `material` (others sharing its old one keep it).")
        .def(
            "object_name",
            [](const Scene& s, int obj) {
                s.check_object(obj);
                return s.objects[size_t(obj)].name;
            },
            py::arg("object"), "An object's name.")
        .def(
            "object_transform",
            [](const Scene& s, int obj) {
                s.check_object(obj);
                return s.objects[size_t(obj)].transform;
            },
            py::arg("object"), "An object's object -> world matrix (4x4).")
        .def(
            "set_object_transform",
            [](Scene& s, int obj, const glm::mat4& t) {
                s.check_object(obj);
                s.set_object_transform(obj, t);
            },
            py::arg("object"), py::arg("transform"),
            "Sets an object's object -> world matrix (4x4; ValueError naming the object when it is singular, "
            "not finite or reaches beyond the scene limits). The next render updates that object's matrix "
            "and its part of the BVH only.")
        .def(
            "object_mesh",
            [](const Scene& s, int obj) {
                s.check_object(obj);
                const Mesh& mesh = s.meshes[size_t(s.objects[size_t(obj)].mesh)];
                py::array_t<float> pos({py::ssize_t(mesh.positions.size()), py::ssize_t(3)});
                py::array_t<float> nrm({py::ssize_t(mesh.normals.size()), py::ssize_t(3)});
                py::array_t<uint32_t> idx({py::ssize_t(mesh.indices.size() / 3), py::ssize_t(3)});
                std::memcpy(pos.mutable_data(), mesh.positions.data(), mesh.positions.size() * 12);
                std::memcpy(nrm.mutable_data(), mesh.normals.data(), mesh.normals.size() * 12);
                std::memcpy(idx.mutable_data(), mesh.indices.data(), mesh.indices.size() * 4);
                py::dict d;
                d["name"] = mesh.name;
                d["positions"] = pos;
                d["normals"] = nrm;
                d["indices"] = idx;
                if (!mesh.uvs.empty()) {
                    py::array_t<float> uv({py::ssize_t(mesh.uvs.size()), py::ssize_t(2)});
                    std::memcpy(uv.mutable_data(), mesh.uvs.data(), mesh.uvs.size() * 8);
                    d["uvs"] = uv;
                }
                if (!mesh.uvs1.empty()) {
                    py::array_t<float> uv({py::ssize_t(mesh.uvs1.size()), py::ssize_t(2)});
                    std::memcpy(uv.mutable_data(), mesh.uvs1.data(), mesh.uvs1.size() * 8);
                    d["uvs1"] = uv;
                }
                if (!mesh.colors.empty()) {
                    py::array_t<float> c({py::ssize_t(mesh.colors.size()), py::ssize_t(4)});
                    std::memcpy(c.mutable_data(), mesh.colors.data(), mesh.colors.size() * 16);
                    d["colors"] = c;
                }
                return d;
            },
            py::arg("object"),
            "The object's mesh in object space: positions, normals, indices (m, 3), uvs, uvs1 and colors (RGBA).")
        .def_property_readonly("lights", [](const Scene& s) { return s.lights; }, "copies of the scene's lights")
        .def(
            "add_light",
            [](Scene& s, const Light& l) { return s.add_light(l); }, py::arg("light"),
            "Adds a copy of a light; returns its index.")
        .def("clear_lights",
             [](Scene& s) {
                 s.lights.clear();
                 for (SceneNode& n : s.nodes) n.light = -1;  // animated nodes carry no light any more
                 s.touch_lights();
             },
             "Removes every light.")
        .def(
            "_assign", [](Scene& s, const Scene& other) { s = other; }, py::arg("other"),
            "Makes this scene a deep copy of `other` (a different scene for GPU caches).");
}

}  // namespace ssr
