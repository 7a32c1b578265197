"""Temporal passes that know what moved: the reproject pass follows gbuffer.motion (camera-only motion
lands where the camera's matrices put it; a moved object's surface where its transforms put it), the
layers tell a disocclusion from a surface that was not there (reject_layers), the reflection is
reprojected by the motion of what it reflects (reflection_reprojection="hit": the hit's previous
position mirrored in the mirror, computed here from the transforms), the resolve's ray reuse leaves
out rays whose hit moved; and, on small moving-object sequences (ssrlab.lab.temporal), hit-point
reprojection ghosts less than surface-only reprojection and the accumulation after N frames beats
the single frame with the same rays. Expectations come from the transforms and the G-buffers, in
numpy, not from the passes under test."""

from __future__ import annotations

import numpy as np
import pytest

import ssrlab
from conftest import small
from test_motion_vectors import moving_scene
from ssrlab import transforms as T
from ssrlab.lab import temporal

W, H = 96, 64


def world_points(frame, layer: int, rows, cols) -> np.ndarray:
    """World positions of layer `layer`'s samples at (rows, cols), from the stored depth."""
    s = frame.settings
    inv_proj = np.linalg.inv(frame.projection_matrix.astype(np.float64))
    inv_view = np.linalg.inv(frame.view_matrix.astype(np.float64))
    ndc = np.stack([(cols + 0.5) / s.width * 2 - 1, 1 - (rows + 0.5) / s.height * 2], -1)
    ray = np.c_[ndc, np.ones(len(ndc)), np.ones(len(ndc))] @ inv_proj.T
    ray = ray[:, :3] / ray[:, 3:4]
    ray = ray / -ray[:, 2:3]
    p = ray * frame.gbuffer.depth[layer, rows, cols][:, None].astype(np.float64)
    return (np.c_[p, np.ones(len(p))] @ inv_view.T)[:, :3]


def pixels_of(frame, world) -> np.ndarray:
    """(col, row) pixel positions (row 0 at the top, centres at .5) of world points in `frame`."""
    s = frame.settings
    clip = np.c_[world, np.ones(len(world))] @ (frame.projection_matrix.astype(np.float64) @
                                                frame.view_matrix.astype(np.float64)).T
    ndc = clip[:, :2] / clip[:, 3:4]
    return np.stack([(ndc[:, 0] * 0.5 + 0.5) * s.width, (0.5 - ndc[:, 1] * 0.5) * s.height], -1)


def two_frames(renderer, scene, cameras, settings, move=None):
    """The two frames of a sequence; `move(scene)` runs between them."""
    out = []
    for f in renderer.render_sequence(scene, cameras, settings):
        out.append(f)
        if len(out) == 1 and move is not None:
            move(scene)
    return out


CAMERA = ssrlab.Camera(position=(0.0, 2.5, 6.0), target=(0, 0.5, 0), fov_y=50, near=0.2, far=40)


def test_camera_motion_reprojects_where_the_camera_matrices_put_each_point(renderer):
    """A still scene under a moving camera: the reproject pass now reads gbuffer.motion, and every
    kept pixel's previous position is the camera reprojection of its point (the matrices' answer,
    which the pass gave before it read motion vectors), within 1e-3 px."""
    scene = ssrlab.scenes.spheres_and_boxes(seed=1, count=6)
    cams = [scene.camera, ssrlab.Camera(position=(0.4, 3.1, 7.3), target=(0.1, 0.7, -2.5), fov_y=55.0, near=0.1,
                                        far=60.0)]
    first, second = two_frames(renderer, scene, cams, small(width=W, height=H, temporal_reflections=True))
    rp = second.reprojection
    rows, cols = np.nonzero(second.gbuffer.coverage[0] & rp.valid)
    assert len(rows) > 0.5 * W * H
    want = pixels_of(first, world_points(second, 0, rows, cols))
    err = np.abs(rp.pixel[rows, cols] - want).max(-1)
    assert err.max() <= 1e-3, f"worst {err.max():.2e} px"


