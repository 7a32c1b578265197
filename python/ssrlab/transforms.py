"""4x4 transforms as float32 numpy arrays in the usual mathematical layout: ``m @ p`` maps
the column vector ``p = (x, y, z, 1)``; compose right to left (``translate @ rotate @ scale``
scales first)."""

from __future__ import annotations

import numpy as np


def identity() -> np.ndarray:
    return np.eye(4, dtype=np.float32)


def translate(offset) -> np.ndarray:
    m = identity()
    m[:3, 3] = np.asarray(offset, dtype=np.float32)
    return m


def scale(factors) -> np.ndarray:
    f = np.broadcast_to(np.asarray(factors, dtype=np.float32), (3,))
    return np.diag([f[0], f[1], f[2], 1.0]).astype(np.float32)


def rotate(axis, degrees: float) -> np.ndarray:
    """Rotation by `degrees` about `axis` (right-handed: counter-clockwise looking down the axis)."""
    a = np.asarray(axis, dtype=np.float64)
    n = np.linalg.norm(a)
    if n == 0:
        raise ValueError("rotate: axis must be non-zero")
    x, y, z = a / n
    t = np.radians(degrees)
    c, s, C = np.cos(t), np.sin(t), 1 - np.cos(t)
    m = identity()
    m[:3, :3] = [
        [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
        [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
        [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
    ]
    return m


def quaternion(axis, degrees: float) -> np.ndarray:
    """The unit quaternion (x, y, z, w), glTF's order, of the rotation by `degrees` about `axis`
    (the same rotation as rotate(axis, degrees)); for ssrlab.Keyframes and glTF rotations."""
    a = np.asarray(axis, dtype=np.float64)
    n = np.linalg.norm(a)
    if n == 0:
        raise ValueError("quaternion: axis must be non-zero")
    h = np.radians(degrees) / 2
    return np.concatenate([a / n * np.sin(h), [np.cos(h)]])


def align_y(normal) -> np.ndarray:
    """A rotation taking +y to `normal` (for planes)."""
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    y = np.array([0.0, 1.0, 0.0])
    axis = np.cross(y, n)
    s = np.linalg.norm(axis)
    if s < 1e-9:
        return identity() if n[1] > 0 else rotate((1, 0, 0), 180.0)
    return rotate(axis, np.degrees(np.arctan2(s, float(np.dot(y, n)))))


def transform_points(m: np.ndarray, points) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    h = np.concatenate([p, np.ones(p.shape[:-1] + (1,))], axis=-1)
    out = h @ np.asarray(m, dtype=np.float64).T
    return out[..., :3] / out[..., 3:4]
