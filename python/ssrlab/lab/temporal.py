"""The moving-camera study of temporal accumulation (notebooks/temporal.ipynb): the
configurations of history rejection it compares, and the per-frame error of each against
every frame's converged reference along a camera path (ssrlab.sequence.hall_path)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..truth import metrics

# With rejection, the accumulated reflection's error may exceed that of the frame alone (no
# history) by at most this much rmse on any frame: "no ghost trails".
GHOST_MARGIN = 0.005


def history_configurations(settings) -> dict:
    """The configurations the moving-camera study compares, from base `settings` (1 ray):
    no history; accumulation with every rejection on (previous depth, normal, off-screen, and
    the neighbourhood variance clamp, gamma 1); with depth/normal/off-screen rejection only; and
    without any rejection (the ghosting case)."""
    acc = settings.replace(temporal_reflections=True)
    return {
        "no history": settings.replace(temporal_reflections=False),
        "rejection": acc.replace(temporal_clamp=1.0),
        "depth+normal only": acc.replace(temporal_clamp=0.0),
        "no rejection": acc.replace(temporal_clamp=0.0, reject_depth=0.0, reject_normal=-1.0, reject_offscreen=False),
    }


def moving_camera_errors(renderer, scene, cameras, configurations: dict, *, reference_rays: int = 64,
                         metric=None) -> dict:
    """Per configuration, the per-frame rmse of the reflection (frame.reflection: the
    accumulation where temporal_reflections is on) against each frame's own converged
    reference, over that frame's reflective pixels. Each frame's reference is computed once,
    from the first configuration's frame (the reference depends on the camera, not the
    settings being compared). Returns {name: np.ndarray of per-frame errors}."""
    rmse = metric or metrics.rmse
    cameras = list(cameras)
    refs, errors = [], {}
    for name, settings in configurations.items():
        e = []
        for i, frame in enumerate(renderer.render_sequence(scene, cameras, settings)):
            if len(refs) <= i:
                refs.append(frame.reference("converged", rays=reference_rays))
            e.append(rmse(frame.reflection, refs[i].reflection, refs[i].reflective))
        errors[name] = np.asarray(e, np.float64)
    return errors




# -- things that move: the moving-object study (benchmarks/studies/temporal_motion.py) -------------------

# The ghost region of frame i: pixels whose reflection showed a moving object in any of the GHOST_FRAMES
# frames before it but shows none now (the trail it left in the history).
GHOST_FRAMES = 8
# Lag: frames after the motion stops until the error is within LAG_TOLERANCE (relative) of its
# converged level: the mean of the last LAG_TAIL frames of the same configuration over the scene
# standing still in its final pose (motion_study).
LAG_TOLERANCE = 0.1
LAG_TAIL = 4


@dataclass
class MotionSequence:
    """A sequence of frames in which objects move: its scene (posed at each frame's time by
    Scene.set_time: the motions given with Scene.animate, or glTF animations it plays), one camera
    per frame, each frame's time in seconds, the objects that move, and the first frame from
    which nothing moves any more (``still_from``; motion is between frames i - 1 and i for
    0 < i < still_from)."""

    name: str
    scene: object
    cameras: list
    times: list
    movers: tuple
    still_from: int

    def frames(self) -> int:
        return len(self.times)


def _times(frames: int, moving: int, duration: float) -> list[float]:
    """Frame i at duration * min(i, moving - 1) / (moving - 1): the motion runs over the first
    `moving` frames, then everything stands still."""
    if not 2 <= moving <= frames:
        raise ValueError(f"a motion sequence needs 2 <= moving <= frames, got moving={moving}, frames={frames}")
    return [duration * min(i, moving - 1) / (moving - 1) for i in range(frames)]


def _cameras(camera, frames: int, orbit_degrees: float) -> list:
    """`frames` cameras: `camera` itself (orbit 0) or orbiting its target about +y, from
    -orbit_degrees / 2 to +orbit_degrees / 2 over the frames."""
    from ..scene import Camera

    if orbit_degrees == 0.0:
        return [camera] * frames
    target = np.asarray(camera.target, np.float64)
    offset = np.asarray(camera.position, np.float64) - target
    out = []
    for i in range(frames):
        a = np.radians(orbit_degrees * (i / max(frames - 1, 1) - 0.5))
        c, s = np.cos(a), np.sin(a)
        o = np.array([c * offset[0] + s * offset[2], offset[1], -s * offset[0] + c * offset[2]])
        out.append(Camera(position=tuple(target + o), target=tuple(target), fov_y=camera.fov_y,
                          near=camera.near, far=camera.far))
    return out


def sphere_over_mirror(frames: int = 32, moving: int = 16, orbit_degrees: float = 0.0) -> MotionSequence:
    """An orange sphere (a dielectric that reflects nothing itself: seen through the mirror, the
    sun's glint would make its converged reference a firefly field) crossing
    ssrlab.scenes.mirror_test's mirror floor from left to right in front of its checkerboard
    wall, 6 m over `moving` frames."""
    from .. import scenes
    from ..animation import Keyframes
    from ..scene import Material

    scene = scenes.mirror_test()
    scene.name = "sphere over mirror"
    sphere = scene.add_sphere((-3.0, 0.9, -3.5), 0.7, segments=48, name="sphere", material=Material(
        base_color=(0.95, 0.45, 0.15), metallic=0.0, roughness=0.3, reflectivity=0.0))
    scene.animate(sphere, Keyframes([0.0, 1.0], translation=[(-3.0, 0.9, -3.5), (3.0, 0.9, -3.5)],
                                    scale=[(0.7, 0.7, 0.7)] * 2))
    return MotionSequence(scene.name, scene, _cameras(scene.camera, frames, orbit_degrees),
                          _times(frames, moving, 1.0), (sphere,), moving)


def box_over_glossy(frames: int = 32, moving: int = 16, orbit_degrees: float = 0.0) -> MotionSequence:
    """A long box (2.4 x 0.5 x 0.5 m) turning 90 degrees about a slightly tilted vertical axis over
    `moving` frames, floating over a glossy floor (roughness 0.2) among still spheres and boxes
    (ssrlab.scenes.spheres_and_boxes): its reflection sweeps the floor."""
    from .. import scenes
    from .. import transforms as T
    from ..scene import Material

    scene = scenes.spheres_and_boxes(seed=3, count=6, floor_roughness=0.2)
    scene.name = "box over glossy floor"
    size = (2.4, 0.5, 0.5)
    box = scene.add_box((0.0, 1.0, -1.0), size, name="turning box", material=Material(
        base_color=(0.85, 0.2, 0.6), roughness=0.4))

    def pose(t):
        turn = T.rotate((0.15, 1.0, 0.1), 90.0 * min(max(t, 0.0), 1.0))
        return T.translate((0.0, 1.0, -1.0)) @ turn @ T.scale(size)

    scene.animate(box, pose)
    return MotionSequence(scene.name, scene, _cameras(scene.camera, frames, orbit_degrees),
                          _times(frames, moving, 1.0), (box,), moving)


def gltf_stage(frames: int = 32, moving: int = 16, orbit_degrees: float = 0.0, folder=None) -> MotionSequence:
    """ssrlab.lab.animated_gltf's stage (a glTF file: written to `folder`, a temporary one by
    default) playing its "Spin" animation (3 s) over `moving` frames: the spinner turning and
    bobbing with its satellite and lamp, the hopper's STEP scale, over a floor of roughness 0.1."""
    import tempfile
    from pathlib import Path

    from .. import scenes
    from .animated_gltf import write_stage

    folder = Path(folder or tempfile.mkdtemp(prefix="ssrlab_stage_"))
    scene = scenes.load(str(write_stage(folder / "stage.gltf")))
    scene.name = "animated glTF stage"
    before = [np.asarray(scene.object_transform(i)) for i in range(scene.object_count)]
    scene.play("Spin")
    scene.set_time(1.3)
    movers = tuple(i for i in range(scene.object_count) if not np.array_equal(before[i], scene.object_transform(i)))
    scene.set_time(0.0)
    return MotionSequence(scene.name, scene, _cameras(scene.camera, frames, orbit_degrees),
                          _times(frames, moving, 1.0), movers, moving)