def interior(mask: np.ndarray) -> np.ndarray:
    """Pixels of `mask` whose 3x3 neighbourhood is all in it."""
    out = mask.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            out &= np.roll(np.roll(mask, dy, 0), dx, 1)
    return out


def test_a_moved_surface_keeps_its_history_and_the_layers_tell_what_it_uncovered(renderer):
    """A fixed camera, the ball slides and turns about a tilted axis through its centre: its own
    pixels reproject to where its transforms put them (within 0.01 px) and keep their history
    (their normals turned with it); the floor it uncovered, which the previous frame's layer 0
    showed as the ball, is rejected: as DISOCCLUDED with reject_layers where a deeper previous
    layer held the floor there (the same pixel: the floor stood still), as DEPTH without."""
    scene, ids = moving_scene()
    before = np.asarray(scene.object_transform(ids["ball"]), np.float64)
    centre = before[:3, 3]
    after = (T.translate(tuple(centre + (0.5, 0.0, 0.25))) @ T.rotate((0.3, 1.0, 0.2), 30.0) @
             T.translate(tuple(-centre)) @ before)
    results = {}
    for layers_rule in (False, True):
        scene, ids = moving_scene()
        s = small(width=W, height=H, layers=3, temporal_reflections=True, reject_layers=layers_rule)
        first, second = two_frames(renderer, scene, [CAMERA, CAMERA], s,
                                   move=lambda sc: sc.set_object_transform(ids["ball"], after))
        results[layers_rule] = (first, second)
        g = second.gbuffer
        ball = interior(g.coverage[0] & (g.object_id[0] == ids["ball"]))
        rows, cols = np.nonzero(ball)
        assert len(rows) > 40
        world = world_points(second, 0, rows, cols)
        local = np.c_[world, np.ones(len(world))] @ np.linalg.inv(after).T
        want = pixels_of(first, (local @ before.T)[:, :3])
        rp = second.reprojection
        valid = rp.valid[rows, cols]
        assert valid.mean() >= 0.9, np.bincount(rp.reason[rows, cols])
        if not layers_rule:  # positions are the motion's (reject_layers may snap an edge texel's)
            assert np.abs(rp.pixel[rows, cols][valid] - want[valid]).max() <= 0.01
    # The uncovered floor: pixels whose 3x3 neighbourhood the previous layer 0 showed as the ball.
    first, second = results[True]
    prev_ids = first.gbuffer.object_id
    uncovered = interior(prev_ids[0] == ids["ball"]) & (second.gbuffer.object_id[0] == ids["floor"])
    assert uncovered.sum() > 20
    floor_behind = ((prev_ids[1:] == ids["floor"]) & first.gbuffer.coverage[1:]).any(axis=0)
    reason = second.reprojection.reason
    expect = np.where(floor_behind, ssrlab.Reprojection.DISOCCLUDED, ssrlab.Reprojection.DEPTH)
    assert floor_behind[uncovered].mean() > 0.5
    assert (reason[uncovered] == expect[uncovered]).mean() >= 0.95
    assert (results[False][1].reprojection.reason[uncovered] == ssrlab.Reprojection.DEPTH).mean() >= 0.95


def mirror_scene():
    s = ssrlab.Scene()
    s.add_plane((0, 0, -2), (16, 16), name="mirror", material=ssrlab.Material(
        base_color=(1, 1, 1), roughness=0.0, metallic=1.0, reflectivity=1.0))
    s.add_box((0, 1.5, -7.0), (10, 3, 0.2), name="wall", material=ssrlab.Material(base_color=(0.7, 0.7, 0.65),
                                                                                   roughness=0.8, reflectivity=0.0))
    ball = s.add_sphere((-0.4, 0.7, -3.0), 0.6, segments=32, name="ball", material=ssrlab.Material(
        base_color=(0.9, 0.4, 0.1), roughness=0.5, reflectivity=0.0))
    s.add_light(ssrlab.directional_light((0.3, -1.0, -0.4), intensity=3.0))
    s.camera = ssrlab.Camera(position=(0.0, 2.2, 4.0), target=(0.0, 0.4, -3.0), fov_y=50, near=0.1, far=50)
    return s, ball


