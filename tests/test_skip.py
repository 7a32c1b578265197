"""The classify pass and the trace over its ray list (Settings.skip), Frame.stats."""

import math

import numpy as np
import pytest

import ssrlab
from ssrlab.metrics import thesis_error
from ssrlab.scene import Camera, Environment, Material, Scene, directional_light
from conftest import small as _small

W, H = 64, 48


def small(**kw) -> ssrlab.Settings:
    """These tests are about the classify pass and its counters: skip on unless a test says
    otherwise, on every device (skip='auto' turns it off on a GPU)."""
    kw.setdefault("skip", True)
    return _small(**kw)


def test_skip_auto_is_on_for_llvmpipe_and_off_for_a_gpu(renderer):
    s = ssrlab.Settings()
    assert s.skip == "auto"
    assert s.resolved("cpu").skip is True and s.resolved("gpu").skip is False
    assert ssrlab.Settings(skip=False).resolved("cpu").skip is False  # only 'auto' is decided
    assert s.to_native("gpu").skip is False and s.to_native("cpu").skip is True
    f = renderer.render(ssrlab.scenes.load("mirror_test"), settings=_small())
    assert f.settings.skip is (renderer.info["device"] == "cpu")  # the value the frame ran with
    assert ("classify" in f.passes) is f.settings.skip


@pytest.mark.parametrize("value", ["on", 1, None, "Auto"])
def test_skip_rejects_anything_but_true_false_or_auto(value):
    with pytest.raises(ValueError, match="Settings.skip must be True, False or one of 'auto'"):
        ssrlab.Settings(skip=value)
    with pytest.raises(ValueError, match="device must be 'cpu' or 'gpu'"):
        ssrlab.Settings().resolved("tpu")

CASES = [  # (glossy, sampling, layers, method, rays)
    ("stochastic", "mirror", 1, "linear", 1),
    ("stochastic", "vndf", 4, "hiz", 2),
    ("stochastic", "mirror", 4, "hiz", 1),
    ("stochastic", "vndf", 1, "linear", 2),
]