MOTION_SEQUENCES = {"sphere over mirror": sphere_over_mirror, "box over glossy floor": box_over_glossy,
                    "animated glTF stage": gltf_stage}


def motion_configurations(settings) -> dict:
    """The configurations the moving-object study compares, from base `settings` (1 ray): each
    frame alone, and the temporal accumulation (no neighbourhood clamp: what reprojection and
    rejection do alone) with the reflection reprojected by the surface or by the hit, the history
    rejected with or without the layers."""
    acc = settings.replace(temporal_reflections=True, temporal_clamp=0.0)
    return {
        "single frame": settings.replace(temporal_reflections=False),
        "surface": acc.replace(reflection_reprojection="surface", reject_layers=False),
        "surface + layers": acc.replace(reflection_reprojection="surface", reject_layers=True),
        "hit": acc.replace(reflection_reprojection="hit", reject_layers=False),
        "hit + layers": acc.replace(reflection_reprojection="hit", reject_layers=True),
    }


def reflects_objects(frame, objects) -> np.ndarray:
    """(H, W) bool: pixels one of whose rays (weight > 0, a screen-space hit kept at least half)
    hit one of `objects` (the object ids of the G-buffer sample it hit), at the image's resolution."""
    s = frame.settings
    if not len(objects):
        return np.zeros((s.height, s.width), bool)
    rays = frame.rays
    layer = rays.hit_layer
    hit = (layer > 0) & (rays.weight > 0) & (rays.fade >= 0.5)
    px = np.floor(rays.hit_pixel).astype(np.int64)
    col = np.clip(px[..., 0], 0, s.width - 1)
    row = np.clip(px[..., 1], 0, s.height - 1)
    ids = frame.gbuffer.object_id[np.clip(layer - 1, 0, s.layers - 1), row, col]
    per_trace = (hit & np.isin(ids, np.asarray(objects))).any(axis=0)
    d = s.downscale
    return np.repeat(np.repeat(per_trace, d, axis=0), d, axis=1)[:s.height, :s.width]