def test_hit_reprojection_follows_the_reflected_object(renderer):
    """A ball slides over a mirror under a fixed camera. Where the mirror reflects the ball, the
    reflection was where the ball's mirror image was: the virtual point along the view ray at the hit
    distance, moved by the mirror image of the ball's motion, projected by the previous camera
    (computed here from the rays' hits and the ball's translation) within 0.02 px; the surface's own
    reprojection stays on the pixel."""
    scene, ball = mirror_scene()
    shift = np.array([0.35, 0.0, 0.1])
    s = small(width=W, height=H, layers=2, sampling="mirror", temporal_reflections=True,
              reflection_reprojection="hit")
    first, second = two_frames(renderer, scene, [scene.camera] * 2, s,
                               move=lambda sc: sc.set_object_transform(ball, T.translate(tuple(shift)) @
                                                                       sc.object_transform(ball)))
    rays = second.rays
    layer = rays.hit_layer[0]
    hit = (layer > 0) & (rays.fade[0] >= 0.5)
    hp = np.floor(rays.hit_pixel[0]).astype(int)
    g = second.gbuffer
    hit_ids = g.object_id[np.clip(layer - 1, 0, 1), hp[..., 1].clip(0, H - 1), hp[..., 0].clip(0, W - 1)]
    rows, cols = np.nonzero(hit & (hit_ids == ball) & (g.object_id[0] == 0))
    assert len(rows) > 40
    # The hit points (their layer's depth at the hit pixel, through the pixel position the trace stored).
    hx, hy = rays.hit_pixel[0][rows, cols].T
    inv_proj = np.linalg.inv(second.projection_matrix.astype(np.float64))
    inv_view = np.linalg.inv(second.view_matrix.astype(np.float64))
    ndc = np.stack([hx / W * 2 - 1, 1 - hy / H * 2], -1)
    ray = np.c_[ndc, np.ones(len(ndc)), np.ones(len(ndc))] @ inv_proj.T
    ray = ray[:, :3] / ray[:, 3:4]
    ray = ray / -ray[:, 2:3]
    depth = g.depth[layer[rows, cols] - 1, hy.astype(int).clip(0, H - 1), hx.astype(int).clip(0, W - 1)]
    h = (np.c_[ray * depth[:, None].astype(np.float64), np.ones(len(ray))] @ inv_view.T)[:, :3]
    p = world_points(second, 0, rows, cols)
    eye = np.asarray(scene.camera.position, np.float64)
    view = (p - eye) / np.linalg.norm(p - eye, axis=1, keepdims=True)
    virtual = p + view * np.linalg.norm(h - p, axis=1, keepdims=True)
    mirrored = shift * np.array([1.0, -1.0, 1.0])  # the mirror image (plane y = 0) of the motion
    want = pixels_of(first, virtual - mirrored)
    rr = second.reflection_reprojection
    valid = rr.valid[rows, cols]
    assert valid.mean() >= 0.8
    got = rr.pixel[rows, cols][valid]
    err = np.abs(got - want[valid]).max(-1)
    # Exact, or where part of the footprint reflected something else, the nearest texel that did not.
    snapped = (np.abs(got - np.floor(got) - 0.5).max(-1) < 1e-4) & (err < 1.0)
    assert (err <= 0.02).mean() >= 0.7 and ((err <= 0.02) | snapped).all(), f"worst {err[~snapped].max():.4f} px"
    moved = np.abs(rr.pixel[rows, cols] - second.reprojection.pixel[rows, cols]).max(-1)[valid]
    assert np.median(moved) > 1.0  # the ball moved by pixels; the surface reprojection did not follow