def _reflective_regions(gbuffer, region=32):
    """The classify pass's 32x32 regions where layer 0 holds a reflective surface, as a mask over
    pixels, and their count (the peeling may flag more: an overdrawn reflective fragment)."""
    reflective = gbuffer.reflectivity[0][::-1] > 0  # regions count from OpenGL's bottom row
    h, w = reflective.shape
    flags = np.zeros((-(-h // region), -(-w // region)), bool)
    ys, xs = np.nonzero(reflective)
    flags[ys // region, xs // region] = True
    mask = np.kron(flags, np.ones((region, region), bool))[:h, :w]
    return mask[::-1], int(flags.sum())


def _pair(renderer, scene, **kw):
    frames = [renderer.render(scene, settings=small(width=W, height=H, skip=skip, **kw)) for skip in (True, False)]
    return frames


@pytest.mark.parametrize("scene_name", list(ssrlab.scenes.SCENES))
@pytest.mark.parametrize("glossy,sampling,layers,method,rays", CASES)
def test_skip_on_and_off_agree(renderer, scene_name, glossy, sampling, layers, method, rays):
    scene = ssrlab.scenes.load(scene_name)
    on, off = _pair(renderer, scene, glossy=glossy, sampling=sampling, layers=layers, method=method,
                    rays_per_pixel=rays, roughness_cutoff=0.6)
    assert "classify" in on.passes and "classify" not in off.passes
    assert thesis_error(on.color, off.color) <= 1e-3
    assert thesis_error(on.reflection, off.reflection) <= 1e-3
    # Every ray texture is written for every pixel: the untraced ones hold the same "no ray".
    for name in ("rays.hit", "rays.direction", "lit", "linear_depth"):
        np.testing.assert_array_equal(on.read(name), off.read(name), err_msg=name)
    # rays.sample: the same weight, pdf and traced flag; the depth fetches (z) only fewer, as the
    # walk no longer fetches a layer empty everywhere (layers_used).
    s_on, s_off = on.read("rays.sample"), off.read("rays.sample")
    np.testing.assert_array_equal(s_on[..., [0, 1, 3]], s_off[..., [0, 1, 3]])
    assert (s_on[..., 2] <= s_off[..., 2]).all()
    # The list holds exactly the reflective pixels below the cutoff that face the camera.
    g = off.gbuffer
    listed = g.coverage[0] & (g.reflectivity[0] > 0) & (g.roughness[0] <= 0.6)
    sample = off.read("rays.sample")
    traced_rays = int((sample[..., 0] > 0).sum())  # rays the full-screen trace generated
    # Classify examines the 32x32 regions where the peeling drew a reflective surface.
    examined, _ = _reflective_regions(g)
    assert int(examined.sum()) <= on.stats["pixels_classified"] <= W * H
    assert on.stats["rays_traced"] == traced_rays
    assert on.stats["pixels_traced"] <= int(listed.sum())
    assert on.stats["trace_groups"] == math.ceil(on.stats["pixels_traced"] / 64) * rays


@pytest.mark.parametrize("glossy", ["cone", "blur_mips"])
def test_skip_agrees_for_one_ray_glossy_methods(renderer, glossy):
    scene = ssrlab.scenes.load("spheres_and_boxes")
    on, off = _pair(renderer, scene, glossy=glossy, layers=2, method="hiz")
    assert thesis_error(on.color, off.color) <= 1e-3


@pytest.mark.parametrize("downscale", [2, 4])
def test_skip_agrees_at_reduced_trace_resolution(renderer, downscale):
    scene = ssrlab.scenes.load("hall")
    on, off = _pair(renderer, scene, downscale=downscale, rays_per_pixel=2, layers=2, reuse_radius=1)
    assert 0 < on.stats["pixels_classified"] <= math.ceil(W / downscale) * math.ceil(H / downscale)
    assert thesis_error(on.color, off.color) <= 1e-3
    np.testing.assert_array_equal(on.read("rays.hit"), off.read("rays.hit"))


def _quad_scene(half_w: float, half_h: float, roughness: float = 0.0) -> Scene:
    """A mirror quad facing a camera that looks straight at it from 5 units, before a matte wall."""
    s = Scene()
    s.name = "quad"

    def quad(z, hw, hh, name, material):
        p = np.float32([(-hw, -hh, z), (hw, -hh, z), (hw, hh, z), (-hw, hh, z)])
        s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name=name, normals=np.tile(np.float32([0, 0, 1]), (4, 1)),
                   material=material)

    quad(0.0, half_w, half_h, "mirror", Material(base_color=(1, 1, 1), roughness=roughness, metallic=1.0,
                                                 reflectivity=1.0))
    quad(-3.0, 50.0, 50.0, "wall", Material(base_color=(0.6, 0.5, 0.4), roughness=0.9))
    s.add_light(directional_light((0.2, -0.4, -1.0), intensity=2.0, cast_shadow=False))
    s.environment = Environment.constant((0.1, 0.1, 0.1))
    s.camera = Camera(position=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), fov_y=60.0, near=0.1, far=50.0)
    return s


def _expected_pixels(half_w, half_h, fov_y=60.0, dist=5.0):
    """Pixel centres whose camera ray meets the quad |x| < half_w, |y| < half_h at distance dist."""
    t = math.tan(math.radians(fov_y) / 2)
    xs = ((np.arange(W) + 0.5) / W * 2 - 1) * t * W / H * dist
    ys = ((np.arange(H) + 0.5) / H * 2 - 1) * t * dist
    return int((np.abs(xs) < half_w).sum() * (np.abs(ys) < half_h).sum())


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_a_known_number_of_reflective_pixels_traces_exactly_that_many(renderer, method):
    # Edges half-way between pixel centres (the pixel pitch at 5 units is 2 t 5 / H).
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    hw, hh = 9 * pitch, 5 * pitch  # 18 x 10 pixels
    expected = _expected_pixels(hw, hh)
    assert expected == 18 * 10
    f = renderer.render(_quad_scene(hw, hh), settings=small(width=W, height=H, method=method, rays_per_pixel=3,
                                                             sampling="vndf"))
    g = f.gbuffer
    assert int((g.reflectivity[0] > 0).sum()) == expected
    # Classify runs over the 32x32 regions holding the quad only, every pixel of them examined.
    examined, regions = _reflective_regions(g)
    assert f.stats["classify_regions"] == regions
    assert f.stats["pixels_classified"] == int(examined.sum()) < W * H
    assert f.stats["pixels_traced"] == expected
    assert f.stats["rays_traced"] == 3 * expected
    assert f.stats["trace_groups"] == math.ceil(expected / 64) * 3
    assert f.stats["depth_fetches"] > 0
    # Exactly the listed pixels carry traced rays.
    traced = f.read("rays.sample")[..., 0] > 0
    assert traced.sum() == 3 * expected


def test_an_empty_list_dispatches_no_trace_group(renderer):
    # The only reflective surface is rougher than the cutoff: nothing is listed, nothing traced.
    f = renderer.render(_quad_scene(1.0, 1.0, roughness=0.8),
                        settings=small(width=W, height=H, roughness_cutoff=0.5))
    assert f.stats["pixels_traced"] == 0
    assert f.stats["trace_groups"] == 0
    assert f.stats["rays_traced"] == 0
    assert not (f.read("rays.sample")[..., 0] > 0).any()
    off = renderer.render(_quad_scene(1.0, 1.0, roughness=0.8),
                          settings=small(width=W, height=H, roughness_cutoff=0.5, skip=False))
    assert thesis_error(f.color, off.color) <= 1e-3


def test_facing_threshold_drops_grazing_pixels(renderer):
    scene = ssrlab.scenes.load("mirror_test")
    base = renderer.render(scene, settings=small(width=W, height=H, sampling="mirror"))
    strict = renderer.render(scene, settings=small(width=W, height=H, sampling="mirror", classify_facing=0.9))
    assert 0 <= strict.stats["pixels_traced"] < base.stats["pixels_traced"]
    with pytest.raises(ValueError, match="classify_facing"):
        small(classify_facing=1.5)


def test_stats_count_passes_without_skip(renderer):
    f = renderer.render(ssrlab.scenes.load("mirror_test"), settings=small(width=W, height=H, skip=False))
    sample = f.read("rays.sample")
    unresolved = int(((f.read("rays.radiance")[..., 3] > -1.5) & (sample[..., 0] > 0)).sum())
    assert f.stats == {"passes_run": len(f.passes), "layers_used": 1, "layers_lit": 1,
                       "rays_traced": int((sample[..., 0] > 0).sum()), "depth_fetches": int(sample[..., 2].sum()),
                       # the specular_occlusion pass's counters (Settings.specular_occlusion, on by default)
                       "unresolved_rays": unresolved, "occluded_misses": f.stats["occluded_misses"]}
    assert f.stats["rays_traced"] > 0 and f.stats["depth_fetches"] > 0


@pytest.mark.parametrize("skip", [False, True])
def test_stats_are_counted_once_per_render(skip):
    """The first render of a variant runs its chain twice (an untimed first-use run, then the timed
    one: Frame.warmup_runs); a later render of it runs it once. Every count is the timed run's
    alone, those a pass keeps in a GPU buffer across runs included: the cold render's stats equal
    the warm render's, and unresolved_rays is the count of rays the specular_occlusion pass marked
    in rays.radiance."""
    r = ssrlab.Renderer("auto")  # its own renderer: nothing warmed yet
    scene = ssrlab.scenes.load("mirror_test")
    s = small(width=W, height=H, skip=skip)
    cold = r.render(scene, settings=s)
    warm = r.render(scene, settings=s)
    r.render(ssrlab.scenes.load("box_stack"), settings=s)  # another scene in between
    again = r.render(scene, settings=s)
    assert cold.warmup_runs >= 1 and warm.warmup_runs == 0 and again.warmup_runs == 0
    assert "specular_occlusion" in cold.passes and ("classify" in cold.passes) is skip
    for f in (cold, warm, again):
        marked = int(((f.read("rays.radiance")[..., 3] > -1.5) & (f.read("rays.sample")[..., 0] > 0)).sum())
        assert marked > 0 and f.stats["unresolved_rays"] == marked, (f.warmup_runs, f.stats["unresolved_rays"], marked)
        assert 0 <= f.stats["occluded_misses"] <= marked
    assert dict(cold.stats) == dict(warm.stats) == dict(again.stats)


def test_layers_used_is_the_depth_complexity_of_the_view(renderer):
    # Three parallel quads one behind the other (no back faces): depth complexity 3.
    s = _quad_scene(1.0, 1.0)
    p = np.float32([(-2, -2, -1.5), (2, -2, -1.5), (2, 2, -1.5), (-2, 2, -1.5)])
    s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name="middle", normals=np.tile(np.float32([0, 0, 1]), (4, 1)),
               material=Material(base_color=(0.2, 0.5, 0.2), roughness=0.7))
    f = renderer.render(s, settings=small(width=W, height=H, layers=16))
    assert f.stats["layers_used"] == 3
    assert f.layer_samples[2] > 0 and not any(f.layer_samples[3:])
    assert f.stats["layers_lit"] == 3  # the 13 empty layers are cleared, not shaded
    off = renderer.render(s, settings=small(width=W, height=H, layers=16, skip=False))
    assert off.stats["layers_lit"] == 16
    for name in ("lit", "linear_depth"):
        np.testing.assert_array_equal(f.read(name), off.read(name), err_msg=name)
    assert thesis_error(f.color, off.color) <= 1e-3


@pytest.mark.parametrize("skip", [True, False])
def test_adaptive_rays_trace_one_ray_per_mirror_pixel(renderer, skip):
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    hw, hh = 9 * pitch, 5 * pitch  # 18 x 10 mirror pixels
    kw = dict(width=W, height=H, rays_per_pixel=8, sampling="vndf", skip=skip)
    fixed = renderer.render(_quad_scene(hw, hh), settings=small(**kw))
    adaptive = renderer.render(_quad_scene(hw, hh), settings=small(adaptive_rays=True, **kw))
    per_pixel = (adaptive.read("rays.sample")[..., 0] > 0).sum(axis=0)
    assert per_pixel.max() == 1 and per_pixel.sum() == 180
    assert (fixed.read("rays.sample")[..., 0] > 0).sum() == 8 * 180
    if skip:
        assert adaptive.stats["rays_traced"] == 180 and fixed.stats["rays_traced"] == 8 * 180
    # A mirror's 8 rays all take the mirror direction: one ray gives the same reflection.
    assert thesis_error(adaptive.color, fixed.color) <= 1e-3


def test_adaptive_rays_follow_roughness(renderer):
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    f = renderer.render(_quad_scene(9 * pitch, 5 * pitch, roughness=0.3),
                        settings=small(width=W, height=H, rays_per_pixel=8, adaptive_rays=True))
    per_pixel = (f.read("rays.sample")[..., 0] > 0).sum(axis=0)
    # ceil(8 * 0.3) = 3 rays (a few VNDF samples may come out invalid, weight 0).
    assert per_pixel.max() == 3 and (per_pixel == 3).mean() > 0.9 * 180 / (W * H)
    assert f.stats["rays_traced"] == per_pixel.sum()
    # The list holds one entry per ray the pixel traces (3 per pixel, not 8 slots): the trace's
    # invocations follow the rays, and the textures are the full-screen trace's.
    assert f.stats["pixels_traced"] == 180
    assert f.stats["trace_groups"] == math.ceil(3 * 180 / 64)
    off = renderer.render(_quad_scene(9 * pitch, 5 * pitch, roughness=0.3),
                          settings=small(width=W, height=H, rays_per_pixel=8, adaptive_rays=True, skip=False))
    for name in ("rays.hit", "rays.sample", "rays.direction"):
        np.testing.assert_array_equal(f.read(name), off.read(name), err_msg=name)
    np.testing.assert_array_equal(f.color, off.color)


def test_a_list_longer_than_a_row_of_groups_is_traced_whole(renderer):
    # 320 x 240 mirror pixels: 1200 groups of 64, more than one row of 1024 (ray_list.glsl).
    kw = dict(width=320, height=240, sampling="mirror", rays_per_pixel=1)
    scene = _quad_scene(100.0, 100.0)
    on = renderer.render(scene, settings=small(**kw))
    off = renderer.render(scene, settings=small(skip=False, **kw))
    assert on.stats["pixels_traced"] == on.stats["rays_traced"] == 320 * 240
    assert on.stats["trace_groups"] == 1024 * 2
    np.testing.assert_array_equal(on.read("rays.sample"), off.read("rays.sample"))
    np.testing.assert_array_equal(on.read("rays.hit"), off.read("rays.hit"))
    # The resolve's list of receiving pixels (own rays: mirror) spans two rows of groups too.
    assert on.stats["resolve_pixels"] == 320 * 240
    assert on.stats["resolve_groups"] == 1024 * 2
    np.testing.assert_array_equal(on.reflection, off.reflection)


def _three_layer_scene(roughness: float = 0.0) -> Scene:
    """The mirror quad (over a wider middle quad, over the wall): depth complexity 3 in the centre."""
    s = _quad_scene(1.0, 1.0, roughness=roughness)
    p = np.float32([(-2, -2, -1.5), (2, -2, -1.5), (2, 2, -1.5), (-2, 2, -1.5)])
    s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name="middle", normals=np.tile(np.float32([0, 0, 1]), (4, 1)),
               material=Material(base_color=(0.2, 0.5, 0.2), roughness=0.7))
    return s


