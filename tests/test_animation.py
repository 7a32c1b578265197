"""Things that move: glTF animations sampled at a time match the glTF 2.0 interpolation formulas
(Appendix C), computed here independently with numpy for every interpolation mode and path, an
animated parent moving its children; Python keyframes and functions of time move objects and
lights through set_object_transform and set_light, giving the very frames of the same motion
set by hand; render_sequence(times=...) poses each frame; animations survive save and load."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

import ssrlab
from conftest import small
from ssrlab import transforms as T
from ssrlab.lab.animated_gltf import Builder, write_stage
from ssrlab.transforms import quaternion

# -- the expected values, computed independently of ssrlab's sampler ------------------------


def rotation_matrix(q) -> np.ndarray:
    """3x3 rotation of a unit quaternion (x, y, z, w)."""
    x, y, z, w = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def axis_angle_matrix(axis, angle) -> np.ndarray:
    """Rodrigues' formula."""
    k = np.asarray(axis, float)
    k = k / np.linalg.norm(k)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def slerp_matrix(q0, q1, u) -> np.ndarray:
    """Slerp as rotation matrices: R0 turned by the fraction u of the rotation from R0 to R1 (its
    angle in [0, pi]: the shorter arc), with no quaternion arithmetic."""
    r0, r1 = rotation_matrix(q0), rotation_matrix(q1)
    rel = r0.T @ r1
    angle = math.acos(max(-1.0, min(1.0, (np.trace(rel) - 1) / 2)))
    if angle < 1e-9:
        return r0
    axis = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    return r0 @ axis_angle_matrix(axis, u * angle)


def hermite(v0, b0, v1, a1, td, u):
    """The glTF cubic spline between keyframes, tangents b0 (out) and a1 (in) scaled by td."""
    v0, b0, v1, a1 = (np.asarray(x, float) for x in (v0, b0, v1, a1))
    return ((2 * u ** 3 - 3 * u ** 2 + 1) * v0 + td * (u ** 3 - 2 * u ** 2 + u) * b0
            + (-2 * u ** 3 + 3 * u ** 2) * v1 + td * (u ** 3 - u ** 2) * a1)


def trs(t=(0, 0, 0), r=None, s=(1, 1, 1)) -> np.ndarray:
    m = np.eye(4)
    rot = np.eye(3) if r is None else (r if np.shape(r) == (3, 3) else rotation_matrix(r))
    m[:3, :3] = rot @ np.diag(np.asarray(s, float))
    m[:3, 3] = t
    return m


def segment(times, t):
    """(k, u): t lies at fraction u between keyframes k and k + 1 (t strictly inside)."""
    k = int(np.searchsorted(times, t, side="right")) - 1
    return k, (t - times[k]) / (times[k + 1] - times[k])


# -- a hand-made animated file ---------------------------------------------------------------
# Parent (a box at node 0) carries Child (node 1, a box above it); Other (node 2) stands still.
KEYS = [0.0, 1.0, 3.0]
Q = [quaternion((0, 1, 0), 10.0), quaternion((1, 1, 0), 100.0), quaternion((0.2, -0.5, 1), 170.0)]
# The second key flipped to -q: the same rotation, and slerp must still take the shorter arc.
Q_FLIPPED = [Q[0], tuple(-c for c in Q[1]), Q[2]]
T_KEYS = [(0.0, 0.0, 0.0), (1.0, 2.0, -1.0), (-0.5, 0.25, 3.0)]
S_KEYS = [(1.0, 1.0, 1.0), (2.0, 0.5, 1.0), (0.5, 0.5, 3.0)]
# CUBICSPLINE: (in-tangent, value, out-tangent) per keyframe.
T_CUBIC = [[(9, 9, 9), (0, 0, 0), (1, 0, -2)], [(0.5, 1, 0), (1, 2, -1), (-1, 0.5, 2)], [(0, 1, 1), (-0.5, 0.25, 3), (7, 7, 7)]]
S_CUBIC = [[(0, 0, 0), (1, 1, 1), (0.5, -0.5, 0)], [(1, 0, 0), (2, 0.5, 1), (0, 0, 1)], [(0.2, 0.2, 0.2), (0.5, 0.5, 3), (0, 0, 0)]]
R_CUBIC = [[(0, 0, 0, 0), Q[0], (0.1, 0.2, 0, 0)], [(0, 0.3, 0.1, 0), Q[1], (0.2, 0, -0.1, 0.05)],
           [(0.1, 0, 0, 0.1), Q[2], (0, 0, 0, 0)]]
