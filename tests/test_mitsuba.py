"""The converged reference against Mitsuba 3, at 64x48 (the glossy floors at 96x54) on
ssrlab.crosscheck's scene: a white metallic floor with boxes and spheres of ssrlab's dielectric
material, a back wall and a shadow-casting sun; no ambient, black environment. Floor pixels only
(without silhouette pixels). Mitsuba traces rays through the pixel centres with its path
integrator (max_depth 3). The floor is Mitsuba's own BSDF (conductor for the mirror,
roughconductor with GGX, visible-normal sampling and alpha = roughness^2 for glossy floors;
material "none", whose Fresnel factor is 1 as ssrlab's Schlick F with F0 = 1 is), so its
microfacet BRDF, Fresnel and sampling are Mitsuba's, not ssrlab's; the objects, which no Mitsuba
BSDF models as ssrlab does, are a Dr.Jit copy of ssrlab's BRDF (crosscheck.SsrlabBSDF), as is
the floor with bsdf="ssrlab". Full-size figures and the diagnosis:
benchmarks/accuracy/mitsuba_crosscheck.py."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

pytest.importorskip("mitsuba")

import ssrlab  # noqa: E402
from ssrlab import crosscheck as cc  # noqa: E402

W, H = 64, 48
GW, GH, GLOSSY_SPP = 96, 54, 128  # the glossy floors against Mitsuba's roughconductor
TINY_BIAS = dict(origin_bias=1e-5)
# Agreement "to the noise": the bias, in standard errors measured from two seeds of each renderer
# (crosscheck.noise_agreement), at most this; a deterministic seed makes it pass or fail always.
NOISE_Z = 4.0


@pytest.fixture(scope="module")
def mitsuba():
    try:
        return cc.load_mitsuba()
    except ImportError as e:
        pytest.skip(f"mitsuba does not load here: {e}")


@pytest.fixture(scope="module")
def mirror(mitsuba):
    scene = cc.crosscheck_scene(0.0)
    ms = cc.mitsuba_scene(scene, width=W, height=H, bsdf="mitsuba")
    assert ms.own_bsdf == {cc.FLOOR: "conductor"}  # the floor is Mitsuba's own mirror, the objects the port
    return scene, ms, cc.render_mitsuba(ms, spp=1)


def _settings(**kw):
    return ssrlab.Settings(width=W, height=H, **kw)


def test_scene_and_camera_line_up(renderer, mirror):
    scene, ms, _ = mirror
    frame, _ = cc.ssrlab_reference(renderer, scene, _settings())
    g = frame.gbuffer
    ours = np.where(g.coverage[0], g.object_id[0], -1)
    theirs = cc.first_hit_objects(ms)
    assert set(np.unique(theirs)) - {-1} == set(range(scene.object_count))
    # Both sample the pixel centres of the same triangles: only a sample that lands exactly on a
    # shared edge may differ.
    assert (ours == theirs).mean() >= 0.995


def test_mirror_floor_exact_options(renderer, mirror):
    """With the physical viewer and a tiny ray offset (or the robust offset), the mirror floor
    matches to float precision on floor pixels whose reflection lands on no silhouette: 74 dB at
    160x90, 72 dB at 640x360 (benchmark; what is left is the smooth-shaded spheres' shadow
    terminator, shadow map against traced shadow). 55 dB still fails for any real difference:
    a 1 % error in the sun's contribution alone costs ~50 dB here."""
    scene, ms, mit = mirror
    settings, kwargs, _ = cc.exact_options(_settings(**TINY_BIAS))
    frame, truth = cc.ssrlab_reference(renderer, scene, settings, **kwargs)
    floor = cc.floor_pixels(frame) & ~cc.reflected_silhouettes(ms)
    assert floor.sum() > 600
    value = cc.floor_psnr(truth.color, mit, floor)
    print(f"mirror floor, exact options: {value:.1f} dB")
    assert value >= 55.0


