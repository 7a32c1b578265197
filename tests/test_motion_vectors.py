"""Motion vectors (Settings.motion_vectors, frame.gbuffer.motion; seed 002, 4.6.4's velocity
buffer): every sample of every layer, whatever constructed the deep G-buffer, points to where its
surface point was in the previous frame of the sequence. The expectation is computed here from the
transforms alone: the sample's world point from its stored depth and the camera, taken into its
object's space by this frame's transform and out by the previous frame's, projected by the previous
camera."""

import numpy as np
import pytest

import ssrlab
from ssrlab import transforms as T
from conftest import small

CONSTRUCTIONS = ("peel", "lists", "visibility", "visibility_lists")
W, H = 96, 64


def moving_scene():
    s = ssrlab.Scene()
    ids = {
        "floor": s.add_plane((0, 0, 0), (12, 12), material=ssrlab.Material(base_color=(0.5, 0.5, 0.5), roughness=0.1)),
        "box": s.add_box((0, 0.6, 0), (1.0, 1.2, 1.0), material=ssrlab.Material(base_color=(0.8, 0.2, 0.2))),
        "ball": s.add_sphere((1.6, 0.5, -0.8), 0.5, segments=24, material=ssrlab.Material(base_color=(0.2, 0.3, 0.9))),
    }
    return s, ids


def settings(construction, **kw):
    kw.setdefault("layers", 3)
    return small(width=W, height=H, deep_gbuffer=construction, motion_vectors=True, method="off", shadow_map_size=0,
                 **kw)


def pixel_of(world: np.ndarray, view: np.ndarray, proj: np.ndarray) -> np.ndarray:
    """(col, row) of world points in an image of the arrays' orientation (row 0 at the top)."""
    clip = np.c_[world, np.ones(len(world))] @ (proj @ view).T
    ndc = clip[:, :2] / clip[:, 3:4]
    return np.stack([(ndc[:, 0] * 0.5 + 0.5) * W, (0.5 - ndc[:, 1] * 0.5) * H], -1)


def expected_motion(frame, previous, transforms_now, transforms_before):
    """Per covered sample (layer, row, col): previous pixel minus this pixel, from the transforms."""
    g = frame.gbuffer
    inv_proj = np.linalg.inv(frame.projection_matrix.astype(np.float64))
    inv_view = np.linalg.inv(frame.view_matrix.astype(np.float64))
    layer, row, col = np.nonzero(g.coverage)
    ndc = np.stack([(col + 0.5) / W * 2 - 1, 1 - (row + 0.5) / H * 2], -1)
    # The pixel's ray at view depth 1, scaled to the sample's view depth.
    ray = np.c_[ndc, np.ones(len(ndc)), np.ones(len(ndc))] @ inv_proj.T
    ray = ray[:, :3] / ray[:, 3:4]
    ray = ray / -ray[:, 2:3]
    view_point = ray * g.depth[layer, row, col][:, None].astype(np.float64)
    world = np.c_[view_point, np.ones(len(view_point))] @ inv_view.T
    ids = g.object_id[layer, row, col]
    before = np.empty((len(world), 3))
    for obj in np.unique(ids):
        sel = ids == obj
        local = world[sel] @ np.linalg.inv(transforms_now[obj]).T
        before[sel] = (local @ transforms_before[obj].T)[:, :3]
    prev = pixel_of(before, previous.view_matrix.astype(np.float64), previous.projection_matrix.astype(np.float64))
    return (layer, row, col), prev - np.stack([col + 0.5, row + 0.5], -1)


