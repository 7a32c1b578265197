"""Hybrid reflections, the rest: reflection probes (fallback="probes", seed 004's local
cube maps), traced shadows in the BVH passes (bvh_shadows="traced"), and how often SSR's accepted
hits are wrong against the per-ray reference (reference.wrong_hits)."""
import numpy as np
import pytest

import ssrlab
from ssrlab.metrics import psnr, thesis_error
from ssrlab.reference import wrong_hits
from conftest import assert_finite, small


def _room() -> ssrlab.Scene:
    """A closed room of planes (its bounds are its walls: box projection is exact there), a
    mirror floor, diffuse walls of distinct colours lit by a point light, no shadow caster."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), (8, 8), material=ssrlab.Material(base_color=(0.5, 0.5, 0.5), roughness=0.0,
                                                            reflectivity=1.0, metallic=1.0), name="floor")
    walls = [((0, 4, -4), (0, 0, 1), (0.8, 0.2, 0.1)), ((0, 4, 4), (0, 0, -1), (0.1, 0.6, 0.2)),
             ((-4, 4, 0), (1, 0, 0), (0.2, 0.3, 0.9)), ((4, 4, 0), (-1, 0, 0), (0.9, 0.8, 0.2)),
             ((0, 8, 0), (0, -1, 0), (0.7, 0.7, 0.7))]
    for i, (c, n, col) in enumerate(walls):
        s.add_plane(c, (8, 8), normal=n, material=ssrlab.Material(base_color=col, roughness=1.0), name=f"wall{i}")
    s.add_light(ssrlab.point_light((0.5, 6.0, 0.5), intensity=60.0))
    s.camera = ssrlab.Camera(position=(0.0, 3.0, 3.5), target=(0.0, 0.0, -2.0), fov_y=70.0, near=0.05, far=30.0)
    return s


def test_probe_lookup_returns_the_traced_colour(renderer):
    # Every ray goes to the probe (max_steps=1: screen space resolves almost none); the probe,
    # placed off-centre so that the lookup needs its parallax correction, must bring what the
    # ray truly sees (the per-ray reference, viewed from the ray: the probe views from its
    # centre, so only the walls' small view-dependent specular and texel filtering differ).
    scene = _room()
    scene.probes = [(1.0, 2.0, -1.5)]
    f = renderer.render(scene, settings=small(width=128, height=96, fallback="probes", max_steps=1, probe_size=64))
    assert "fallback_probes" in f.passes and f.stats["probes"] == 1
    rad = f.read("rays.radiance")
    looked = rad[..., 3] >= 0.0
    assert looked.sum() > 2000 and f.fallback_stats["probes"] > 0.9
    truth = f.reference("per_ray", viewer="ray", shadows="map").radiance
    rel = np.abs(rad[..., :3] - truth).sum(-1)[looked] / truth.sum(-1)[looked]
    assert np.median(rel) < 0.03 and np.percentile(rel, 90) < 0.1, (np.median(rel), np.percentile(rel, 90))
    # The distance channel: the estimated hit lies where the ray truly hits.
    t_true = f.reference("per_ray", viewer="ray", shadows="map").t
    assert np.median(np.abs(rad[..., 3][looked] - t_true[looked]) / t_true[looked]) < 0.02
    # Against the environment the walls were lost.
    e = renderer.render(scene, settings=f.settings.replace(fallback="environment"))
    assert psnr(f.reflection, e.reflection) < 30.0


def test_probes_beat_the_environment_on_hall_and_are_cached(renderer):
    # 160x120: at 128x96 the hall's unresolved rays are a few corner pixels where the centre
    # probe helps one corner and hurts the other (the README's figures are at 640x360).
    scene = ssrlab.scenes.hall(floor_roughness=0.0)
    # Against the bare environment (specular occlusion also darkens the hall's misses, and
    # beats the probes there: 0.029 against 0.034; tests/test_occlusion.py).
    st = small(width=160, height=120, origin_bias=0.0005, specular_occlusion="off")
    f = renderer.render(scene, settings=st)
    floor = f.gbuffer.object_id[0] == 0
    ref = f.reference("converged", rays=1, viewer="camera", shadows="map")
    truth = ref.reflection[..., :3]
    p = renderer.render(scene, settings=st.replace(fallback="probes", probe_size=64))
    assert p.stats["probe_capture_ms"] > 0.0 and p.stats["probes"] == 1  # one probe: the bounds' centre
    assert_finite(p.reflection)
    err = {"env": thesis_error(f.reflection[..., :3], truth, ref.reflective),
           "probes": thesis_error(p.reflection[..., :3], truth, ref.reflective)}
    assert err["probes"] < 0.9 * err["env"], err
    assert psnr(p.reflection[..., :3], truth, mask=floor) > psnr(f.reflection[..., :3], truth, mask=floor)
    s = p.fallback_stats
    assert s["probes"] > 0.0 and s["bvh"] == 0.0 and s["rejected"] == 0.0
    assert sum(s[k] for k in ("screen", "probes", "environment", "none")) == pytest.approx(1.0)
    # Cached on the renderer: the next frame (another view too) does not capture again.
    q = renderer.render(scene, settings=st.replace(fallback="probes", probe_size=64))
    assert q.stats["probe_capture_ms"] == 0.0
    np.testing.assert_array_equal(q.reflection, p.reflection)
    assert "fallback_probes" in q.timings
    # A new probe set is captured again.
    moved = scene.copy()
    moved.probes = [(0.0, 0.5, 1.5)]
    assert renderer.render(moved, settings=st.replace(fallback="probes", probe_size=64)).stats["probe_capture_ms"] > 0


def test_bad_probe_positions_raise(renderer):
    scene = ssrlab.scenes.hall()
    with pytest.raises(ValueError, match="Scene.probes.*finite"):
        scene.probes = [(0.0, 1.0, 0.0), (0.0, float("nan"), 0.0)]
    with pytest.raises(ValueError, match=r"Scene.probes.*shape \(n, 3\)"):
        scene.probes = [(0.0, 1.0)]
    with pytest.raises(ValueError, match="at most 64"):
        scene.probes = [(0.0, 1.0, 0.0)] * 65
    scene.probes = [(0.0, 1.0, 0.0), (0.0, 50.0, 0.0)]  # the second above the hall's 8 m walls
    assert scene.probes[1] == (0.0, 50.0, 0.0)
    with pytest.raises(ValueError, match=r"Scene.probes: probe 1 at \(0, 50, 0\) lies outside the scene bounds"):
        renderer.render(scene, settings=small(fallback="probes"))
    scene.probes = []
    assert renderer.render(scene, settings=small(fallback="probes", probe_grid=2)).stats["probes"] == 8
    with pytest.raises(ValueError, match="probe_grid"):
        ssrlab.Settings(probe_grid=0)
    with pytest.raises(ValueError, match="glossy"):
        ssrlab.Settings(fallback="probes", glossy="cone")


@pytest.mark.parametrize("scene_name, kw", [
    ("hall", dict(scene=dict(floor_roughness=0.0))),
    ("spheres_and_boxes", dict(settings=dict(rays_per_pixel=2))),
])
def test_bvh_with_traced_shadows_equals_the_reference_with_traced_shadows(renderer, scene_name, kw):
    scene = ssrlab.scenes.load(scene_name, **kw.get("scene", {}))
    st = small(method="bvh", bvh_shadows="traced", **kw.get("settings", {}))
    f = renderer.render(scene, settings=st)
    rad = f.read("rays.radiance")
    traced = rad[..., 3] > -1.5
    assert traced.sum() > 100
    ref = f.reference("per_ray", viewer="ray", shadows="traced").radiance
    assert np.abs(ref[traced] - rad[..., :3][traced]).max() <= 1e-5
    # And the option acts: the shadow map's blur differs from the traced shadow somewhere.
    m = renderer.render(scene, settings=st.replace(bvh_shadows="map")).read("rays.radiance")
    assert np.abs(m[..., :3] - rad[..., :3])[traced].max() > 1e-3


def test_fallback_bvh_with_traced_shadows(renderer):
    scene = ssrlab.scenes.hall(floor_roughness=0.0)
    f = renderer.render(scene, settings=small(fallback="bvh", bvh_shadows="traced"))
    rad = f.read("rays.radiance")
    traced = (rad[..., 3] > -1.5) & ~f.rays.hit  # retraced by the BVH (kept screen hits are shaded there too)
    assert traced.any()
    ref = f.reference("per_ray", viewer="ray", shadows="traced")
    # The fallback retraces from the ray's origin the ray the per-ray reference traces.
    assert np.abs(ref.radiance[traced] - rad[..., :3][traced]).max() <= 1e-5


def test_confidence_lowers_the_share_of_wrong_accepted_hits(renderer):
    # hall's mirror floor with a generous thickness (1 m): rays grazing the pews' top edges and
    # the columns' sides are accepted as hits where the true ray passes by.
    scene = ssrlab.scenes.hall(floor_roughness=0.0)
    st = small(width=128, height=96, origin_bias=0.0005, thickness=1.0, fallback="bvh")
    w = {}
    for conf in (False, True):
        f = renderer.render(scene, settings=st.replace(fallback_confidence=conf))
        w[conf] = wrong_hits(f, tolerance_px=2.0)
    assert w[False]["wrong"] > 5
    assert w[True]["wrong_share"] < 0.5 * w[False]["wrong_share"], w
    assert w[True]["accepted"] < w[False]["accepted"]  # the test rejected hits (and retraced them)