@pytest.mark.parametrize("glossy,method", [("cone", "linear"), ("stochastic", "hiz")])
def test_per_layer_passes_work_on_the_layers_used_only(renderer, glossy, method):
    # Depth complexity 3 with 16 layers allowed: the Hi-Z pyramid is built for 3 layers, the
    # pre-convolution and pre-integration (cone) work on 3, the trace walk fetches no 4th;
    # every texture reads as with skip off.
    s = _three_layer_scene(roughness=0.2)
    kw = dict(width=W, height=H, layers=16, glossy=glossy, method=method, sampling="vndf", rays_per_pixel=2,
              thickness=5.0)
    frames, hiz = [], []
    for skip in (True, False):
        f = renderer.render(s, settings=small(skip=skip, **kw))
        hiz.append(f.read("hiz"))  # per-renderer scratch: read before the next render
        frames.append(f)
    on, off = frames
    assert on.stats["layers_used"] == off.stats["layers_used"] == 3
    assert on.stats["hiz_layers_built"] == 3 and off.stats["hiz_layers_built"] == 16
    np.testing.assert_array_equal(hiz[0], hiz[1])
    names = ["lit", "linear_depth", "rays.hit", "rays.direction"]
    if glossy == "cone":
        names += ["lit_preconvolved", "visibility"]
    for name in names:
        np.testing.assert_array_equal(on.read(name), off.read(name), err_msg=name)
    fetch_on, fetch_off = on.read("rays.sample")[..., 2], off.read("rays.sample")[..., 2]
    assert (fetch_on <= fetch_off).all()
    assert on.stats["depth_fetches"] == int(fetch_on.sum())
    assert thesis_error(on.color, off.color) <= 1e-3


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_the_walk_fetches_no_layer_empty_everywhere(renderer, method):
    # spheres_and_boxes fills 6 of 16 layers: a ray behind all 6 where they are all covered
    # fetched the empty 7th to learn it was empty; with skip it stops at the 6th.
    scene = ssrlab.scenes.load("spheres_and_boxes")
    on, off = _pair(renderer, scene, layers=16, method=method, sampling="vndf", rays_per_pixel=2)
    assert on.stats["layers_used"] == 6
    fetch_on, fetch_off = on.read("rays.sample")[..., 2], off.read("rays.sample")[..., 2]
    assert (fetch_on <= fetch_off).all() and fetch_on.sum() < fetch_off.sum()
    assert on.stats["depth_fetches"] == int(fetch_on.sum())
    np.testing.assert_array_equal(on.read("rays.hit"), off.read("rays.hit"))


