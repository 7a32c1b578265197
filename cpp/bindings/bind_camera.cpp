// ssrlab.Camera: a pinhole camera with its matrices; Camera::validate checks it.

#include "bindings/bindings.h"
#include "render/camera.h"

namespace py = pybind11;

namespace ssr {

void bind_camera(py::module_& m) {
    py::class_<Camera>(m, "Camera", R"doc(
A pinhole camera, OpenGL conventions: right-handed world, y up, looking down the camera's -z.

position, target, up  world space
fov_y                 vertical field of view in degrees (0, 179)
near, far             clip distances along the view axis, 0 < near < far
The aspect ratio comes from the image (Settings.width / Settings.height).)doc")
        .def(py::init([](glm::vec3 position, glm::vec3 target, glm::vec3 up, float fov_y, float near_plane,
                         float far_plane) {
                 Camera c;
                 c.position = position;
                 c.target = target;
                 c.up = up;
                 c.fov_y_degrees = fov_y;
                 c.near_plane = near_plane;
                 c.far_plane = far_plane;
                 c.validate();
                 return c;
             }),
             py::arg("position") = glm::vec3(0, 0, 5), py::arg("target") = glm::vec3(0.0f),
             py::arg("up") = glm::vec3(0, 1, 0), py::arg("fov_y") = 60.0f, py::arg("near") = 0.1f,
             py::arg("far") = 100.0f)
        .def_readwrite("position", &Camera::position, "eye position, world space")
        .def_readwrite("target", &Camera::target, "point looked at, world space")
        .def_readwrite("up", &Camera::up, "world up direction (not parallel to the view direction)")
        .def_readwrite("fov_y", &Camera::fov_y_degrees, "vertical field of view, degrees in (0, 179)")
        .def_readwrite("near", &Camera::near_plane, "near clip distance along the view axis, > 0")
        .def_readwrite("far", &Camera::far_plane, "far clip distance along the view axis, > near")
        .def("view_matrix", &Camera::view, "World -> view matrix (4x4, row-major numpy).")
        .def(
            "projection_matrix",
            [](const Camera& c, float aspect, const std::string& depth_mode) {
                return c.projection(DepthConvention{parse_depth_mode(depth_mode)}, aspect);
            },
            py::arg("aspect"), py::arg("depth_mode") = "standard",
            "View -> clip matrix for this aspect ratio and depth convention.")
        .def("validate", &Camera::validate, "Raises ValueError naming the field if the camera is invalid.")
        .def(py::pickle(
            [](const Camera& c) {
                return py::make_tuple(c.position, c.target, c.up, c.fov_y_degrees, c.near_plane, c.far_plane);
            },
            [](py::tuple t) {
                Camera c;
                c.position = t[0].cast<glm::vec3>();
                c.target = t[1].cast<glm::vec3>();
                c.up = t[2].cast<glm::vec3>();
                c.fov_y_degrees = t[3].cast<float>();
                c.near_plane = t[4].cast<float>();
                c.far_plane = t[5].cast<float>();
                return c;
            }))
        .def("__repr__", [](const Camera& c) {
            auto v = [](const glm::vec3& x) {
                return "(" + std::to_string(x.x) + ", " + std::to_string(x.y) + ", " + std::to_string(x.z) + ")";
            };
            return "Camera(position=" + v(c.position) + ", target=" + v(c.target) + ", up=" + v(c.up) +
                   ", fov_y=" + std::to_string(c.fov_y_degrees) + ", near=" + std::to_string(c.near_plane) +
                   ", far=" + std::to_string(c.far_plane) + ")";
        });
}

}  // namespace ssr