PARENT_REST = dict(t=(1.0, 0.0, 0.0))
CHILD_REST = dict(t=(0.0, 2.0, 0.0), s=(0.5, 0.5, 0.5))
CHILD_ROT_STEP = [quaternion((1, 0, 0), 30.0), quaternion((0, 0, 1), -45.0), quaternion((0, 1, 0), 90.0)]


def animated_file(path, suffix=".gltf"):
    b = Builder()
    box = b.box(b.material("grey", (0.7, 0.7, 0.7)))
    child = b.node("Child", mesh=box, translation=CHILD_REST["t"], scale=CHILD_REST["s"])
    parent = b.node("Parent", mesh=box, translation=PARENT_REST["t"], children=[child])
    other = b.node("Other", mesh=box, translation=(-3.0, 0.0, 0.0))
    b.animation("linear", [(parent, "rotation", "LINEAR", KEYS, Q_FLIPPED),
                           (parent, "translation", "LINEAR", KEYS, T_KEYS),
                           (child, "scale", "LINEAR", KEYS, S_KEYS)])
    b.animation("step", [(parent, "translation", "STEP", KEYS, T_KEYS),
                         (child, "rotation", "STEP", KEYS, CHILD_ROT_STEP),
                         (child, "scale", "STEP", KEYS, S_KEYS)])
    b.animation("cubic", [(parent, "translation", "CUBICSPLINE", KEYS, T_CUBIC),
                          (parent, "rotation", "CUBICSPLINE", KEYS, R_CUBIC),
                          (child, "scale", "CUBICSPLINE", KEYS, S_CUBIC)])
    # Keys that end earlier than the clip's other channels: they hold their last value.
    b.animation("short", [(child, "translation", "LINEAR", [0.5, 1.5], [(0, 2, 0), (0, 3, 1)])])
    return b.write(path / f"animated{suffix}", [parent, other])


def linear_values(t):
    """(rotation matrix, translation, scale) of the "linear" clip at t."""
    tt = min(max(t, KEYS[0]), KEYS[-1])
    if tt in (KEYS[0], KEYS[-1]):
        k = 0 if tt == KEYS[0] else len(KEYS) - 1
        return rotation_matrix(Q[k]), np.array(T_KEYS[k]), np.array(S_KEYS[k])
    k, u = segment(KEYS, tt)
    return (slerp_matrix(Q_FLIPPED[k], Q_FLIPPED[k + 1], u),
            (1 - u) * np.array(T_KEYS[k]) + u * np.array(T_KEYS[k + 1]),
            (1 - u) * np.array(S_KEYS[k]) + u * np.array(S_KEYS[k + 1]))


def expected_linear(t, child_translation=CHILD_REST["t"]):
    rot, tr, sc = linear_values(t)
    parent = trs(tr, rot)
    return parent, parent @ trs(child_translation, None, sc)


def expected_step(t):
    k = 0 if t <= KEYS[0] else int(np.searchsorted(KEYS, t, side="right")) - 1
    parent = trs(T_KEYS[k])
    return parent, parent @ trs(CHILD_REST["t"], CHILD_ROT_STEP[k], S_KEYS[k])


def cubic_values(t):
    """(translation, unit quaternion, scale) of the "cubic" clip at t."""
    tt = min(max(t, KEYS[0]), KEYS[-1])
    if tt in (KEYS[0], KEYS[-1]):
        k = 0 if tt == KEYS[0] else len(KEYS) - 1
        return T_CUBIC[k][1], R_CUBIC[k][1], S_CUBIC[k][1]
    k, u = segment(KEYS, tt)
    td = KEYS[k + 1] - KEYS[k]
    tr, q, sc = (hermite(c[k][1], c[k][2], c[k + 1][1], c[k + 1][0], td, u) for c in (T_CUBIC, R_CUBIC, S_CUBIC))
    return tr, q / np.linalg.norm(q), sc