def test_a_camera_change_reuses_the_gpu_scene(renderer):
    s = ssrlab.scenes.load("mirror_test")
    before = renderer.stats["scene_uploads"]
    renderer.render(s, settings=small(width=W, height=H))
    assert renderer.stats["scene_uploads"] == before + 1
    cam = s.camera
    moved = Camera(position=tuple(np.add(cam.position, (0.3, 0.1, 0.0))), target=tuple(cam.target),
                   fov_y=cam.fov_y, near=cam.near, far=cam.far)
    renderer.render(s, camera=moved, settings=small(width=W, height=H))
    renderer.render(s, settings=small(width=W, height=H, layers=2, method="linear"))
    assert renderer.stats["scene_uploads"] == before + 1  # new camera, new settings: same content
    s.add_box(center=(0.0, 0.5, 0.0), size=(0.2, 0.2, 0.2))
    renderer.render(s, settings=small(width=W, height=H))
    assert renderer.stats["scene_uploads"] == before + 2  # changed content: uploaded again


def test_the_reference_bvh_is_built_once_per_scene_content(renderer):
    s = ssrlab.scenes.load("mirror_test")
    before = renderer.stats["bvh_builds"]
    f = renderer.render(s, settings=small(width=W, height=H))
    assert renderer.stats["bvh_builds"] == before  # a frame without a reference builds none
    f.reference(kind="converged", rays=2)
    cam = s.camera
    moved = Camera(position=tuple(np.add(cam.position, (0.2, 0.0, 0.0))), target=tuple(cam.target),
                   fov_y=cam.fov_y, near=cam.near, far=cam.far)
    g = renderer.render(s, camera=moved, settings=small(width=W, height=H))
    g.reference(kind="converged", rays=2)
    g.reference(kind="per_ray")
    assert renderer.stats["bvh_builds"] == before + 1
    s.add_box(center=(0.0, 0.5, 0.0), size=(0.2, 0.2, 0.2))
    renderer.render(s, settings=small(width=W, height=H)).reference(kind="converged", rays=1)
    assert renderer.stats["bvh_builds"] == before + 2