def disoccluded(frame, previous) -> np.ndarray:
    """(H, W) bool: pixels whose surface the previous frame did not show where it was: its layer 0
    at the pixel's previous position (gbuffer.motion, nearest pixel) was another object, or that
    position lay off the image. Computed from the G-buffers alone (object ids and motion), not
    from the reproject pass. None where there is no previous frame."""
    g = frame.gbuffer
    h, w = g.coverage.shape[1:]
    if previous is None:
        return np.zeros((h, w), bool)
    m = g.motion[0]
    rows, cols = np.mgrid[0:h, 0:w]
    pc = np.floor(cols + 0.5 + m[..., 0]).astype(np.int64)
    pr = np.floor(rows + 0.5 + m[..., 1]).astype(np.int64)
    inside = (pc >= 0) & (pc < w) & (pr >= 0) & (pr < h)
    before = np.full((h, w), -2, np.int32)
    before[inside] = previous[pr[inside], pc[inside]]
    return g.coverage[0] & (before != g.object_id[0])


# The ghost's scale: the error is averaged over (2 GHOST_BLUR + 1)^2 pixels before its energy is
# taken, so that per-pixel noise (which accumulation lowers, single frames keep) does not hide the
# trail (coherent over many pixels).
GHOST_BLUR = 2


def box_filter(image: np.ndarray, radius: int) -> np.ndarray:
    """The mean of every (2 radius + 1)^2 window of an (H, W, C) image (edges: the window's part
    inside the image)."""
    a = np.asarray(image, np.float64)
    for axis in (0, 1):
        c = np.cumsum(np.pad(a, [(radius + 1, radius) if k == axis else (0, 0) for k in range(a.ndim)]), axis=axis)
        n = a.shape[axis]
        hi = np.take(c, np.arange(2 * radius + 1, 2 * radius + 1 + n), axis=axis)
        lo = np.take(c, np.arange(0, n), axis=axis)
        idx = np.arange(n)
        count = (np.minimum(idx + radius, n - 1) - np.maximum(idx - radius, 0) + 1).astype(np.float64)
        shape = [1] * a.ndim
        shape[axis] = n
        a = (hi - lo) / count.reshape(shape)
    return a


def ghost_energy(image, reference, mask, blur: int = GHOST_BLUR) -> float:
    """Sum over `mask`'s pixels of the squared error, averaged over the channels, after the error
    image is averaged over (2 blur + 1)^2 pixels (box_filter)."""
    if not mask.any():
        return 0.0
    e = box_filter(np.asarray(image, np.float64) - np.asarray(reference, np.float64), blur)[mask]
    return float((e * e).mean(axis=-1).sum())


def _rmse(a, b, mask) -> float:
    return metrics.rmse(a, b, mask) if mask.any() else float("nan")