def test_ray_reuse_leaves_out_rays_whose_hit_moved(renderer):
    """temporal_ray_reuse on a mirror (each pixel reuses its own previous ray): where the mirror
    reflected the ball before and no longer does, the previous ray went to where the ball was: it is
    left out, and the reflection is this frame's alone."""
    base = small(width=W, height=H, layers=2, sampling="mirror")
    out = {}
    for reuse in (False, True):
        scene, ball = mirror_scene()
        out[reuse] = two_frames(renderer, scene, [scene.camera] * 2, base.replace(temporal_ray_reuse=reuse),
                                move=lambda sc: sc.set_object_transform(ball, T.translate((0.8, 0.0, 0.0)) @
                                                                        sc.object_transform(ball)))
    first, second = out[True]
    shows = [temporal.reflects_objects(f, [ball]) for f in (first, second)]
    left = shows[0] & ~shows[1]
    assert left.sum() > 30
    a, b = second.reflection[left], out[False][1].reflection[left]
    assert np.abs(a - b).max() <= 1e-3
    # Where the same static surface is reflected in both frames, the previous ray counts: the
    # reflection is the mean of two identical mirror rays' (the same value, so the reuse is seen
    # through the resolve's timings only); its pass ran with history.
    assert "resolve" in second.passes and second.reprojection.valid.mean() > 0.5


@pytest.mark.parametrize("settings, motion", [
    (dict(temporal_reflections=True), True),
    (dict(taa="clamped"), True),
    (dict(denoise="svgf"), True),
    (dict(temporal_ray_reuse=True), True),
    (dict(bounces="history"), True),
    (dict(taa="thesis"), False),
    (dict(), False),
])
def test_the_deep_gbuffer_writes_motion_for_what_reprojects(renderer, settings, motion):
    """gbuffer.motion is written whenever a temporal technique reprojects (it reads it), and only
    then (or with Settings.motion_vectors): the thesis's TAA blends at the same pixel."""
    f = renderer.render(ssrlab.scenes.load("hall"), settings=small(width=48, height=32, **settings))
    assert ("gbuffer.motion" in f.texture_names) == motion
    assert ("reprojection" in f.texture_names) == motion


def test_hit_reprojection_runs_its_pass_for_the_reflection_only(renderer):
    scene = ssrlab.scenes.load("spheres_and_boxes")
    for s in (dict(temporal_reflections=True), dict(denoise="svgf")):
        f = renderer.render(scene, settings=small(width=48, height=32, reflection_reprojection="hit", **s))
        passes = f.passes
        # After the trace whose hits it moves, before the accumulation that reads it.
        assert passes.index("trace_linear") < passes.index("reproject_reflection")
        assert passes.index("reproject_reflection") < passes.index("temporal" if "temporal_reflections" in s else
                                                                   "svgf_temporal")
        assert f.reflection_reprojection.reason.max() == ssrlab.Reprojection.NO_HISTORY
    f = renderer.render(scene, settings=small(width=48, height=32, reflection_reprojection="hit", taa="clamped"))
    assert "reproject_reflection" not in f.passes
    with pytest.raises(ValueError, match="reflection_reprojection"):
        f.reflection_reprojection


@pytest.fixture(scope="module")
def sphere_study(renderer):
    """The sphere over the mirror, 8 frames (the sphere moves over 6), 96x54, still camera."""
    seq = temporal.sphere_over_mirror(frames=8, moving=6)
    base = ssrlab.Settings(width=96, height=54, layers=4, rays_per_pixel=1, shadow_map_size=512)
    cfg = {k: v for k, v in temporal.motion_configurations(base).items() if k in ("single frame", "surface", "hit")}
    return temporal.motion_study(renderer, seq, cfg, reference_rays=4)


def test_hit_reprojection_ghosts_less_than_surface_reprojection(sphere_study):
    """Where the sphere's reflection left the mirror, surface-only reprojection keeps the old
    reflection (its error energy there above the single frame's); hit-point reprojection follows
    the sphere and rejects the reflection it uncovered: at most a quarter of that excess."""
    r = sphere_study
    single = r["single frame"]["ghost"].sum()
    surface, hit = r["surface"]["ghost"].sum() - single, r["hit"]["ghost"].sum() - single
    assert r["masks"]["ghost"][1:].sum() > 100
    assert surface > 0.1 * single, (surface, single)
    assert hit <= 0.25 * surface, (hit, surface)
    assert r["hit"]["lag"] is not None and (r["surface"]["lag"] is None or r["hit"]["lag"] <= r["surface"]["lag"])
    # Standing still, a mirror's frames are all alike: what their accumulation reaches is the frame's.
    assert r["single frame"]["still at stop"] == r["single frame"]["all"][5]
    assert r["hit"]["still at stop"] == pytest.approx(r["single frame"]["all"][5], rel=1e-3)