def test_nothing_is_read_back_that_nobody_asked_for(renderer):
    s = ssrlab.scenes.load("mirror_test")
    before = renderer.stats
    f = renderer.render(s, settings=small(width=W, height=H))
    _ = f.stats, f.timings, f.passes, f.layer_samples
    assert renderer.stats["readbacks"] == before["readbacks"]  # no image read yet
    _ = f.color
    _ = f.color  # cached: read once
    after = renderer.stats
    assert after["readbacks"] == before["readbacks"] + 1
    assert after["readback_bytes"] - before["readback_bytes"] == W * H * 4 * 4
    # The trace keeps no counters: its rays and fetches are summed from rays.sample
    # when one of them is first read, once.
    stats = f.stats
    assert "depth_fetches" in stats and "rays_traced" in stats
    assert renderer.stats["readbacks"] == after["readbacks"]
    assert stats["depth_fetches"] > 0 and f.stats["rays_traced"] > 0
    assert renderer.stats["readbacks"] == after["readbacks"] + 1


@pytest.mark.parametrize("skip", [True, False])
def test_trace_sums_are_read_before_release_or_refused_with_a_reason(renderer, skip):
    s = ssrlab.scenes.load("mirror_test")
    f = renderer.render(s, settings=small(width=W, height=H, skip=skip))
    kept = f.stats
    fetches = kept["depth_fetches"]
    sample = f.read("rays.sample")
    assert fetches == int(sample[..., 2].sum()) > 0
    assert kept["rays_traced"] == int((sample[..., 0] > 0).sum()) > 0
    f.release()
    assert f.stats["depth_fetches"] == fetches and kept["depth_fetches"] == fetches  # summed before
    g = renderer.render(s, settings=small(width=W, height=H, skip=skip))
    early = g.stats
    g.release()
    assert early["passes_run"] == len(g.passes)  # the GPU's own counters stay
    with pytest.raises(KeyError, match="before releasing the frame"):
        early["depth_fetches"]
    with pytest.raises(KeyError, match="before releasing the frame"):
        g.stats["rays_traced"]


