"""The renderer: devices, settings and camera validation, timings, determinism, frames."""

import numpy as np
import pytest

import ssrlab
from conftest import small


def test_info_reports_the_device(renderer):
    info = renderer.info
    for key in ("vendor", "renderer", "gl_version", "device", "requested"):
        assert info[key]
    assert info["device"] in ("gpu", "cpu")
    assert "4.5" in info["gl_version"] or "4.6" in info["gl_version"]


@pytest.mark.needs_cpu_device
def test_cpu_device_is_llvmpipe():
    assert ssrlab.Renderer("cpu").info["device"] == "cpu"


def test_gpu_request_without_a_gpu_raises(renderer):
    if renderer.info["device"] == "gpu":
        pytest.skip("this machine has a GPU")
    with pytest.raises(ssrlab.DeviceError, match="gpu"):
        ssrlab.Renderer("gpu")


def test_unknown_device():
    with pytest.raises(ValueError, match="device"):
        ssrlab.Renderer("tpu")


def test_same_inputs_give_the_same_image(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=5)
    a = renderer.render(scene, settings=small(layers=3))
    b = renderer.render(ssrlab.scenes.spheres_and_boxes(seed=5), settings=small(layers=3))
    np.testing.assert_array_equal(a.color, b.color)
    np.testing.assert_array_equal(a.gbuffer.depth, b.gbuffer.depth)


def test_timings_cover_every_pass_and_layer(renderer):
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(), settings=small(layers=3, skip=True, deep_gbuffer="peel"))
    t = f.timings
    # With imageLoad (the CPU device) the resolve's tile fill is a pass of its own.
    fetch = ["resolve_fetch"] if renderer.info["input_fetch"] == "imageLoad" else []
    assert f.passes == ["depth_peel", "shadow_map", "lighting", "classify", "trace_linear", "specular_occlusion",
                        *fetch, "resolve", "composite"]
    for name in f.passes + [f"depth_peel.layer{i}" for i in range(3)] + ["specular_occlusion.cells"]:
        assert t[name] > 0, name
    assert t["total"] == pytest.approx(sum(t[p] for p in f.passes))
    assert sum(t[f"depth_peel.layer{i}"] for i in range(3)) <= t["depth_peel"] * 1.001


def test_no_shadow_pass_without_a_shadow_caster(renderer):
    f = renderer.render(ssrlab.scenes.mirror_test(), settings=small())
    assert "shadow_map" not in f.passes


def test_frames_keep_their_images(renderer):
    scene = ssrlab.scenes.spheres_and_boxes()
    a = renderer.render(scene, settings=small(layers=2))
    b = renderer.render(scene, settings=small(layers=2, shadow_map_size=0))
    assert not np.array_equal(a.color, b.color)
    again = renderer.render(scene, settings=small(layers=2))
    np.testing.assert_array_equal(a.color, again.color)


def test_images_are_read_back_only_when_asked(renderer):
    f = renderer.render(ssrlab.scenes.mirror_test(), settings=small())
    assert f._cache == {}
    _ = f.gbuffer.depth
    assert list(f._cache) == ["linear_depth@0"]


def test_scene_edits_reach_the_gpu(renderer):
    scene = ssrlab.scenes.mirror_test()
    before = renderer.render(scene, settings=small()).color
    scene.set_material(0, ssrlab.Material(base_color=(1, 0, 0), roughness=0.5))
    after = renderer.render(scene, settings=small()).color
    assert not np.array_equal(before, after)


@pytest.mark.parametrize("field, value", [
    ("width", 0), ("height", -3), ("layers", 20), ("depth_mode", "inverse"), ("shadow_map_size", 8),
    ("shadow_pcf_radius", 9), ("shadow_normal_offset", float("nan")), ("backface_culling", "yes"),
])
def test_invalid_settings_name_the_field(field, value):
    with pytest.raises(ValueError, match=f"Settings.{field}"):
        ssrlab.Settings(**{field: value})
    s = ssrlab.Settings()
    with pytest.raises(ValueError, match=f"Settings.{field}"):
        setattr(s, field, value)


def test_unknown_setting():
    with pytest.raises(ValueError, match="unknown Settings field"):
        ssrlab.Settings().replace(strid=2)
    with pytest.raises(AttributeError, match="no field"):
        ssrlab.Settings().layerz = 3


@pytest.mark.parametrize("kwargs, field", [
    ({"position": (0, 0, 0), "target": (0, 0, 0)}, "target"),
    ({"fov_y": 0}, "fov_y"), ({"fov_y": 180}, "fov_y"), ({"near": 0}, "near"),
    ({"near": 1, "far": 0.5}, "far"), ({"up": (0, 0, -1), "position": (0, 0, 5)}, "up"),
    ({"position": (float("nan"), 0, 0)}, "position"),
])
def test_invalid_camera(kwargs, field):
    with pytest.raises(ValueError, match=f"Camera.{field}"):
        ssrlab.Camera(**kwargs)


def test_bad_meshes_raise_clear_errors():
    s = ssrlab.Scene()
    with pytest.raises(ValueError, match="out of range"):
        s.add_mesh(np.zeros((3, 3)), [[0, 1, 5]], name="tri")
    with pytest.raises(ValueError, match="NaN"):
        s.add_mesh(np.full((3, 3), np.nan), [[0, 1, 2]])
    with pytest.raises(ValueError, match="shape"):
        s.add_mesh(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(ValueError, match="normals"):
        s.add_mesh(np.zeros((3, 3)), [[0, 1, 2]], normals=np.zeros((2, 3)))
    with pytest.raises(ValueError, match="roughness"):
        ssrlab.Material(roughness=1.5)
    with pytest.raises(ValueError, match="radius"):
        s.add_sphere((0, 0, 0), -1)
    assert s.object_count == 0


def test_empty_scene_renders_the_environment(renderer):
    s = ssrlab.Scene()
    s.environment = ssrlab.Environment.constant((0.2, 0.3, 0.4))
    f = renderer.render(s, ssrlab.Camera(), small())
    np.testing.assert_allclose(f.color, np.broadcast_to([0.2, 0.3, 0.4], f.color.shape), atol=1e-6)


def test_primitives_wind_counter_clockwise_from_outside():
    s = ssrlab.Scene()
    for obj in (s.add_plane(), s.add_box(), s.add_sphere(segments=24)):
        m = s.object_mesh(obj)
        p, n, idx = m["positions"], m["normals"], m["indices"]
        a, b, c = p[idx[:, 0]], p[idx[:, 1]], p[idx[:, 2]]
        face = np.cross(b - a, c - a)
        assert np.all(np.einsum("ij,ij->i", face, n[idx[:, 0]]) > 0), m["name"]


def test_renderers_across_threads_keep_their_objects_apart(renderer):
    """A Renderer made and used on a worker thread, then dropped on this one, must delete its
    GL objects in its own context, never in another renderer's (which once lost its buffers)."""
    import gc
    import threading

    scene = ssrlab.scenes.mirror_test()
    before = renderer.render(scene, settings=small()).color
    made = {}

    def work():
        r = ssrlab.Renderer()
        made["renderer"] = r
        made["color"] = r.render(scene, settings=small()).color

    t = threading.Thread(target=work)
    t.start()
    t.join()
    np.testing.assert_array_equal(made["color"], before)
    # Used again from this thread, then destroyed here.
    np.testing.assert_array_equal(made["renderer"].render(scene, settings=small()).color, before)
    del made["renderer"]
    gc.collect()
    np.testing.assert_array_equal(renderer.render(scene, settings=small()).color, before)
