"""Numpy input that is not real numeric data, and Settings' bounds and cross-field
constraints, raise errors naming the argument or both fields."""

import datetime

import numpy as np
import pytest

import ssrlab
from ssrlab import _core

TRI = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)


@pytest.mark.parametrize("what", ["positions", "normals", "uvs", "tangents"])
@pytest.mark.parametrize("bad", [
    lambda shape: np.ones(shape, bool),
    lambda shape: np.ones(shape, complex),
    lambda shape: np.full(shape, "1.0"),
    lambda shape: np.full(shape, b"1"),
    lambda shape: np.full(shape, 1.0, dtype=object),
    lambda shape: np.full(shape, np.datetime64("2020-01-01")),
    lambda shape: np.full(shape, np.timedelta64(1, "s")),
], ids=["bool", "complex", "str", "bytes", "object", "datetime", "timedelta"])
def test_non_numeric_vertex_arrays_raise_type_error_naming_the_argument(what, bad):
    columns = {"positions": 3, "normals": 3, "uvs": 2, "tangents": 4}[what]
    arrays = {"positions": TRI}
    arrays[what] = bad((3, columns))
    s = ssrlab.Scene()
    with pytest.raises(TypeError, match=what):
        s.add_mesh(arrays.pop("positions"), [0, 1, 2], **arrays)
    assert s.object_count == 0


def test_datetime_objects_in_lists_are_rejected():
    s = ssrlab.Scene()
    with pytest.raises(TypeError, match="positions"):
        s.add_mesh([[datetime.datetime(2020, 1, 1)] * 3] * 3, [0, 1, 2])


@pytest.mark.parametrize("what", ["positions", "normals", "uvs", "tangents"])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf, 1e39])
def test_non_finite_vertex_data_raises_value_error(what, value):
    columns = {"positions": 3, "normals": 3, "uvs": 2, "tangents": 4}[what]
    a = np.ones((3, columns))
    a[2, 1] = value
    kw = {"positions": TRI.copy()}
    kw[what] = a
    with pytest.raises(ValueError, match=rf"{what} must be finite.*row 2, component 1"):
        ssrlab.Scene().add_mesh(kw.pop("positions"), [0, 1, 2], **kw)


def test_zero_normals_are_sanitised_and_render_finite(renderer):
    s = ssrlab.Scene()
    s.add_mesh(TRI, [0, 1, 2], normals=np.zeros((3, 3)))
    n = s.object_mesh(0)["normals"]
    assert np.all(np.isfinite(n)) and np.allclose(np.linalg.norm(n, axis=1), 1)


@pytest.mark.parametrize("indices, message", [
    (np.array([0, 1, 2.5]), r"whole numbers: 2.5 at position 2 \(triangle 0, corner 2\)"),
    (np.array([0, np.nan, 2]), r"whole numbers: nan at position 1"),
    (np.array([0, 1, np.inf]), r"whole numbers: inf at position 2"),
    (np.array([0, 1, -1]), r">= 0: -1 at position 2"),
    (np.array([[0, 1, 2], [0, 7, 1]]), r"index 7 at position 4 \(triangle 1, corner 1\) is out of range \(3 vertices\)"),
    (np.array([0, 1, 2**40], np.int64), r"index 1099511627776 at position 2"),
    (np.array([0, 1, 2**63 + 5], np.uint64), r"index 9223372036854775813 at position 2"),
    (np.array([], np.int32), r"empty array; pass indices=None"),
    (np.zeros((0, 3), np.int32), r"empty array"),
    (np.array([0, 1, 2, 0]), r"not a multiple of 3"),
    (np.zeros((2, 2), np.int32), r"shape \(m, 3\) or \(3m,\)"),
])
def test_bad_indices_report_the_value_and_position(indices, message):
    with pytest.raises(ValueError, match=message):
        ssrlab.Scene().add_mesh(TRI, indices)


@pytest.mark.parametrize("indices", [np.array([True, False, True]), np.array([0, 1, 2], complex),
                                     np.array(["0", "1", "2"])])
def test_non_numeric_indices_raise_type_error(indices):
    with pytest.raises(TypeError, match="indices"):
        ssrlab.Scene().add_mesh(TRI, indices)


def test_whole_float_indices_and_none_are_accepted():
    s = ssrlab.Scene()
    s.add_mesh(TRI, np.array([0.0, 1.0, 2.0]))
    s.add_mesh(TRI, None)
    s.add_mesh(TRI, np.array([[0, 1, 2]], np.uint16))
    assert s.object_count == 3 and s.triangle_count == 3