@pytest.mark.parametrize("method", ["linear", "hiz"])
def test_variance_rays_at_threshold_zero_trace_every_ray_a_full_trace_would(renderer, method):
    # Threshold 0: every pixel with fewer rays than the maximum gets the rest, drawn exactly as
    # the full trace draws them, so the rays and the image are the full trace's.
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    scene = _quad_scene(9 * pitch, 5 * pitch, roughness=0.3)
    kw = dict(width=W, height=H, rays_per_pixel=8, sampling="vndf", method=method)
    full = renderer.render(scene, settings=small(**kw))
    adaptive = renderer.render(scene, settings=small(adaptive_rays=True, **kw))
    extra = renderer.render(scene, settings=small(adaptive_rays=True, variance_rays=True, variance_threshold=0.0, **kw))
    assert "variance_rays" in extra.passes and f"trace_{method}_extra" in extra.passes
    for name in ("rays.hit", "rays.sample", "rays.direction"):
        np.testing.assert_array_equal(extra.read(name), full.read(name), err_msg=name)
    np.testing.assert_array_equal(extra.color, full.color)
    n_full = int((full.read("rays.sample")[..., 0] > 0).sum())
    n_adaptive = int((adaptive.read("rays.sample")[..., 0] > 0).sum())
    assert extra.stats["rays_traced"] == n_adaptive
    assert extra.stats["extra_rays"] == n_full - n_adaptive > 0
    assert extra.stats["variance_pixels"] == 180  # every mirror-quad pixel (3 of 8 rays each)