def expected_cubic(t):
    tr, q, sc = cubic_values(t)
    parent = trs(tr, q)
    return parent, parent @ trs(CHILD_REST["t"], None, sc)


TIMES = [-1.0, 0.0, 0.3, 1.0, 1.7, 2.999, 3.0, 4.5]


@pytest.fixture(scope="module")
def animated(tmp_path_factory):
    return animated_file(tmp_path_factory.mktemp("anim"))


def load(path) -> ssrlab.Scene:
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)  # an animated file loads without a warning
        return ssrlab.Scene.load(path)


def objects(scene) -> dict[str, int]:
    return {scene.object_name(i): i for i in range(scene.object_count)}


def test_animations_are_listed_with_names_durations_and_channels(animated):
    scene = load(animated)
    assert [(a.name, a.duration) for a in scene.animations] == [("linear", 3.0), ("step", 3.0), ("cubic", 3.0),
                                                                ("short", 1.5)]
    assert scene.node_names == ["Parent", "Child", "Other"]
    assert scene.animations[2].channels == [(0, "translation", "CUBICSPLINE", 3), (0, "rotation", "CUBICSPLINE", 3),
                                            (1, "scale", "CUBICSPLINE", 3)]
    # Until something plays, the file stands in its rest pose.
    ids = objects(scene)
    np.testing.assert_allclose(scene.object_transform(ids["Child"]),
                               trs(PARENT_REST["t"]) @ trs(CHILD_REST["t"], None, CHILD_REST["s"]), atol=1e-7)


@pytest.mark.parametrize("name, expected", [("linear", expected_linear), ("step", expected_step),
                                            ("cubic", expected_cubic)])
def test_transforms_at_t_match_the_gltf_formulas(animated, name, expected):
    scene = load(animated)
    ids = objects(scene)
    other = scene.object_transform(ids["Other"])
    scene.play(name)
    for t in TIMES:
        scene.set_time(t)
        parent, child = expected(t)
        np.testing.assert_allclose(scene.object_transform(ids["Parent"]), parent, atol=2e-6, err_msg=f"{name} t={t}")
        np.testing.assert_allclose(scene.object_transform(ids["Child"]), child, atol=4e-6, err_msg=f"{name} t={t}")
        np.testing.assert_array_equal(scene.object_transform(ids["Other"]), other)  # not animated: untouched
    assert scene.time == TIMES[-1]


def test_slerp_takes_the_shorter_arc_and_is_not_a_linear_blend(animated):
    """Between keys 0 and 1 (10 deg about y, 100 deg about (1, 1, 0), stored as -q) the rotation
    is the slerp, which a normalised linear blend of the quaternions differs from by > 1e-3."""
    scene = load(animated)
    scene.play("linear")
    scene.set_time(0.3)
    got = scene.object_transform(objects(scene)["Parent"])[:3, :3]
    np.testing.assert_allclose(got, slerp_matrix(Q[0], Q[1], 0.3), atol=2e-6)
    blend = 0.7 * np.array(Q[0]) + 0.3 * np.array(Q[1])
    assert np.abs(got - rotation_matrix(blend / np.linalg.norm(blend))).max() > 1e-3


def test_loop_wraps_time_and_clamp_holds_the_ends(animated):
    scene = load(animated)
    ids = objects(scene)
    scene.play("linear", loop=True)
    for t, inside in [(3.7, 0.7), (6.0, 3.0), (-0.5, 2.5), (9.25, 0.25), (0.0, 0.0)]:
        scene.set_time(t)
        np.testing.assert_allclose(scene.object_transform(ids["Parent"]), expected_linear(inside)[0], atol=2e-6)
    scene.play("linear")  # clamped
    scene.set_time(7.0)
    np.testing.assert_allclose(scene.object_transform(ids["Parent"]), expected_linear(3.0)[0], atol=2e-6)
    # Each clip loops over its own duration: "short" (keys at 0.5 and 1.5 s) is at 1.0 s when
    # "linear" is at 2.5 s; the child's translation is halfway between its keys.
    scene.play("short", "linear", loop=True)
    scene.set_time(2.5)
    np.testing.assert_allclose(scene.object_transform(ids["Child"]), expected_linear(2.5, (0, 2.5, 0.5))[1], atol=4e-6)


