#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <glm/glm.hpp>

namespace ssr {

// One per type or group of functions (bind_<name>.cpp); module.cpp registers them in this order, each
// type before the signatures that name it.
void bind_material(pybind11::module_& m);
void bind_light(pybind11::module_& m);
void bind_environment(pybind11::module_& m);
void bind_camera(pybind11::module_& m);
void bind_scene(pybind11::module_& m);
void bind_animation(pybind11::module_& m);
void bind_render(pybind11::module_& m);
void bind_io(pybind11::module_& m);

}  // namespace ssr

// glm vectors <-> Python sequences (tuples on the way out).
namespace pybind11::detail {

template <int N>
struct type_caster<glm::vec<N, float>> {
    using Vec = glm::vec<N, float>;
    PYBIND11_TYPE_CASTER(Vec, const_name("tuple[float, ...]"));

    bool load(handle src, bool) {
        if (!src || !PySequence_Check(src.ptr()) || PyUnicode_Check(src.ptr())) return false;
        sequence seq = reinterpret_borrow<sequence>(src);
        if (seq.size() != size_t(N)) return false;
        for (int i = 0; i < N; ++i) {
            PyObject* item = seq[size_t(i)].ptr();
            double v = PyFloat_AsDouble(item);
            if (v == -1.0 && PyErr_Occurred()) {
                PyErr_Clear();
                return false;
            }
            value[i] = float(v);
        }
        return true;
    }

    static handle cast(const glm::vec<N, float>& v, return_value_policy, handle) {
        tuple t(N);
        for (int i = 0; i < N; ++i) t[size_t(i)] = float_(double(v[i]));
        return t.release();
    }
};

// 4x4 matrices as numpy-compatible nested sequences, row-major on the Python side
// (m[row][col], the usual mathematical layout); glm stores columns.
template <>
struct type_caster<glm::mat4> {
    PYBIND11_TYPE_CASTER(glm::mat4, const_name("numpy.ndarray[4, 4]"));

    bool load(handle src, bool convert) {
        if (!src) return false;
        array_t<float, array::c_style | array::forcecast> a;
        if (!convert && !array_t<float>::check_(src)) return false;
        a = array_t<float, array::c_style | array::forcecast>::ensure(src);
        if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) return false;
        auto r = a.unchecked<2>();
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) value[col][row] = r(row, col);
        return true;
    }

    static handle cast(const glm::mat4& m, return_value_policy, handle) {
        array_t<float> a({4, 4});
        auto w = a.mutable_unchecked<2>();
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) w(row, col) = m[col][row];
        return a.release();
    }
};

}  // namespace pybind11::detail