@pytest.mark.parametrize("depth_mode", ["reversed_z", "standard"])
@pytest.mark.parametrize("construction", CONSTRUCTIONS)
def test_motion_points_to_where_each_sample_was(renderer, construction, depth_mode):
    """The camera orbits and rises, the box turns and slides, the ball stays: every layer's samples
    reproject onto their previous positions within 0.01 px."""
    scene, ids = moving_scene()
    cams = [ssrlab.Camera(position=(0.0, 2.5, 6.0), target=(0, 0.5, 0), fov_y=50, near=0.2, far=40),
            ssrlab.Camera(position=(0.5, 2.7, 5.8), target=(0.05, 0.5, 0), fov_y=50, near=0.2, far=40)]
    box_before = T.translate((0, 0.6, 0))
    box_after = T.translate((0.25, 0.6, -0.1)) @ T.rotate((0, 1, 0), 12.0)
    transforms = []
    frames = []
    for i, cam in enumerate(cams):
        scene.set_object_transform(ids["box"], box_before if i == 0 else box_after)
        transforms.append([np.asarray(scene.object_transform(k), dtype=np.float64) for k in range(3)])
    # A sequence: frame 1 is the moved state, frame 0 the state before.
    scene.set_object_transform(ids["box"], box_before)
    seq = renderer.render_sequence(scene, cams, settings(construction, depth_mode=depth_mode))
    for i, f in enumerate(seq):
        if i == 0:
            frames.append(f)
            scene.set_object_transform(ids["box"], box_after)
            continue
        frames.append(f)
    first, second = frames
    assert second.settings.deep_gbuffer == construction
    np.testing.assert_array_equal(first.gbuffer.motion, 0.0)  # the sequence's first frame: no history
    (layer, row, col), want = expected_motion(second, first, transforms[1], transforms[0])
    got = second.gbuffer.motion[layer, row, col]
    err = np.abs(got - want).max(-1)
    assert len(err) > 0.5 * W * H and second.stats["layers_used"] >= 2
    assert err.max() <= 0.01, f"{construction}: worst {err.max():.4f} px at layer {layer[err.argmax()]}"
    moved = second.gbuffer.object_id[layer, row, col] == ids["box"]
    assert np.abs(got[moved]).max() > 2.0  # the box moved by pixels, not a rounding
    # Empty samples hold 0.
    assert not second.gbuffer.motion[~second.gbuffer.coverage].any()


@pytest.mark.parametrize("construction", CONSTRUCTIONS)
def test_nothing_moved_is_exactly_zero_with_taa_jitter(renderer, construction):
    """A still camera over a still scene, TAA's sub-pixel jitter on: the jitter is no motion, and a
    point that did not move has exactly 0 (both positions come through the same matrices)."""
    scene = ssrlab.scenes.load("spheres_and_boxes")
    frames = list(renderer.render_sequence(scene, [scene.camera] * 3, settings(construction, taa="clamped")))
    for f in frames:
        assert f.gbuffer.coverage.any()
        assert not f.gbuffer.motion.any()


def test_only_the_moved_object_moves(renderer):
    """A fixed camera: the moved object's samples have motion (as the transforms say), every other
    sample exactly 0."""
    scene, ids = moving_scene()
    cam = ssrlab.Camera(position=(0.0, 2.5, 6.0), target=(0, 0.5, 0), fov_y=50, near=0.2, far=40)
    before = [np.asarray(scene.object_transform(k), dtype=np.float64) for k in range(3)]
    out = []
    for f in renderer.render_sequence(scene, [cam, cam], settings("visibility")):
        out.append(f)
        scene.set_object_transform(ids["ball"], T.translate((1.6, 0.9, -0.8)))
    now = [np.asarray(scene.object_transform(k), dtype=np.float64) for k in range(3)]
    g = out[1].gbuffer
    ball = g.coverage & (g.object_id == ids["ball"])
    assert ball.sum() > 50
    assert not g.motion[g.coverage & ~ball].any()
    (layer, row, col), want = expected_motion(out[1], out[0], now, before)
    assert np.abs(g.motion[layer, row, col] - want).max() <= 0.01
    assert np.abs(g.motion[ball]).max() > 2.0


def test_motion_needs_the_setting(renderer):
    f = renderer.render(ssrlab.scenes.load("hall"), settings=small(width=32, height=16))
    assert "gbuffer.motion" not in f.texture_names
    with pytest.raises(KeyError, match="motion_vectors"):
        f.gbuffer.motion