def test_several_animations_by_name_and_index(animated):
    scene = load(animated)
    ids = objects(scene)
    scene.play(1, "short")  # step moves the parent, short the child's translation
    scene.set_time(1.0)
    parent = trs(T_KEYS[1])
    child = parent @ trs((0, 2.5, 0.5), CHILD_ROT_STEP[1], S_KEYS[1])
    np.testing.assert_allclose(scene.object_transform(ids["Child"]), child, atol=4e-6)
    with pytest.raises(KeyError, match="no animation named 'walk'.*'linear'"):
        scene.play("walk")
    with pytest.raises(IndexError, match="animation index 9 is out of range"):
        scene.play(9)
    scene.play()  # all four
    scene.stop()
    moved = scene.object_transform(ids["Parent"])
    scene.set_time(0.0)
    np.testing.assert_array_equal(scene.object_transform(ids["Parent"]), moved)  # stopped: nothing moves


def test_animated_light_moves_with_its_parent(tmp_path):
    path = write_stage(tmp_path / "stage.gltf")
    scene = load(path)
    ids = objects(scene)
    lamp = [i for i, l in enumerate(scene.lights) if l.type == "point"][0]
    scene.play("Spin")
    for t in (0.0, 0.8, 2.2):
        scene.set_time(t)
        spinner = scene.object_transform(ids["Spinner"])
        # The lamp is the spinner's child at (0, 0.9, 0) in its frame.
        np.testing.assert_allclose(scene.lights[lamp].position, (spinner @ [0, 0.9, 0, 1])[:3], atol=1e-6)
        np.testing.assert_allclose(scene.object_transform(ids["Satellite"]), spinner @ trs((0.9, 0, 0), None, (0.3,) * 3),
                                   atol=2e-6)


def test_keyframes_sample_as_gltf_does():
    kf = ssrlab.Keyframes(KEYS, translation=T_CUBIC, rotation=R_CUBIC, scale=S_CUBIC, interpolation="cubicspline")
    for t in TIMES:
        np.testing.assert_allclose(kf.matrix(t), trs(*cubic_values(t)), atol=4e-6, err_msg=f"t={t}")
    lin = ssrlab.Keyframes(KEYS, rotation=Q_FLIPPED)
    np.testing.assert_allclose(lin.matrix(1.7)[:3, :3], slerp_matrix(Q[1], Q[2], 0.35), atol=2e-6)
    step = ssrlab.Keyframes(KEYS, scale=S_KEYS, interpolation="step")
    np.testing.assert_array_equal(step.sample(2.999)["scale"], np.float32(S_KEYS[1]))
    assert set(step.sample(0.0)) == {"scale"}