def test_mirror_floor_default_settings(renderer, mirror):
    """Default settings against Mitsuba's own conductor on the mirror floor: >= 45 dB (79.7 here).
    The reference's rays leave the exact floor point (not SSR's origin_bias), its shadows are
    traced and it views reflected surfaces physically (viewer='ray'); with SSR's origin offset and
    the camera as viewer (the defaults before) this scene measured 33-35 dB."""
    scene, ms, mit = mirror
    frame, truth = cc.ssrlab_reference(renderer, scene, _settings())
    floor = cc.floor_pixels(frame) & ~cc.reflected_silhouettes(ms)
    value = cc.floor_psnr(truth.color, mit, floor)
    print(f"mirror floor, default settings, Mitsuba's conductor: {value:.1f} dB")
    assert value >= 45.0


def test_hybrid_and_bvh_frames_against_mitsuba(renderer, mirror):
    """The frames themselves at default settings, not the reference: SSR + the BVH fallback and
    pure BVH (traced shadows in the BVH passes) against Mitsuba on the floor pixels whose
    reflection lands on no silhouette (59.8 and 76.5 dB here; 320x180 and 640x360 in
    benchmarks/accuracy/mitsuba_crosscheck.py's frames table). SSR alone, which keeps every hit it finds,
    stays far below (34.8 dB)."""
    scene, ms, mit = mirror
    values = {}
    for name, kw in {"ssr": {}, "hybrid": dict(fallback="bvh"), "bvh": dict(method="bvh")}.items():
        f = renderer.render(scene, settings=_settings(**kw))
        floor = cc.floor_pixels(f) & ~cc.reflected_silhouettes(ms)
        values[name] = cc.floor_psnr(f.color, mit, floor)
    print(f"frames against Mitsuba: {values}")
    assert values["hybrid"] >= 50.0 and values["bvh"] >= 50.0 and values["ssr"] < 40.0, values


def test_moved_frame_agrees_as_a_still_frame_does(renderer, mitsuba):
    """A frame of a sequence after objects moved (ssrlab.crosscheck.MOVES: a sphere slid, a box
    turned and slid, a sphere lifted): its converged reference comes from the scene's updated GPU
    entries, BVH and shadow maps; Mitsuba renders the moved scene from scratch. The mirror floor
    agrees as a still frame's does (>= 45 dB at default settings), on the moved objects'
    triangles (camera rays hit the same objects), and the objects did move in the image."""
    scene = cc.crosscheck_scene(0.0)
    still, _ = cc.ssrlab_reference(renderer, scene, _settings())
    still_ids = np.where(still.gbuffer.coverage[0], still.gbuffer.object_id[0], -1)
    frame, truth = cc.moved_reference(renderer, scene, _settings())
    ms = cc.mitsuba_scene(scene, width=W, height=H)
    mit = cc.render_mitsuba(ms, spp=1)
    ours = np.where(frame.gbuffer.coverage[0], frame.gbuffer.object_id[0], -1)
    assert (ours == cc.first_hit_objects(ms)).mean() >= 0.995
    assert (ours != still_ids).sum() > 50  # the objects moved on screen
    floor = cc.floor_pixels(frame) & ~cc.reflected_silhouettes(ms)
    assert floor.sum() > 600
    value = cc.floor_psnr(truth.color, mit, floor)
    print(f"mirror floor, moved frame, default settings: {value:.1f} dB")
    assert value >= 45.0


def test_tinted_mirror_fresnel(renderer, mitsuba):
    """A coloured mirror with Schlick's Fresnel through composite='pbr': the composite's F(N.V)
    with the G-buffer's 8-bit sRGB F0 against Mitsuba's float F0 (66 dB at 160x90). Mitsuba has no
    Schlick Fresnel (its conductors' is the exact one of an eta and k), so this floor is the port."""
    scene = cc.crosscheck_scene(0.0, floor_color=(0.95, 0.64, 0.54))
    ms = cc.mitsuba_scene(scene, width=W, height=H)
    assert ms.own_bsdf == {}
    mit = cc.render_mitsuba(ms, spp=1)
    settings, kwargs, _ = cc.exact_options(_settings(composite="pbr", **TINY_BIAS))
    frame, truth = cc.ssrlab_reference(renderer, scene, settings, **kwargs)
    value = cc.floor_psnr(truth.color, mit, cc.floor_pixels(frame) & ~cc.reflected_silhouettes(ms))
    print(f"tinted mirror, pbr: {value:.1f} dB")
    assert value >= 55.0