def test_variance_rays_add_rays_only_where_the_neighbourhood_disagrees(renderer):
    scene = ssrlab.scenes.load("spheres_and_boxes")
    kw = dict(width=W, height=H, rays_per_pixel=8, sampling="vndf", adaptive_rays=True, roughness_cutoff=1.0)
    adaptive = renderer.render(scene, settings=small(**kw))
    f = renderer.render(scene, settings=small(variance_rays=True, variance_threshold=0.3, **kw))
    none = renderer.render(scene, settings=small(variance_rays=True, variance_threshold=1e3, **kw))
    # Nothing disagrees by 1000x its mean: no extra ray, the adaptive frame exactly.
    assert none.stats["variance_pixels"] == none.stats["extra_rays"] == 0
    np.testing.assert_array_equal(none.color, adaptive.color)
    # The listed pixels are exactly those at or above the threshold with fewer than 8 rays.
    var = f.read("variance")[0, :, :, 0]
    rough = f.gbuffer.roughness[0]
    count = np.clip(np.ceil(8 * rough), 1, 8)
    listed = (var >= 0.3) & (count < 8)
    assert 0 < f.stats["variance_pixels"] == int(listed.sum()) < int((var >= 0).sum())
    per_pixel = (f.read("rays.sample")[..., 0] > 0).sum(axis=0)
    per_pixel_adaptive = (adaptive.read("rays.sample")[..., 0] > 0).sum(axis=0)
    assert (per_pixel[~listed] == per_pixel_adaptive[~listed]).all()
    assert (per_pixel[listed] >= per_pixel_adaptive[listed]).all()
    assert f.stats["extra_rays"] == int(per_pixel.sum() - per_pixel_adaptive.sum()) > 0
    # Skip off (full-screen first trace) lists the same pixels and makes the same image.
    off = renderer.render(scene, settings=small(variance_rays=True, variance_threshold=0.3, skip=False, **kw))
    assert off.stats["variance_pixels"] == f.stats["variance_pixels"]
    assert off.stats["extra_rays"] == f.stats["extra_rays"]
    assert thesis_error(off.color, f.color) <= 1e-3


def test_variance_rays_need_adaptive_rays():
    with pytest.raises(ValueError, match="variance_rays"):
        small(variance_rays=True)
    with pytest.raises(ValueError, match="variance_threshold"):
        small(variance_threshold=-1.0)


@pytest.mark.parametrize("scene_name", list(ssrlab.scenes.SCENES))
def test_skip_agrees_with_adaptive_and_variance_rays(renderer, scene_name):
    scene = ssrlab.scenes.load(scene_name)
    on, off = _pair(renderer, scene, sampling="vndf", rays_per_pixel=4, layers=2, method="hiz", roughness_cutoff=1.0,
                    adaptive_rays=True, variance_rays=True, variance_threshold=0.2)
    for name in ("rays.hit", "rays.direction", "variance"):
        np.testing.assert_array_equal(on.read(name), off.read(name), err_msg=name)
    assert on.stats["extra_rays"] == off.stats["extra_rays"]
    assert on.stats["rays_traced"] == int((on.read("rays.sample")[..., 0] > 0).sum()) - on.stats["extra_rays"]
    assert thesis_error(on.color, off.color) <= 1e-3


# The resolve over the classify pass's resolve list: the receiving pixels (own rays:
# mirror rays with BRDF weights, or reuse radius 0, at full resolution) or the 16x16 tiles
# holding one; the classify pass writes the other pixels' reflection (0, or the environment
# where a reflective surface is rougher than the cutoff).
def _mirror_and_rough_scene(with_mirror: bool = True) -> Scene:
    """The 18 x 10 pixel mirror quad of _quad_scene, and a rough reflective quad beside it."""
    pitch = 2 * math.tan(math.radians(30)) * 5 / H
    s = _quad_scene(9 * pitch, 5 * pitch)
    if not with_mirror:
        s = _quad_scene(0.0, 0.0)
    p = np.float32([(1.6, -1.0, 0.2), (2.4, -1.0, 0.2), (2.4, 1.2, 0.2), (1.6, 1.2, 0.2)])
    s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name="rough", normals=np.tile(np.float32([0, 0, 1]), (4, 1)),
               material=Material(base_color=(1, 1, 1), roughness=0.8, metallic=1.0, reflectivity=1.0))
    return s


