"""Things that move: glTF animations, keyframes and functions of time, for objects and lights.

A scene has a time, in seconds. ``Scene.set_time(t)`` poses everything that moves at ``t``:
the glTF animations being played (``Scene.play``) and the motions given from Python
(``Scene.animate``); ``Renderer.render_sequence(scene, cameras, times=...)`` sets each frame's
time before it renders it. Moving an object goes through ``Scene.set_object_transform`` and
moving a light through ``Scene.set_light``, exactly as if the same values were set by hand.

Sampling is the glTF 2.0 specification's (Appendix C), for glTF files and ``Keyframes`` alike,
by the same native code: STEP holds a keyframe's value until the next; LINEAR interpolates
translation and scale linearly and rotations by spherical linear interpolation along the
shorter arc; CUBICSPLINE evaluates the cubic Hermite spline through the keyframes' values with
their out- and in-tangents scaled by the keyframe interval, and normalises rotations after it.

Time outside the keyframes: *clamped* by default: before the first keyframe a channel holds its
first value, after the last its last (what glTF specifies for each channel). With ``loop=True``
the clip repeats: t is wrapped by whole durations into (0, duration] (a multiple of the duration
shows the clip's end, t = 0 its start; negative t counts back from the end). glTF says nothing
about looping; most viewers loop, ssrlab asks for it, so that a sequence's last frame is the
clip's end unless told otherwise.
"""

from __future__ import annotations

import math

import numpy as np

from . import _core
from ._core import Light

# The fields a light motion's function may set, by name.
LIGHT_FIELDS = ("position", "direction", "color", "intensity", "inner_cone", "outer_cone", "range", "cast_shadow")


def _seconds(t, what: str) -> float:
    if isinstance(t, bool) or not isinstance(t, (int, float, np.integer, np.floating)):
        raise TypeError(f"{what} must be a number of seconds, got {type(t).__name__}")
    t = float(t)
    if not math.isfinite(t):
        raise ValueError(f"{what} must be finite, got {t}")
    return t


def seconds_array(values, what: str) -> np.ndarray:
    """A non-empty 1-D float64 array of finite seconds, or a ValueError naming `what`."""
    try:
        a = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{what} must be a list of seconds: {e}") from None
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"{what} must be a non-empty 1-D list of seconds, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"{what} must be finite, value {int(np.argmin(np.isfinite(a)))} is not")
    return a


def clip_time(t: float, duration: float, loop: bool) -> float:
    """The time inside a clip of `duration` seconds that scene time `t` shows: `t` itself when
    clamped (the channels clamp), wrapped into (0, duration] when looping (see the module)."""
    if not loop or duration <= 0.0:
        return t
    r = math.fmod(t, duration)  # exact, with the sign of t
    if r < 0.0:
        r += duration
    return duration if r == 0.0 and t > 0.0 else r + 0.0  # + 0.0: no -0.0


class Keyframes:
    """Keyframed motion, sampled as glTF samples its animations (see the module).

    times: (k,) seconds, >= 0 and strictly increasing. Each channel is optional:
    translation (k, 3), rotation (k, 4) unit quaternions (x, y, z, w) as glTF stores them (see
    ssrlab.transforms.quaternion), scale (k, 3). interpolation: "linear", "step" or
    "cubicspline"; a cubic spline's channels are (k, 3, c): each keyframe's in-tangent, value
    and out-tangent (glTF's order), tangents in units per second.

    An object's transform at t is ``matrix(t)`` = translate @ rotate @ scale (glTF's node order;
    a channel not given is the identity: give the scale of a scaled object). A light takes its
    position from the translation and its direction from the rotation applied to (0, 0, -1) (a
    KHR_lights_punctual light's frame); a channel not given leaves that field as it is.
    """

    def __init__(self, times, *, translation=None, rotation=None, scale=None, interpolation: str = "linear"):
        t = seconds_array(times, "Keyframes.times")
        if translation is None and rotation is None and scale is None:
            raise ValueError("Keyframes needs at least one of translation, rotation, scale")
        if not isinstance(interpolation, str):
            raise TypeError(f"Keyframes.interpolation must be a string, got {type(interpolation).__name__}")
        self.interpolation = interpolation.lower()
        self._native = _core._Keyframes([float(x) for x in t], *(None if v is None else np.asarray(v, np.float32)
                                                                  for v in (translation, rotation, scale)),
                                        self.interpolation)
        self.times = t
        self.channels = tuple(name for name, v in (("translation", translation), ("rotation", rotation),
                                                   ("scale", scale)) if v is not None)

    @property
    def duration(self) -> float:
        """The last keyframe's time, seconds."""
        return float(self.times[-1])

    def sample(self, t: float) -> dict[str, np.ndarray]:
        """The channels' values at t (seconds), by name: translation (3,), rotation (4,) x y z w,
        scale (3,), float64."""
        values = self._native.sample(_seconds(t, "Keyframes.sample: t"))
        return {name: np.asarray(v) for name, v in zip(("translation", "rotation", "scale"), values) if v}

    def matrix(self, t: float) -> np.ndarray:
        """translate @ rotate @ scale at t, a float32 4x4 (a channel not given: identity)."""
        return np.asarray(self._native.matrix(_seconds(t, "Keyframes.matrix: t")), dtype=np.float32)

    def __repr__(self) -> str:
        return (f"Keyframes({len(self.times)} keys, {self.times[0]:g}-{self.times[-1]:g} s, "
                f"{self.interpolation}, {', '.join(self.channels)})")