@pytest.mark.parametrize("roughness", [0.2, 0.5])
def test_glossy_floor_mitsuba_roughconductor(renderer, mitsuba, roughness):
    """Mitsuba's own roughconductor (GGX, visible normals, alpha = roughness^2, Fresnel 1) against
    the converged reference (composite='pbr': the floor's direct light plus its reflection times
    the GGX directional albedo) on the glossy floor, 128 samples per pixel in both, two seeds each.
    They agree to their noise: the floor's mean difference and its per-pixel squared bias are both
    within NOISE_Z standard errors measured from the seeds (crosscheck.noise_agreement; it measures
    z = 1.2 and -0.04 at roughness 0.2, 1.9 and 0.5 at 0.5). The test's power, measured with
    Mitsuba's floor changed: alpha = roughness (not squared) fails by z 55-135, Beckmann for GGX
    by 22-91, a Fresnel factor of 0.98 by 15-17 (a 2 % darker floor), alpha 10 % too large by 44 at
    roughness 0.5 (at 0.2 it stays just inside, z 3.9); sample_visible=False (another sampler of
    the same BRDF) passes."""
    scene = cc.crosscheck_scene(roughness)
    ms = cc.mitsuba_scene(scene, width=GW, height=GH, bsdf="mitsuba")
    assert ms.own_bsdf == {cc.FLOOR: "roughconductor"}
    m1 = cc.render_mitsuba(ms, spp=GLOSSY_SPP, seed=1)
    m2 = cc.render_mitsuba(ms, spp=GLOSSY_SPP, seed=2)
    settings = ssrlab.Settings(width=GW, height=GH, composite="pbr")
    fa, ta = cc.ssrlab_reference(renderer, scene, settings, rays=GLOSSY_SPP, seed=0)
    a = ta.color.copy()
    _, tb = cc.ssrlab_reference(renderer, scene, settings, rays=GLOSSY_SPP, seed=1)
    b = tb.color.copy()
    floor = cc.floor_pixels(fa)
    assert floor.sum() > 1500
    agree = cc.noise_agreement(a, b, m1, m2, floor)
    print(f"glossy floor {roughness}, Mitsuba's roughconductor: {cc.floor_psnr(a, m1, floor):.2f} dB "
          f"(Mitsuba's two seeds {cc.floor_psnr(m1, m2, floor):.2f} dB); mean "
          f"{100 * agree['mean_relative']:+.2f} % ± {100 * agree['se_mean_relative']:.2f} % (z {agree['z_mean']:.2f}); "
          f"squared bias z {agree['z_bias2']:.2f}; MSE / noise {agree['mse_over_noise']:.3f}")
    assert agree["noise"] > 0
    assert abs(agree["z_mean"]) <= NOISE_Z and agree["z_bias2"] <= NOISE_Z, agree


def test_glossy_floor_within_noise(renderer, mitsuba):
    """The port of ssrlab's BRDF (bsdf="ssrlab") on the floor too: roughness 0.2, 32 samples per
    pixel in both. Independent noise makes the mean squared
    difference the sum of the two images' noise variances (each half the MSE between two seeds)
    plus the squared bias: the ratio is 1 for unbiased images and is allowed 1.25 (at ~1400
    pixels x 3 channels its sampling spread is a few percent; it measures 1.03). The mean floor
    radiance must agree within 1 % plus 4 standard errors (it measures 0.995 +- 0.003): the 'pbr'
    composite without the GGX directional albedo was 1.4-5.8 % bright at roughness 0.2-0.3, a
    missing highlight or Fresnel factor is far more."""
    spp = 32
    scene = cc.crosscheck_scene(0.2)
    ms = cc.mitsuba_scene(scene, width=W, height=H, bsdf="ssrlab")
    assert ms.own_bsdf == {}
    m1 = cc.render_mitsuba(ms, spp=spp, seed=1)
    m2 = cc.render_mitsuba(ms, spp=spp, seed=2)
    settings, kwargs, _ = cc.exact_options(_settings(composite="pbr", **TINY_BIAS))
    fa, ta = cc.ssrlab_reference(renderer, scene, settings, rays=spp, seed=0, **kwargs)
    a = ta.color.copy()
    _, tb = cc.ssrlab_reference(renderer, scene, settings, rays=spp, seed=1, **kwargs)
    b = tb.color.copy()
    floor = cc.floor_pixels(fa)
    split = cc.noise_split(a, b, m1, m2, floor)
    ratio, err = cc.mean_ratio(a, b, m1, m2, floor)
    print(f"glossy floor: MSE / noise {split['ratio']:.3f}, mean ratio {ratio:.4f} ± {err:.4f}")
    assert split["noise_mitsuba"] > 0 and split["noise_ssrlab"] > 0
    assert split["ratio"] <= 1.25
    assert abs(ratio - 1.0) <= 0.01 + 4 * err


