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

    def to_dict(self) -> dict:
        """The path as plain data (what save() writes)."""
        return {"positions": self.positions.tolist(), "targets": self.targets.tolist(), "frames": self.frames,
                "up": list(self.up), "fov_y": self.fov_y, "near": self.near, "far": self.far}

    def save(self, path, *, overwrite: bool = False):
        """Writes the path as JSON (CameraPath.load reads it back); refuses to replace a file unless
        overwrite=True."""
        import json
        from pathlib import Path

        from .io import atomic_write

        target = Path(path)
        if target.exists() and not overwrite:
            raise FileExistsError(f"CameraPath.save: {target} exists (overwrite=True replaces it)")
        text = json.dumps({"ssrlab": "camera_path", **self.to_dict()}, indent=1)
        atomic_write(target, lambda tmp: tmp.write_text(text))  # an OutputError naming `target` on failure
        return target

    @classmethod
    def load(cls, path) -> "CameraPath":
        """A path written by save() (or the viewer's 'record camera path'); ValueError naming the
        file where it is not one."""
        import json
        from pathlib import Path

        path = Path(path)
        try:
            d = json.loads(path.read_text())
        except ValueError as e:
            raise ValueError(f"{path}: not a camera path file (JSON: {e})") from None
        if not isinstance(d, dict) or d.get("ssrlab") != "camera_path":
            raise ValueError(f"{path}: not a camera path file (no \"ssrlab\": \"camera_path\" entry)")
        try:
            return cls(d["positions"], d["targets"], d["frames"], up=d.get("up", (0.0, 1.0, 0.0)),
                       fov_y=d.get("fov_y", 60.0), near=d.get("near", 0.1), far=d.get("far", 100.0))
        except (KeyError, TypeError, ValueError) as e:
            raise ValueError(f"{path}: {e}") from None

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
