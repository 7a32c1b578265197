"""Camera paths for sequences of frames (Renderer.render_sequence).

A ``CameraPath`` holds position and target keyframes and the number of frames the path is
rendered over; frame i sits at path parameter t = i / (frames - 1) in [0, 1], the keyframes
evenly spaced in t, and the camera's position and target are interpolated linearly between
the two keyframes around t (piecewise linear: constant speed between keyframes, no
overshoot). Field of view, up vector and clip planes are shared by every frame.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ._core import Camera


def _keys(name: str, values) -> np.ndarray:
    try:
        a = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"CameraPath.{name} must be a list of (x, y, z) points: {e}") from None
    if a.ndim == 1 and a.shape == (3,):
        a = a[None]
    if a.ndim != 2 or a.shape[1] != 3 or len(a) < 1:
        raise ValueError(f"CameraPath.{name} must be a list of (x, y, z) points, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError(f"CameraPath.{name} has a non-finite coordinate")
    return a


class CameraPath(Sequence):
    """Cameras along keyframed positions and targets, `frames` frames long.

    positions, targets: keyframes, (k, 3) each (one target: a fixed point every frame looks at;
    otherwise as many targets as positions). Indexing and iteration give ssrlab.Camera objects.
    """

    def __init__(self, positions, targets, frames: int, *, up=(0.0, 1.0, 0.0), fov_y: float = 60.0,
                 near: float = 0.1, far: float = 100.0):
        self.positions = _keys("positions", positions)
        self.targets = _keys("targets", targets)
        if len(self.targets) not in (1, len(self.positions)):
            raise ValueError(f"CameraPath.targets must hold 1 or {len(self.positions)} points (one per position), "
                             f"got {len(self.targets)}")
        if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 1:
            raise ValueError(f"CameraPath.frames must be an integer >= 1, got {frames!r}")
        self.frames = int(frames)
        self.up, self.fov_y, self.near, self.far = tuple(map(float, up)), float(fov_y), float(near), float(far)
        for i in range(self.frames):
            p, t = self._at(i)
            if np.linalg.norm(p - t) < 1e-9:
                raise ValueError(f"CameraPath: frame {i}'s position and target coincide")
        self[0]  # validates the camera parameters now

    def _interp(self, keys: np.ndarray, t: float) -> np.ndarray:
        if len(keys) == 1:
            return keys[0]
        x = t * (len(keys) - 1)
        k = min(int(np.floor(x)), len(keys) - 2)
        f = x - k
        return keys[k] * (1.0 - f) + keys[k + 1] * f

    def _at(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        t = i / (self.frames - 1) if self.frames > 1 else 0.0
        return self._interp(self.positions, t), self._interp(self.targets, t)

    def __len__(self) -> int:
        return self.frames

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self.frames))]
        if i < 0:
            i += self.frames
        if not 0 <= i < self.frames:
            raise IndexError(f"CameraPath has {self.frames} frames, no frame {i}")
        p, t = self._at(i)
        return Camera(position=tuple(map(float, p)), target=tuple(map(float, t)), up=self.up, fov_y=self.fov_y,
                      near=self.near, far=self.far)

    def __repr__(self) -> str:
        return f"CameraPath({len(self.positions)} keyframes, {self.frames} frames)"


# -- the moving-camera path (the study: ssrlab.lab.temporal) -------------------------------
# The documented path over scenes.hall(): the camera slides 3 m sideways (left to right) and 3 m
# forward down the nave while dipping 0.2 m, always looking at the end wall; the polished floor
# (roughness 0.15) reflects the columns and pews.
HALL_PATH_POSITIONS = [(-1.5, 1.8, 3.0), (1.5, 1.6, 0.0)]
HALL_PATH_TARGETS = [(0.0, 2.0, -20.0)]


def hall_path(frames: int) -> CameraPath:
    return CameraPath(HALL_PATH_POSITIONS, HALL_PATH_TARGETS, frames)