@pytest.mark.parametrize("case", ["masked", "emissive", "emissive_texture", "point_shadow", "vertex_colors"])
def test_mask_and_emission_cases(renderer, mitsuba, case):
    """glTF alphaMode MASK (a checkerboard alpha mask on a quad, Mitsuba's mask BSDF through
    volpath, so that holes pass light in its shadow rays too), emission (an area emitter in
    Mitsuba), an emissive texture (a checkerboard: the area emitter's bitmap radiance), a point
    light's shadows (traced to the casting point light) and vertex colours (the quad's
    "vertex_color" mesh attribute times the base colour in the BSDF) on a mirror floor: >= 40 dB on
    the floor pixels, default reference options."""
    scene = {"masked": cc.masked_crosscheck_scene, "emissive": cc.emissive_crosscheck_scene,
             "emissive_texture": cc.emissive_texture_crosscheck_scene,
             "point_shadow": cc.point_shadow_crosscheck_scene,
             "vertex_colors": cc.vertex_color_crosscheck_scene}[case]()
    ms = cc.mitsuba_scene(scene, width=W, height=H)
    # Beside an area emitter Mitsuba's light sampling picks the sun or the emitter per sample, so
    # at 1 spp the sun's highlight on the emitter's dielectric specular comes 0 or 2x (41 dB for the
    # emissive quad, where the highlight is wide); 16 samples average it.
    mit = cc.render_mitsuba(ms, spp=16 if case == "emissive_texture" else 1)
    frame, truth = cc.ssrlab_reference(renderer, scene, _settings())
    floor = cc.floor_pixels(frame) & ~cc.reflected_silhouettes(ms)
    assert floor.sum() > 600
    # The feature is in view: the mirror shows holes and cells, or the emission.
    if case == "masked":
        seen = cc.mirror_objects(ms)[floor]
        assert (seen == 1).sum() > 50 and (seen == 2).sum() > 50
    elif case == "vertex_colors":
        # The mirror shows the quad's red and its green corners.
        c = truth.color[floor]
        assert (c[:, 0] > 2 * c[:, 1]).sum() > 20 and (c[:, 1] > 2 * c[:, 0]).sum() > 20
    elif case == "emissive":
        assert (truth.color[floor].max(axis=-1) > 1.0).sum() > 50
    elif case == "emissive_texture":
        # Both kinds of cell in the mirror: bright (4 x 1.0) and dim (4 x 0.051) reflections.
        red = truth.color[floor][:, 0]
        assert (red > 3.0).sum() > 50 and ((red > 0.15) & (red < 0.3)).sum() > 50
    else:
        # The mirror shows the wall (object 1) both lit and in the objects' shadows.
        wall = floor & (cc.mirror_objects(ms) == 1)
        lum = truth.color[wall].mean(axis=-1)
        assert wall.sum() > 100 and (lum < 0.02 * np.median(lum)).sum() > 20 and (lum > 0.5 * np.median(lum)).sum() > 50
    value = cc.floor_psnr(truth.color, mit, floor)
    # (metrics.psnr reports 100 dB for images equal to float precision: the largest difference says more)
    print(f"{case}: {value:.1f} dB, largest difference {np.abs(truth.color[floor] - mit[floor]).max():.2e} "
          f"over {floor.sum()} floor pixels")
    assert value >= 40.0