def lag(errors, level: float, still_from: int, tolerance: float = LAG_TOLERANCE):
    """Frames after the motion stops (frame still_from) until the per-frame error is within
    `tolerance` (relative) of its converged `level`; None when it never is within the sequence (or
    it has no still frames)."""
    for k in range(still_from, len(errors)):
        if errors[k] <= level * (1.0 + tolerance):
            return k - still_from
    return None


def motion_study(renderer, seq: MotionSequence, configurations: dict, *, reference_rays: int = 64,
                 ghost_frames: int = GHOST_FRAMES, keep=()) -> dict:
    """Every configuration's per-frame error on a moving-object sequence, against each frame's own
    converged reference (``frame.reference("converged", rays=reference_rays)``, computed once per
    frame from the first configuration, which must render each frame alone: it also gives the
    masks), over the reflective pixels ("all") and split into:

      moved        pixels whose reflection shows an object that moved since the previous frame
                   (one of its rays hit it: reflects_objects);
      disoccluded  pixels whose surface the previous frame did not show there (disoccluded);
      rest         the other reflective pixels;

    the ghosting ("ghost"): the error energy in the region the moving objects left (pixels whose
    reflection showed a mover in one of the `ghost_frames` frames before but shows none now, and
    not disoccluded) at the trail's scale (ghost_energy: the error averaged over 5x5 pixels first),
    to be read against the single-frame rendering's energy there; and the lag: frames after the
    motion stops until the error over the motion's footprint (every pixel that showed a mover, was
    disoccluded or in the ghost region in some frame) is within LAG_TOLERANCE of the level the same
    configuration converges to there when the scene stood still in its final pose from the first
    frame (rendered for the purpose, with the same cameras: the mean over its last LAG_TAIL frames,
    "converged"). Returns {"frames": n, "still_from": k, "masks": {name: per-frame pixel counts},
    name: {"all", "moved", "disoccluded", "rest",
    "footprint", "still footprint": per-frame rmse arrays (nan where the mask is empty; the
    footprint's from the stop on), "still at stop": the error over the reflective pixels at the
    last frame of the motion (which shows the final pose) had the scene stood still in that pose
    from the first frame, "ghost": per-frame energy, "converged": the footprint's level,
    "lag": frames or None}} and, for the configurations named in `keep`,
    "images": {name: [per-frame reflection]} (with "reference" and "ghost region")."""
    names = list(configurations)
    if configurations[names[0]].temporal_reflections:
        raise ValueError("motion_study: the first configuration must render each frame alone (the masks' source)")
    n = seq.frames()
    refs, masks, out = [], [], {"frames": n, "still_from": seq.still_from, "images": {}}
    mover_history = []
    footprint = None
    for name in names:
        settings = configurations[name].replace(motion_vectors=True)
        rows = {k: [] for k in ("all", "moved", "disoccluded", "rest", "ghost")}
        images = [] if name in keep else None
        after_stop = {}
        previous_ids = None
        for i, frame in enumerate(renderer.render_sequence(seq.scene, seq.cameras, settings, times=seq.times)):
            if len(refs) <= i:
                ref = frame.reference("converged", rays=reference_rays)
                refs.append((ref.reflection.copy(), ref.reflective.copy()))
                reflective = refs[i][1]
                moved_now = seq.movers if 0 < i < seq.still_from else ()
                shows = reflects_objects(frame, seq.movers)
                dis = disoccluded(frame, previous_ids) & reflective
                trail = np.zeros_like(shows)
                for past in mover_history[-ghost_frames:]:
                    trail |= past
                mover_history.append(shows)
                moved = reflects_objects(frame, moved_now) & reflective
                masks.append({"moved": moved, "disoccluded": dis, "rest": reflective & ~moved & ~dis,
                              "ghost": trail & ~shows & reflective & ~dis})
                footprint = (shows | dis | trail) if footprint is None else footprint | shows | dis | trail
                previous_ids = np.where(frame.gbuffer.coverage[0], frame.gbuffer.object_id[0], -1)
            reflection, reflective = refs[i]
            got = frame.reflection
            rows["all"].append(_rmse(got, reflection, reflective))
            for k in ("moved", "disoccluded", "rest"):
                rows[k].append(_rmse(got, reflection, masks[i][k]))
            rows["ghost"].append(ghost_energy(got, reflection, masks[i]["ghost"]))
            if i >= seq.still_from:
                after_stop[i] = got.copy()
            if images is not None:
                images.append(got.copy())
        out[name] = {k: np.asarray(v, np.float64) for k, v in rows.items()}
        out[name]["_after_stop"] = after_stop
        if images is not None:
            out["images"][name] = images
    # The motion's footprint, and each configuration's error there, moving and standing still.
    for name in names:
        settings = configurations[name].replace(motion_vectors=True)
        result = out[name]
        moving = np.full(n, np.nan)
        for i, got in result.pop("_after_stop").items():
            moving[i] = _rmse(got, refs[i][0], footprint & refs[i][1])
        still = moving.copy()  # each frame alone: standing still from the start changes nothing after the stop
        # The last frame of the motion already shows the final pose: its error had the scene stood still.
        k = seq.still_from - 1
        result["still at stop"] = result["all"][k]
        if settings.temporal_reflections or settings.denoise == "svgf":
            for i, frame in enumerate(renderer.render_sequence(seq.scene, seq.cameras, settings, times=[seq.times[-1]] * n)):
                if i >= seq.still_from:
                    still[i] = _rmse(frame.reflection, refs[i][0], footprint & refs[i][1])
                elif i == k:
                    result["still at stop"] = _rmse(frame.reflection, refs[i][0], refs[i][1])
        result["footprint"], result["still footprint"] = moving, still
        result["converged"] = float(np.nanmean(still[-LAG_TAIL:]))
        result["lag"] = lag(moving, result["converged"], seq.still_from)
    out["masks"] = {k: np.array([int(m[k].sum()) for m in masks]) for k in ("moved", "disoccluded", "rest", "ghost")}
    out["masks"]["footprint"] = np.full(n, int(footprint.sum()))
    if keep:
        out["images"]["reference"] = [r for r, _ in refs]
        out["images"]["ghost region"] = [m["ghost"] for m in masks]
    return out