def rotate_direction(q, v=(0.0, 0.0, -1.0)) -> np.ndarray:
    """The unit quaternion q (x, y, z, w) applied to the vector v."""
    x, y, z, w = (float(c) for c in q)
    u = np.array([x, y, z])
    v = np.asarray(v, dtype=np.float64)
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


class Motion:
    """One target's motion given from Python: Keyframes or a function of time."""

    def __init__(self, kind: str, index: int, motion, loop: bool):
        self.kind, self.index, self.motion, self.loop = kind, index, motion, bool(loop)
        self.what = f"Scene.animate: {kind} {index}'s motion"
        if isinstance(motion, Keyframes):
            if kind == "light" and "scale" in motion.channels:
                raise ValueError(f"{self.what}: a light has no scale; give Keyframes translation (its position) "
                                 "and rotation (its direction)")
        elif not callable(motion):
            raise TypeError(f"{self.what} must be ssrlab.Keyframes or a function of time (seconds), "
                            f"got {type(motion).__name__}")
        elif loop:
            raise ValueError(f"{self.what}: loop applies to Keyframes; a function of time is given t as it is")

    def object_transform(self, t: float) -> np.ndarray:
        if isinstance(self.motion, Keyframes):
            return self.motion.matrix(clip_time(t, self.motion.duration, self.loop))
        m = self.motion(t)
        try:
            a = np.asarray(m, dtype=np.float32)
        except (TypeError, ValueError) as e:
            raise ValueError(f"{self.what} at t = {t:g} s returned no 4x4 matrix: {e}") from None
        if a.shape != (4, 4) or not np.all(np.isfinite(a)):
            raise ValueError(f"{self.what} at t = {t:g} s must return a finite 4x4 matrix, got "
                             f"{'shape ' + str(a.shape) if a.shape != (4, 4) else 'NaN or Inf'}")
        return a

    def light(self, base: Light, t: float) -> Light:
        if isinstance(self.motion, Keyframes):
            values = self.motion.sample(clip_time(t, self.motion.duration, self.loop))
            if "translation" in values:
                base.position = tuple(values["translation"])
            if "rotation" in values:
                base.direction = tuple(rotate_direction(values["rotation"]))
            return base
        out = self.motion(t)
        if isinstance(out, Light):
            return out
        if not isinstance(out, dict):
            raise TypeError(f"{self.what} at t = {t:g} s must return an ssrlab.Light or a dict of its fields "
                            f"({', '.join(LIGHT_FIELDS)}), got {type(out).__name__}")
        for key, value in out.items():
            if key not in LIGHT_FIELDS:
                raise ValueError(f"{self.what} at t = {t:g} s returned field {key!r}; a light's fields are "
                                 f"{', '.join(LIGHT_FIELDS)}")
            setattr(base, key, value)
        return base


class AnimationState:
    """What a scene plays and the time it shows (kept by ssrlab.Scene)."""

    def __init__(self):
        self.time = 0.0
        self.playing: list[tuple[int, bool]] = []  # (glTF animation index, loop)
        self.motions: dict[tuple[str, int], Motion] = {}

    def copy(self) -> "AnimationState":
        out = AnimationState()
        out.time, out.playing, out.motions = self.time, list(self.playing), dict(self.motions)
        return out


def resolve_animations(scene, names) -> list[int]:
    """Animation indices from names or indices (all of the scene's when `names` is empty)."""
    animations = scene.animations
    if not names:
        if not animations:
            raise ValueError(f"Scene.play: scene {scene.name!r} has no animations")
        return list(range(len(animations)))
    out = []
    for a in names:
        if isinstance(a, bool):
            raise TypeError("Scene.play: an animation is a name or an index, got a bool")
        if isinstance(a, (int, np.integer)):
            if not 0 <= int(a) < len(animations):
                raise IndexError(f"Scene.play: animation index {int(a)} is out of range (the scene has "
                                 f"{len(animations)} animations)")
            out.append(int(a))
        elif isinstance(a, str):
            hits = [i for i, x in enumerate(animations) if x.name == a]
            if not hits:
                names_known = ", ".join(repr(x.name) for x in animations) or "none"
                raise KeyError(f"Scene.play: no animation named {a!r} (the scene's: {names_known})")
            if len(hits) > 1:
                raise KeyError(f"Scene.play: animations {hits} are all named {a!r}; pass an index")
            out.append(hits[0])
        else:
            raise TypeError(f"Scene.play: an animation is a name or an index, got {type(a).__name__}")
    return out


def pose(scene, state: AnimationState, t: float) -> None:
    """Sets everything that moves to its state at t, through set_object_transform and set_light."""
    if state.playing:
        durations = [a.duration for a in scene.animations]
        played = [(i, clip_time(t, durations[i], loop)) for i, loop in state.playing]
        objects, lights = scene._pose(played)
        for index, matrix in objects:
            scene.set_object_transform(index, matrix)
        for index, light in lights:
            scene.set_light(index, light)
    for motion in state.motions.values():
        if motion.kind == "object":
            scene.set_object_transform(motion.index, motion.object_transform(t))
        else:
            scene.set_light(motion.index, motion.light(scene.lights[motion.index], t))
    state.time = t

__all__ = ["Keyframes", "clip_time"]