def test_own_bsdf_only_where_exact():
    """Mitsuba's own BSDF stands in for ssrlab's model only where it computes the same: a metal
    whose F0 is 1 (Schlick's F then 1 at every angle, as the conductors' with material "none"),
    a mirror below roughness 0.01 and GGX from roughness 0.03 (ssrlab's punctual-light alpha floor)."""
    assert cc.own_bsdf((1, 1, 1), 1.0, 0.0)["type"] == "conductor"
    rough = cc.own_bsdf((1, 1, 1), 1.0, 0.5)
    assert rough["type"] == "roughconductor" and rough["distribution"] == "ggx" and rough["sample_visible"]
    assert rough["alpha"] == pytest.approx(0.25) and rough["material"] == "none"
    assert cc.own_bsdf((1, 1, 1), 1.0, 0.02) is None  # lights see alpha 0.03^2, rays 0.02^2
    assert cc.own_bsdf((0.95, 0.64, 0.54), 1.0, 0.0) is None  # Schlick's F with F0 < 1
    assert cc.own_bsdf((1, 1, 1), 0.0, 0.5) is None  # dielectric: Lambert under (1 - F), F0 0.04
    assert cc.own_bsdf((1, 1, 1), 1.0, 0.5, vertex_colors=True) is None


def test_incomparable_scenes_are_refused(mitsuba):
    scene = cc.crosscheck_scene(0.0)
    scene.ambient = (0.1, 0.1, 0.1)
    with pytest.raises(ValueError, match="ambient"):
        cc.mitsuba_scene(scene, width=W, height=H)
    scene = cc.crosscheck_scene(0.0)
    scene.environment = ssrlab.Environment.sky()
    with pytest.raises(ValueError, match="environment"):
        cc.mitsuba_scene(scene, width=W, height=H)
    scene = cc.emissive_crosscheck_scene()
    scene.add_box((2, 0.5, -3), (1, 1, 1), material=ssrlab.Material(base_color=(0.5, 0.5, 0.5)))
    with pytest.raises(ValueError, match="lit by the emissive"):
        cc.mitsuba_scene(scene, width=W, height=H)
    scene = cc.masked_crosscheck_scene()
    img = np.zeros((4, 4, 4), np.uint8)
    img[..., 3] = 128
    quad = scene.object_count - 1
    m = scene.material(quad)
    m.base_color_texture = scene.add_image(img)
    scene.set_material(quad, m)
    with pytest.raises(ValueError, match="alpha mask"):
        cc.mitsuba_scene(scene, width=W, height=H)
    with pytest.raises(ValueError, match="spp"):
        cc.render_mitsuba(cc.mitsuba_scene(cc.crosscheck_scene(0.0), width=8, height=8), spp=0)
    with pytest.raises(ValueError, match="bsdf"):
        cc.mitsuba_scene(cc.crosscheck_scene(0.0), width=8, height=8, bsdf="pbrt")


def test_harness_survives_repeated_loads(mitsuba, tmp_path):
    """Dr.Jit's thread pool aborted the process on CI in load_dict (mitsuba3#849). With its
    workers this loop aborted in 1 of 4 runs here (10 of 12 with ssrlab frames rendered between
    the loads); without them (crosscheck.JIT_THREADS) it completes. It runs in a child process,
    so that an abort fails this test, not the suite."""
    import subprocess
    import sys

    script = tmp_path / "loop.py"
    script.write_text(
        "import drjit as dr\n"
        "from ssrlab import crosscheck as cc\n"
        "cc.load_mitsuba()\n"
        "assert dr.thread_count() == cc.JIT_THREADS, dr.thread_count()\n"
        "scene = cc.crosscheck_scene(0.0)\n"
        "for _ in range(30):\n"
        "    cc.render_mitsuba(cc.mitsuba_scene(scene, width=8, height=8), spp=1)\n"
        "print('done')\n")
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0 and run.stdout.strip() == "done", run.stderr[-2000:]