def _tiles_holding(mask: np.ndarray) -> int:
    h, w = mask.shape
    t = np.zeros(((h + 15) // 16, (w + 15) // 16), bool)
    ys, xs = np.nonzero(mask)
    t[ys // 16, xs // 16] = True
    return int(t.sum())


@pytest.mark.parametrize("sampling,rays,radius,downscale,own", [
    ("mirror", 1, 1, 1, True),    # mirror rays with BRDF weights: own rays
    ("vndf", 2, 0, 1, True),      # reuse radius 0: own rays
    ("vndf", 2, 1, 1, False),     # neighbour reuse: tiles
    ("mirror", 1, 1, 2, False),   # half-resolution rays: tiles
])
def test_the_resolve_runs_over_the_receivers_only(renderer, sampling, rays, radius, downscale, own):
    assert W % 16 == 0 and H % 16 == 0  # the tiles are the same counted from the top or the bottom
    scene = _mirror_and_rough_scene()
    kw = dict(sampling=sampling, rays_per_pixel=rays, reuse_radius=radius, downscale=downscale, roughness_cutoff=0.5)
    on, off = _pair(renderer, scene, **kw)
    g = off.gbuffer
    reflective = g.coverage[0] & (g.reflectivity[0] > 0)
    receivers = reflective & (g.roughness[0] <= 0.5)
    rough = reflective & (g.roughness[0] > 0.5)
    assert int(receivers.sum()) == 18 * 10 and int(rough.sum()) > 0
    assert on.stats["environment_pixels"] == int(rough.sum())
    if own:
        assert on.stats["resolve_pixels"] == 18 * 10
        assert on.stats["resolve_groups"] == math.ceil(18 * 10 / 64)
        assert "resolve_tiles" not in on.stats
    else:
        assert on.stats["resolve_tiles"] == _tiles_holding(receivers) == 2
        assert on.stats["resolve_groups"] == 2
        assert "resolve_pixels" not in on.stats
    assert "resolve_pixels" not in off.stats and "resolve_tiles" not in off.stats
    # The same reflection everywhere: receivers resolved, rough pixels the environment, the rest 0.
    np.testing.assert_array_equal(on.reflection, off.reflection)
    np.testing.assert_array_equal(on.color, off.color)
    assert (on.reflection[rough] > 0).all()
    assert not on.reflection[~reflective].any()


@pytest.mark.parametrize("sampling", ["mirror", "vndf"])
def test_an_empty_resolve_list_dispatches_no_group(renderer, sampling):
    # Only the rough quad reflects: nothing receives rays, the resolve runs no group.
    on, off = _pair(renderer, _mirror_and_rough_scene(with_mirror=False), sampling=sampling, roughness_cutoff=0.5)
    assert "resolve" in on.passes
    assert on.stats["resolve_groups"] == 0
    assert on.stats.get("resolve_pixels", 0) == on.stats.get("resolve_tiles", 0) == 0
    g = off.gbuffer
    rough = g.coverage[0] & (g.reflectivity[0] > 0)
    assert on.stats["environment_pixels"] == int(rough.sum()) > 0
    np.testing.assert_array_equal(on.reflection, off.reflection)


@pytest.mark.parametrize("skip", [True, False])
def test_no_ray_is_all_zeros(renderer, skip):
    # A pixel that traces no ray (here: not reflective) holds zeros in every ray texture, with
    # skip (the classify pass's clear) and without (the full-screen trace writes them).
    f = renderer.render(_mirror_and_rough_scene(), settings=small(width=W, height=H, skip=skip, sampling="vndf",
                                                                   rays_per_pixel=2, roughness_cutoff=0.5))
    traced = f.read("rays.sample")[0, ..., 3] > 0.5
    assert int(traced.sum()) == 18 * 10
    for name in ("rays.hit", "rays.sample", "rays.direction"):
        assert not f.read(name)[:, ~traced].any(), name
    d = f.read("rays.direction")[:, traced, :3]
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0, atol=1e-5)