def test_native_binding_is_the_last_line():
    """Behind Scene.add_mesh's Python checks, the native _add_mesh refuses the same input."""
    s = ssrlab.Scene()
    eye, mat = np.eye(4, dtype=np.float32), ssrlab.Material()
    with pytest.raises(TypeError, match="positions"):
        s._add_mesh(TRI.astype(complex), None, None, None, None, mat, eye, "x")
    with pytest.raises(TypeError, match="indices"):
        s._add_mesh(TRI, np.array([True, True, False]), None, None, None, mat, eye, "x")
    with pytest.raises(ValueError, match="whole numbers"):
        s._add_mesh(TRI, np.array([0, 1, 1.5]), None, None, None, mat, eye, "x")
    with pytest.raises(ValueError, match="whole numbers"):
        s._add_mesh(TRI, np.array([0, 1, np.nan]), None, None, None, mat, eye, "x")
    with pytest.raises(ValueError, match="empty"):
        s._add_mesh(TRI, np.array([], np.int64), None, None, None, mat, eye, "x")
    assert s.object_count == 0


# -- Settings ------------------------------------------------------------------------------------

FLOAT_BOUNDS = [(f, end) for f, spec in ssrlab.settings._FIELDS.items()
                if spec.metadata["lo"] is not None and spec.type in ("float", float) for end in ("lo", "hi")]


@pytest.mark.parametrize("name, end", FLOAT_BOUNDS)
def test_documented_float_bounds_are_accepted_by_the_native_validation(name, end):
    value = ssrlab.settings._FIELDS[name].metadata[end]
    kw = {name: value}
    if name == "fade_distance_start" and value > 0:  # the distance fade's constraint ties the two
        if value >= 1e7:
            pytest.skip("start = 1e7 leaves no room for an end > start")
        kw["fade_distance_end"] = 1e7
    if name == "fade_distance_end" and value > 0:
        kw["fade_distance_start"] = value / 2
    ssrlab.Settings(**kw).to_native()  # once refused with "must be in [0.000001, ...], got 0.000001"


def test_issue_8_lower_bounds():
    ssrlab.Settings(edge_depth_sigma=1e-6).to_native()
    ssrlab.Settings(hiz_crossing_offset=1e-5).to_native()
    with pytest.raises(ValueError, match="edge_depth_sigma"):
        ssrlab.Settings(edge_depth_sigma=0.9e-6)


@pytest.mark.parametrize("kw, fields", [
    (dict(hiz_stop_level=5, hiz_max_level=3), ("hiz_stop_level", "hiz_max_level")),
    (dict(hiz_start_level=4, hiz_max_level=3), ("hiz_start_level", "hiz_max_level")),
    (dict(fade_distance_start=5.0, fade_distance_end=5.0), ("fade_distance_start", "fade_distance_end")),
    (dict(fade_distance_start=5.0), ("fade_distance_start", "fade_distance_end")),
    (dict(fade_distance_end=3.0), ("fade_distance_start", "fade_distance_end")),
])
def test_cross_field_constraints_name_both_fields(kw, fields):
    for make in (lambda: ssrlab.Settings(**kw), lambda: ssrlab.Settings().replace(**kw),
                 lambda: ssrlab.Settings.from_dict(kw)):
        with pytest.raises(ValueError) as e:
            make()
        assert all(f in str(e.value) for f in fields), str(e.value)


# Settings that break one rule between fields each, by the rule's words (settings_rules.def).
BREAKS = {
    "glossy == 'stochastic' when method == 'bvh'": dict(method="bvh", glossy="cone"),
    "method != 'bvh' and fallback not in ('bvh', 'probes') when temporal_ray_reuse":
        dict(temporal_ray_reuse=True, fallback="probes"),
    "temporal_reflections is off when denoise == 'svgf'": dict(denoise="svgf", temporal_reflections=True),
    "glossy == 'stochastic' when fallback in ('bvh', 'probes')": dict(fallback="bvh", glossy="blur_mips"),
    "adaptive_rays, method in ('linear', 'hiz') and glossy == 'stochastic' when variance_rays":
        dict(variance_rays=True, adaptive_rays=True, method="off"),
    "hiz_stop_level <= hiz_max_level": dict(hiz_stop_level=5, hiz_max_level=3, hiz_start_level=0),
    "hiz_start_level <= hiz_max_level": dict(hiz_start_level=4, hiz_max_level=3),
    "fade_distance_end > fade_distance_start when fade_distance_start > 0":
        dict(fade_distance_start=2.5, fade_distance_end=0.125),
    "fade_distance_end == 0 when fade_distance_start == 0": dict(fade_distance_end=3.0),
}


def test_every_rule_between_fields_has_a_case_here():
    assert sorted(BREAKS) == sorted(c.rule for c in ssrlab.settings.CONSTRAINTS)


