"""Frames share per-renderer scratch, release their textures, and memory of dropped
frames goes back to the OS. (benchmarks/timing/memory.py runs the 1000-render version.)"""

import gc
import os
import warnings

import numpy as np
import pytest

import ssrlab
from conftest import small

MIB = 1 << 20


def rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


@pytest.fixture
def fresh():
    # A renderer of its own: the pool and the frame count are this test's alone.
    r = ssrlab.Renderer("auto")
    yield r
    gc.collect()


def test_kept_frames_do_not_hold_a_shadow_map_each(fresh):
    scene = ssrlab.scenes.spheres_and_boxes()
    s = ssrlab.Settings(width=64, height=48, shadow_map_size=2048)
    frames = [fresh.render(scene, settings=s) for _ in range(3)]
    assert "shadow_map" in frames[0].passes
    per_frame = [f.gpu_bytes for f in frames]
    assert max(per_frame) < 1 * MIB, per_frame  # each frame once held 16 MiB
    # The renderer holds one shadow map (2048^2 * 4 bytes) however many frames are kept.
    assert fresh._native.scratch_bytes >= 2048 * 2048 * 4
    assert fresh.gpu_bytes < sum(per_frame) + fresh._native.scratch_bytes + 1
    assert len(fresh.live_frames) == 3


def test_release_and_context_manager(fresh):
    scene = ssrlab.scenes.mirror_test()
    with fresh.render(scene, settings=small(width=32, height=24)) as f:
        color = f.color.copy()
        assert f.gpu_bytes > 0 and len(fresh.live_frames) == 1
    assert f.released and f.gpu_bytes == 0 and len(fresh.live_frames) == 0
    assert np.isfinite(color).all()
    for read in (lambda: f.color, lambda: f.gbuffer.depth, lambda: f.rays, lambda: f.reflection,
                 lambda: f.read("lit"), lambda: f.reference("per_ray")):
        with pytest.raises(ValueError, match="released"):
            read()
    f.release()  # idempotent
    g = fresh.render(scene, settings=small(width=32, height=24))
    del g
    gc.collect()
    assert len(fresh.live_frames) == 0


def test_scratch_is_readable_until_the_next_render(fresh):
    scene = ssrlab.scenes.spheres_and_boxes()
    a = fresh.render(scene, settings=small(width=40, height=30, method="hiz"))
    assert "hiz" in a.texture_names
    pyramid = a.read("hiz")
    assert pyramid.shape[1:3] == (30, 40)
    b = fresh.render(scene, settings=small(width=40, height=30, method="hiz"))
    assert "hiz" not in a.texture_names and "hiz" in b.texture_names
    with pytest.raises(ValueError, match="scratch"):
        a.read("hiz", 1)
    a.read("color")  # the frame's own textures stay


def test_reference_re_renders_the_shared_shadow_map(fresh):
    """A per-ray reference (shadows="map") of an older frame shades with that frame's shadow map, though a
    later frame with another shadow-map size has overwritten the shared one."""
    scene = ssrlab.scenes.spheres_and_boxes()
    s = small(width=64, height=48, sampling="mirror")
    a = fresh.render(scene, settings=s)
    first = a.reference("per_ray", shadows="map").radiance.copy()
    b = fresh.render(scene, settings=s.replace(shadow_map_size=256))
    assert "shadow_map" in b.passes and "shadow_map" not in a.texture_names
    other = b.reference("per_ray", shadows="map").radiance
    assert np.abs(other - first).max() > 1e-3  # the shadow map's size shows in the shading...
    again = a.reference("per_ray", shadows="map").radiance
    np.testing.assert_array_equal(first, again)  # ...and a's reference got a's shadow map back


def test_kept_then_dropped_frames_give_memory_back(fresh):
    scene = ssrlab.scenes.spheres_and_boxes()
    s = ssrlab.Settings(width=64, height=48, shadow_map_size=2048)
    for _ in range(20):  # warm-up: shaders, pool, allocator
        fresh.render(scene, settings=s).color
    gc.collect()
    start = rss_bytes()
    kept = []
    for _ in range(150):
        kept.append(fresh.render(scene, settings=s))
    held = rss_bytes() - start
    per_frame_rss = held / len(kept)
    per_frame_api = np.mean([f.gpu_bytes for f in kept])
    assert per_frame_api < 1 * MIB
    assert per_frame_rss < 1 * MIB, f"{per_frame_rss / MIB:.2f} MiB of RSS per kept frame"
    del kept
    gc.collect()
    end = rss_bytes()
    assert end < 1.10 * start, f"RSS {start / MIB:.0f} MiB -> {end / MIB:.0f} MiB after dropping the frames"
    assert len(fresh.live_frames) == 0


def test_cylinder_engine_camera_warns_about_depth_precision(renderer):
    from conftest import model_path
    scene = ssrlab.Scene.load(model_path("2CylinderEngine/2CylinderEngine.glb"))
    cam = scene.camera
    assert cam.far / cam.near > ssrlab.renderer.STANDARD_DEPTH_SAFE_RATIO
    with pytest.warns(ssrlab.renderer.DepthPrecisionWarning, match="reversed_z"):
        renderer.render(scene, settings=small(width=32, height=24, method="off"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        renderer.render(scene, settings=small(width=32, height=24, method="off", depth_mode="reversed_z"))
        renderer.render(ssrlab.scenes.mirror_test(), settings=small(width=32, height=24))