@pytest.mark.parametrize("kwargs, message", [
    (dict(times=[0, 1, 1], translation=[(0, 0, 0)] * 3), "increase strictly"),
    (dict(times=[-1, 1], translation=[(0, 0, 0)] * 2), "first keyframe time"),
    (dict(times=[0, 1], translation=[(0, 0, 0)] * 3), "3 keyframes, times has 2"),
    (dict(times=[0, 1], rotation=[(0, 0, 0, 0), (0, 0, 0, 1)]), "zero quaternion"),
    (dict(times=[0], translation=[[(0, 0, 0)] * 3], interpolation="cubicspline"), "at least 2 keyframes"),
    (dict(times=[0, 1], translation=[(0, 0, 0)] * 2, interpolation="smooth"), "'linear', 'step' or 'cubicspline'"),
    (dict(times=[0, 1], translation=[(0, 0, np.nan)] * 2), "not finite"),
    (dict(times=[0, 1]), "at least one of translation"),
])
def test_bad_keyframes_are_refused_by_name(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ssrlab.Keyframes(**kwargs)


def moving_scene():
    scene = ssrlab.scenes.mirror_test()
    ids = [i for i in range(scene.object_count) if scene.object_name(i) != "floor"] or [1]
    return scene, ids[0]


def test_python_motion_gives_the_frames_of_the_same_motion_set_by_hand(renderer):
    """A function of time for an object and keyframes for a light, played by render_sequence(times=...),
    against render_sequence with the same transforms and light set by hand before each frame: equal bit for bit."""
    base, obj = moving_scene()
    start = base.object_transform(obj)
    light0 = base.lights[0]

    def motion(t):
        return T.translate((0.6 * t, 0.0, 0.3 * t)) @ T.rotate((0, 1, 0), 40.0 * t) @ start

    light_keys = ssrlab.Keyframes([0.0, 1.0], translation=[(0.0, 3.0, 1.0), (2.0, 2.0, -1.0)],
                                  rotation=[quaternion((1, 0, 0), -70.0), quaternion((1, 0.3, 0), -40.0)])
    times = [0.0, 0.4, 1.0]
    settings = small(layers=2, width=64, height=40, deep_gbuffer="peel", temporal_reflections=True)
    cam = base.camera

    animated = base.copy()
    animated.animate(obj, motion)
    animated.animate(light=0, motion=light_keys)
    a = [f.color.copy() for f in renderer.render_sequence(animated, cam, settings, times=times)]

    by_hand = base.copy()
    frames = renderer.render_sequence(by_hand, [cam] * len(times), settings)
    b = []
    for t in times:
        by_hand.set_object_transform(obj, motion(t))
        light = by_hand.lights[0]
        values = light_keys.sample(t)
        light.position = tuple(values["translation"])
        light.direction = tuple(rotation_matrix(values["rotation"]) @ [0.0, 0.0, -1.0])
        by_hand.set_light(0, light)
        b.append(next(frames).color.copy())
    frames.close()
    for i in range(len(times)):
        np.testing.assert_array_equal(a[i], b[i], err_msg=f"frame {i}")
    assert not np.array_equal(a[0], a[-1])  # the motion shows
    assert light0.position != animated.lights[0].position


def test_render_sequence_with_a_camera_path_and_a_fixed_camera(renderer, tmp_path):
    scene = load(write_stage(tmp_path / "stage.glb"))
    scene.play("Spin", "Hop", loop=True)
    cam = scene.camera
    settings = small(layers=1, width=48, height=32, deep_gbuffer="peel")
    fixed = [f for f in renderer.render_sequence(scene, cam, settings, times=[0.0, 1.2])]
    assert [f.time for f in fixed] == [0.0, 1.2] and scene.time == 1.2
    assert not np.array_equal(fixed[0].color, fixed[1].color)
    path = ssrlab.CameraPath([cam.position, (0.5, 1.4, 3.0)], [cam.target], frames=2, fov_y=cam.fov_y,
                             near=cam.near, far=cam.far)
    moving = list(renderer.render_sequence(scene, path, settings, times=[0.0, 1.2]))
    np.testing.assert_array_equal(moving[0].color, fixed[0].color)  # same camera, same time: same frame
    assert [f.time for f in renderer.render_sequence(scene, path, settings)] == [None, None]
    with pytest.raises(ValueError, match="3 times for 2 cameras"):
        list(renderer.render_sequence(scene, path, settings, times=[0, 1, 2]))
    with pytest.raises(ValueError, match="finite"):
        list(renderer.render_sequence(scene, cam, settings, times=[0, math.inf]))


def test_animate_checks_its_target_and_motion():
    scene, obj = moving_scene()
    with pytest.raises(ValueError, match="one of them"):
        scene.animate(obj, lambda t: T.identity(), light=0)
    with pytest.raises(IndexError, match="object index 99"):
        scene.animate(99, lambda t: T.identity())
    with pytest.raises(TypeError, match="Keyframes or a function"):
        scene.animate(obj, "spin")
    with pytest.raises(ValueError, match="a light has no scale"):
        scene.animate(light=0, motion=ssrlab.Keyframes([0, 1], scale=[(1, 1, 1)] * 2))
    with pytest.raises(ValueError, match=r"object \d+'s motion at t = 0 s must return a finite 4x4"):
        scene.animate(obj, lambda t: np.eye(3))
    with pytest.raises(ValueError, match="returned field 'colour'"):
        scene.animate(light=0, motion=lambda t: {"colour": (1, 0, 0)})
    scene.set_time(1.0)  # the motions that failed were not kept
    scene.animate(light=0, motion=lambda t: {"intensity": 1.0 + t})
    scene.set_time(2.0)
    assert scene.lights[0].intensity == 3.0
    with pytest.raises(ValueError, match="set_time: t must be finite"):
        scene.set_time(math.nan)


def test_a_pose_that_cannot_be_drawn_is_a_scene_error(tmp_path):
    b = Builder()
    box = b.box(b.material("grey", (0.5, 0.5, 0.5)))
    node = b.node("Shrinker", mesh=box)
    b.animation("vanish", [(node, "scale", "LINEAR", [0.0, 1.0], [(1, 1, 1), (0, 0, 0)])])
    path = b.write(tmp_path / "vanish.gltf", [node])
    scene = load(path)
    scene.play("vanish")
    scene.set_time(0.5)
    with pytest.raises(ssrlab.SceneError, match=r"vanish.gltf: animation 'vanish' at t = 1 s: node 0 \('Shrinker'\)"):
        scene.set_time(1.0)


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_animations_survive_save_and_load(animated, tmp_path, suffix, renderer):
    scene = load(animated)
    scene.play("cubic")
    scene.set_time(1.3)  # saved in this pose
    path = scene.save(tmp_path / f"again{suffix}")
    back = load(path)
    assert [(a.name, a.duration, a.channels) for a in back.animations] == \
        [(a.name, a.duration, a.channels) for a in scene.animations]
    for i in range(scene.object_count):
        assert back.object_name(i) == scene.object_name(i)
        np.testing.assert_array_equal(back.object_transform(i), scene.object_transform(i))
    settings = small(layers=2, width=48, height=32, deep_gbuffer="peel")
    cam = ssrlab.Camera(position=(0, 3, 9), target=(0, 1, 0))
    np.testing.assert_array_equal(renderer.render(scene, cam, settings).color, renderer.render(back, cam, settings).color)
    for name in ("linear", "step", "cubic"):
        scene.play(name)
        back.play(name)
        for t in (0.4, 2.2):
            scene.set_time(t)
            back.set_time(t)
            for i in range(scene.object_count):
                np.testing.assert_array_equal(back.object_transform(i), scene.object_transform(i))
    doc = json.loads(path.read_text()) if suffix == ".gltf" else None
    if doc:
        assert {s["interpolation"] for a in doc["animations"] for s in a["samplers"]} == {"LINEAR", "STEP", "CUBICSPLINE"}


def test_a_stage_model_moves_in_its_frames(renderer, tmp_path):
    """The animated stage model: something moves between frames, everything stays finite."""
    scene = load(write_stage(tmp_path / "stage.gltf"))
    scene.play("Spin")
    settings = small(layers=2, width=64, height=40, deep_gbuffer="peel")
    frames = [f.color.copy() for f in renderer.render_sequence(scene, scene.camera, settings, times=[0.0, 0.75])]
    assert all(np.isfinite(f).all() for f in frames)
    assert np.abs(frames[0] - frames[1]).max() > 0.05


def test_an_object_moved_by_hand_is_saved_relative_to_its_node(animated, tmp_path):
    """Saved as a child of its node holding the offset: it loads where it was, and follows its
    node (keeping the offset) when the animation plays."""
    scene = load(animated)
    ids = objects(scene)
    moved = T.translate((0.0, 0.0, 2.0)) @ scene.object_transform(ids["Child"])
    scene.set_object_transform(ids["Child"], moved)
    back = load(scene.save(tmp_path / "moved.glb"))
    np.testing.assert_allclose(back.object_transform(objects(back)["Child"]), moved, atol=1e-6)
    back.play("linear")  # it follows its node again when the animation plays
    back.set_time(1.0)
    parent = back.object_transform(objects(back)["Parent"])
    np.testing.assert_allclose(back.object_transform(objects(back)["Child"]),
                               parent @ trs(CHILD_REST["t"], None, S_KEYS[1]) @ np.linalg.inv(
                                   trs(PARENT_REST["t"]) @ trs(CHILD_REST["t"], None, CHILD_REST["s"])) @ moved,
                               atol=1e-5)