@pytest.mark.parametrize("rule", [c.rule for c in ssrlab.settings.CONSTRAINTS])
def test_a_rule_between_fields_reads_the_same_from_python_and_from_cpp_callers(rule, renderer):
    """One validation path: ssrlab.Settings raises the native rule's message word for word, as a
    C++ caller meets it in RenderSettings::validate() and at render."""
    kw = BREAKS[rule]
    with pytest.raises(ValueError) as python:
        ssrlab.Settings(**kw)
    native = _core.RenderSettings()
    for name, value in kw.items():
        setattr(native, name, value)
    with pytest.raises(ValueError) as validate:
        native.validate()
    scene = ssrlab.scenes.mirror_test()
    with pytest.raises(ValueError) as render:
        renderer._native.render(scene, scene.camera, native)
    assert str(python.value) == str(validate.value) == str(render.value)
    c = next(c for c in ssrlab.settings.CONSTRAINTS if c.rule == rule)
    got = ", ".join(f"{n}={ssrlab.Settings.__dataclass_fields__[n].default!r}" if n not in kw else f"{n}={kw[n]!r}"
                    for n in c.fields)
    assert str(python.value) == f"Settings: {rule} is violated ({got}); {c.why}"


def test_constraints_are_checked_at_render_after_single_assignments(renderer):
    s = ssrlab.Settings(width=16, height=16, method="hiz")
    s.hiz_max_level = 2  # assignments are checked per field, so related fields can be set in turn...
    s.hiz_start_level = 1
    s.hiz_stop_level = 3
    with pytest.raises(ValueError, match="hiz_stop_level.*hiz_max_level"):  # ...and together at render
        renderer.render(ssrlab.scenes.mirror_test(), settings=s)
    s.hiz_stop_level = 1
    renderer.render(ssrlab.scenes.mirror_test(), settings=s)


def test_valid_combinations_pass():
    ssrlab.Settings(hiz_start_level=3, hiz_stop_level=3, hiz_max_level=3)
    ssrlab.Settings(fade_distance_start=1.0, fade_distance_end=3.0)
    ssrlab.Settings(fade_camera_start=0.9, fade_camera_end=0.5)  # documented: no camera fade


def test_describe_lists_the_constraints():
    text = ssrlab.Settings.describe()
    assert "[constraints]" in text
    for c in ssrlab.settings.CONSTRAINTS:
        assert c.rule in text
    assert "hiz_stop_level <= hiz_max_level" in text
    assert "fade_camera_end <= fade_camera_start" in text


def test_an_image_beyond_the_device_texture_limit_names_the_texture_and_settings(renderer):
    # The Hi-Z tracer's atlas is 1.5x the image's width: an image wider than 2/3 of the device's
    # largest texture, which Settings accepts (up to 16384), cannot be traced with method="hiz".
    limit = int(renderer.info["max_texture_size"])
    width = limit * 2 // 3 + 2
    if width > 16384:
        pytest.skip(f"this device takes textures of {limit} texels: Settings' width limit comes first")
    s = ssrlab.Settings(width=width, height=8, method="hiz", layers=1, shadow_map_size=0)
    with pytest.raises(ValueError, match=r"Settings.width x Settings.height = .* 'hiz_trace' .*GL_MAX_TEXTURE_SIZE"):
        renderer.render(ssrlab.scenes.hall(), settings=s)
    # The renderer is still usable afterwards.
    assert renderer.render(ssrlab.scenes.hall(), settings=ssrlab.Settings(width=32, height=16)).color.shape == (16, 32, 3)


def test_a_frame_beyond_the_cpu_device_memory_is_refused_before_allocation(renderer):
    # On llvmpipe textures take system memory; an allocation beyond it would succeed (overcommit)
    # and the process be killed mid-frame. 16384 x 16384 with 16 layers needs hundreds of GiB.
    if renderer.info["device"] != "cpu":
        pytest.skip("the check is for the CPU device, whose textures live in system memory")
    try:
        with open("/proc/meminfo") as f:
            available = next(int(line.split()[1]) * 1024 for line in f if line.startswith("MemAvailable:"))
    except (OSError, StopIteration):
        pytest.skip("no /proc/meminfo here")
    if available > 2**40:
        pytest.skip("this machine has more than 1 TiB available")
    s = ssrlab.Settings(width=16384, height=16384, layers=16, rays_per_pixel=4)
    with pytest.raises(ValueError, match=r"Settings \(16384 x 16384, layers 16, rays_per_pixel 4, shadow_map_size 2048 "
                                         r"for 1 shadow-map face\) need .* GiB of "
                                         r"textures, more than the .* GiB of memory available"):
        renderer.render(ssrlab.scenes.hall(), settings=s)
    assert renderer.render(ssrlab.scenes.hall(), settings=ssrlab.Settings(width=32, height=16)).color.shape == (16, 32, 3)
