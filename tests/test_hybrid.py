"""Hybrid reflections: ray-traced reflections (method="bvh") and the BVH fallback
for rays screen space cannot resolve (fallback="bvh")."""
import numpy as np
import pytest

import ssrlab
from ssrlab.metrics import psnr
from conftest import assert_finite, small


def _traced(frame):
    """Rays the BVH traced (rays.radiance.a > -1.5 on a ray screen space did not keep: the
    fallback also shades the screen-space hits it keeps there) and their radiance."""
    rad = frame.read("rays.radiance")
    return (rad[..., 3] > -1.5) & ~frame.rays.hit, rad


@pytest.mark.parametrize("scene_name, kw", [
    ("hall", dict(scene=dict(floor_roughness=0.0))),                    # mirror floor
    ("spheres_and_boxes", dict(settings=dict(rays_per_pixel=2))),      # glossy, several rays
])
def test_bvh_method_equals_the_per_ray_reference(renderer, scene_name, kw):
    scene = ssrlab.scenes.load(scene_name, **kw.get("scene", {}))
    f = renderer.render(scene, settings=small(method="bvh", **kw.get("settings", {})))
    assert "trace_bvh" in f.passes and "trace_linear" not in f.passes
    traced, rad = _traced(f)
    assert traced.sum() > 100
    assert (rad[..., 3][traced] >= 0).sum() > 50  # some rays hit triangles
    # The pass shades the physical reflection: the ray's origin views the hit, the shadow map shadows it.
    ref = f.reference("per_ray", viewer="ray", shadows="map")
    assert np.abs(ref.radiance[traced] - rad[..., :3][traced]).max() <= 1e-5
    # Where the BVH hit, the reference hit at the same distance.
    hit = traced & (rad[..., 3] >= 0)
    np.testing.assert_allclose(ref.t[hit], rad[..., 3][hit], rtol=1e-5, atol=1e-5)
    assert_finite(f.reflection)


def test_bvh_rays_leave_the_exact_surface_point_whatever_the_origin_bias(renderer):
    # The BVH passes start their rays where the converged reference starts its own (the camera
    # ray's hit, moved off by a few ulps), not at the G-buffer point lifted by origin_bias: with
    # the lift, a mirror floor's reflection rays passed beside the pews' edges the reference's
    # rays met (hall, default origin_bias 0.002, 160x120: 28 dB on the floor).
    scene = ssrlab.scenes.hall(floor_roughness=0.0)
    st = small(width=160, height=120, method="bvh")
    f = renderer.render(scene, settings=st)
    floor = f.gbuffer.object_id[0] == 0
    truth = f.reference("converged", rays=1, viewer="ray", shadows="map").reflection[..., :3]
    assert psnr(f.reflection[..., :3], truth, mask=floor) > 40.0
    g = renderer.render(scene, settings=st.replace(origin_bias=0.05))
    np.testing.assert_array_equal(g.read("rays.radiance"), f.read("rays.radiance"))
    # The BVH fallback retraces its rays from the same points.
    h = renderer.render(scene, settings=st.replace(method="linear", fallback="bvh"))
    traced, rad = _traced(h)
    assert traced.sum() > 100
    np.testing.assert_array_equal(rad[traced], f.read("rays.radiance")[traced])


def test_fallback_bvh_beats_screen_space_alone_on_the_mirror_floor(renderer):
    # hall's default view: the floor's reflections leave the top of the screen.
    scene = ssrlab.scenes.hall(floor_roughness=0.0)
    st = small(width=128, height=96, origin_bias=0.0005)
    f = renderer.render(scene, settings=st)
    floor = f.gbuffer.object_id[0] == 0
    truth = f.reference("converged", rays=1, viewer="ray", shadows="map").reflection[..., :3]
    score = {}
    stats = {}
    for name, kw in {"none": dict(fallback="none"), "environment": dict(fallback="environment"),
                     "bvh_fallback": dict(fallback="bvh"), "bvh": dict(method="bvh")}.items():
        g = renderer.render(scene, settings=st.replace(**kw))
        assert_finite(g.reflection)
        score[name] = psnr(g.reflection[..., :3], truth, mask=floor)
        stats[name] = g.fallback_stats
        assert sum(stats[name][k] for k in ("screen", "bvh", "environment", "none")) == pytest.approx(1.0)
    assert score["none"] < score["environment"] < score["bvh_fallback"] - 1.0
    # The confidence test's rejected hits, retraced, lower the error further.
    g = renderer.render(scene, settings=st.replace(fallback="bvh", fallback_confidence=False))
    assert g.fallback_stats["rejected"] == 0.0
    assert psnr(g.reflection[..., :3], truth, mask=floor) < score["bvh_fallback"]
    assert score["bvh"] > 35.0
    # What each frame resolved where.
    assert stats["environment"]["bvh"] == 0.0 and stats["environment"]["environment"] > 0.05
    assert stats["none"]["none"] == pytest.approx(stats["environment"]["environment"])
    assert stats["bvh_fallback"]["bvh"] > 0.01  # most unresolved rays leave into the sky
    assert stats["bvh_fallback"]["bvh"] + stats["bvh_fallback"]["environment"] == pytest.approx(
        stats["environment"]["environment"] + stats["bvh_fallback"]["rejected"])
    # Screen space resolved the same rays; the confidence test sent some of its hits to the BVH.
    assert stats["bvh_fallback"]["screen"] + stats["bvh_fallback"]["rejected"] == pytest.approx(
        stats["environment"]["screen"])
    assert stats["bvh_fallback"]["rejected"] > 0.0
    assert stats["bvh"]["screen"] == 0.0 and stats["bvh"]["bvh"] > 0.5


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_fallback_only_retraces_what_screen_space_did_not_resolve(renderer, method):
    scene = ssrlab.scenes.hall(floor_roughness=0.0)
    f = renderer.render(scene, settings=small(method=method, fallback="bvh"))
    assert f.passes.index(f"trace_{method}") < f.passes.index("fallback_bvh") < f.passes.index("resolve")
    traced, _ = _traced(f)
    hit = f.read("rays.hit")
    resolved = (hit[..., 2] > 0.5) & (hit[..., 3] >= 1.0)
    assert traced.any() and resolved.any()
    assert not (traced & resolved).any()  # hits screen space resolved (and kept) are not retraced
    smp = f.read("rays.sample")
    assert not (traced & ~((smp[..., 3] > 0.5) & (smp[..., 0] > 0))).any()  # only rays that exist


def test_hybrid_settings_are_validated():
    with pytest.raises(ValueError, match="fallback"):
        ssrlab.Settings(fallback="cubemap")
    with pytest.raises(ValueError, match="glossy"):
        ssrlab.Settings(method="bvh", glossy="cone")
    with pytest.raises(ValueError, match="glossy"):
        ssrlab.Settings(fallback="bvh", glossy="blur_mips")
    native = ssrlab.Settings().to_native()
    native.method = "bvh"
    native.glossy = "cone"
    with pytest.raises(ValueError, match="bvh"):
        native.validate()
    with pytest.raises(ValueError, match="temporal_ray_reuse"):
        ssrlab.Settings(method="bvh", temporal_ray_reuse=True)
    assert ssrlab.Settings().fallback == "environment"