def accumulation_bound(renderer, seq: MotionSequence, settings, *, frame: int | None = None, count: int | None = None,
                       reference_rays: int = 64) -> dict:
    """What any accumulation of `count` frames could reach at frame `frame` (default: the last
    frame of the motion, seq.still_from - 1, with `count` = still_from, the frames a history holds
    there): the per-pixel mean of `count` renders of that frame's pose and camera, each alone with
    its own rays (seeds settings.seed + frame + j, j = 0 the sequence's own frame), against the
    frame's converged reference. It is a temporal filter's best case: no motion to follow, no
    history rejected, every frame weighted alike (the temporal filter's running mean up to
    Settings.temporal_max_history frames is this mean on a still scene). Its error over the single
    frame's says how much of that error is noise the frames average out; the rest is the bias of
    screen space (what the rays cannot see, the lit G-buffer they fetch), which no accumulation of
    frames removes: a mirror's one ray per pixel is the same every frame, so there the bound is 1.
    Returns {"frame", "count", "single": rmse, "mean": rmse, "ratio": mean / single}."""
    k = seq.still_from - 1 if frame is None else int(frame)
    n = seq.still_from if count is None else int(count)
    if not 0 <= k < seq.frames() or n < 1:
        raise ValueError(f"accumulation_bound: frame {k} of {seq.frames()}, count {n}")
    base = settings.replace(temporal_reflections=False, denoise="none")
    seq.scene.set_time(seq.times[k])
    total, single, reflection, reflective = None, None, None, None
    for j in range(n):
        f = renderer.render(seq.scene, seq.cameras[k], settings=base.replace(seed=(settings.seed + k + j) % 2**31))
        if j == 0:
            ref = f.reference("converged", rays=reference_rays)
            reflection, reflective = ref.reflection.copy(), ref.reflective.copy()
            single = _rmse(f.reflection, reflection, reflective)
        image = np.asarray(f.reflection, np.float64)
        total = image if total is None else total + image
    mean = _rmse(total / n, reflection, reflective)
    return {"frame": k, "count": n, "single": single, "mean": mean, "ratio": mean / single if single > 0 else float("nan")}


__all__ = ["GHOST_BLUR", "GHOST_FRAMES", "GHOST_MARGIN", "LAG_TAIL", "LAG_TOLERANCE", "MOTION_SEQUENCES", "MotionSequence",
           "accumulation_bound", "box_filter", "box_over_glossy", "disoccluded", "ghost_energy", "gltf_stage", "history_configurations", "lag", "motion_configurations",
           "motion_study", "moving_camera_errors", "reflects_objects", "sphere_over_mirror"]