def test_hit_accumulation_beats_the_single_frame_after_n_frames(renderer):
    """The long box turning over the glossy floor (roughness 0.2), 1 ray per pixel: after 8 frames of
    motion, the accumulation with hit-point reprojection has less error against that frame's
    converged reference than the frame alone with the same rays."""
    seq = temporal.box_over_glossy(frames=8, moving=8)
    base = ssrlab.Settings(width=96, height=54, layers=4, rays_per_pixel=1, shadow_map_size=512)
    errors = {}
    for name in ("single frame", "hit"):
        s = temporal.motion_configurations(base)[name]
        for i, f in enumerate(renderer.render_sequence(seq.scene, seq.cameras, s, times=seq.times)):
            if i == 7:
                if name == "single frame":
                    ref = f.reference("converged", rays=64)
                errors[name] = ssrlab.metrics.rmse(f.reflection, ref.reflection, ref.reflective)
    assert errors["hit"] < errors["single frame"], errors


def test_study_masks_come_from_the_gbuffers():
    """disoccluded(): a pixel whose previous position (its motion, nearest pixel) showed another
    object, or lay off the image; box_filter: window means."""
    class G:
        pass

    class F:
        pass

    f = F()
    f.gbuffer = G()
    f.gbuffer.coverage = np.ones((1, 2, 3), bool)
    f.gbuffer.object_id = np.array([[[0, 0, 1], [0, 1, 1]]])
    m = np.zeros((1, 2, 3, 2), np.float32)
    m[0, 0, 0] = (-1.0, 0.0)  # off the image
    m[0, 1, 1] = (1.0, 0.0)   # lands on object 1: the same
    m[0, 0, 1] = (0.6, 0.0)   # lands on (0, 2): object 1, not 0
    f.gbuffer.motion = m
    previous = np.array([[0, 0, 1], [0, 0, 1]])
    np.testing.assert_array_equal(temporal.disoccluded(f, previous), [[True, True, False], [False, False, False]])
    img = np.arange(12, dtype=np.float64).reshape(3, 4, 1)
    out = temporal.box_filter(img, 1)
    assert out[1, 1, 0] == pytest.approx(img[0:3, 0:3].mean()) and out[0, 0, 0] == pytest.approx(img[0:2, 0:2].mean())


@pytest.mark.parametrize("make, below_one", [(temporal.sphere_over_mirror, False), (temporal.box_over_glossy, True)])
def test_accumulation_bound_separates_noise_from_bias(renderer, make, below_one):
    """The best any accumulation of K frames reaches: on the mirror, one ray per pixel is the same
    every frame (the mean of the renders is the single frame: ratio exactly 1, bias only); on the
    glossy floor the frames' rays differ and their mean is closer to the reference. Its single
    frame is the sequence's own frame K (same seed, same pose)."""
    seq = make(frames=4, moving=4)
    base = ssrlab.Settings(width=96, height=54, layers=2, rays_per_pixel=1, shadow_map_size=512)
    bound = temporal.accumulation_bound(renderer, seq, base, reference_rays=8)
    assert bound["frame"] == 3 and bound["count"] == 4
    if below_one:
        assert bound["ratio"] < 0.95, bound
    else:
        assert bound["ratio"] == 1.0, bound
    *_, last = renderer.render_sequence(seq.scene, seq.cameras, base, times=seq.times)
    ref = last.reference("converged", rays=8)
    assert ssrlab.metrics.rmse(last.reflection, ref.reflection, ref.reflective) == pytest.approx(bound["single"], rel=1e-6)
    with pytest.raises(ValueError, match="accumulation_bound"):
        temporal.accumulation_bound(renderer, seq, base, frame=4)
