"""The page's camera as an ssrlab.Camera and back, and a frame as the Python that reproduces it.

The browser's camera (viser) is a position and a rotation `wxyz` from camera to world in OpenCV's
convention (x right, y down, z forward) with a vertical field of view in radians; ssrlab's is a
position, a target, an up vector and a vertical field of view in degrees, looking down -z with
y up (OpenGL). The forward axis is the rotation's third column, up the negated second.
"""

from __future__ import annotations

import math

import numpy as np

from .._core import Camera


def _rotation(wxyz) -> np.ndarray:
    w, x, y, z = (float(c) for c in wxyz)
    n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def from_page(position, wxyz, fov_radians: float, look_at, near: float, far: float) -> Camera:
    """The ssrlab.Camera of the page's camera; the target lies on the view axis at the orbit's distance
    (the point the page orbits about), so that the camera's own target stays meaningful."""
    p = np.asarray(position, np.float64)
    r = _rotation(wxyz)
    forward, up = r[:, 2], -r[:, 1]
    distance = float(np.linalg.norm(np.asarray(look_at, np.float64) - p))
    target = p + forward * (distance if distance > 1e-6 else 1.0)
    fov = min(max(math.degrees(float(fov_radians)), 1e-3), 179.0 - 1e-3)
    return Camera(position=tuple(map(float, p)), target=tuple(map(float, target)), up=tuple(map(float, up)),
                  fov_y=fov, near=float(near), far=float(far))


def to_page(client_camera, camera: Camera) -> None:
    """Points a page's camera (viser's CameraHandle) as `camera` looks."""
    with client_camera.client.atomic():
        client_camera.fov = math.radians(camera.fov_y)
        client_camera.position = tuple(camera.position)
        client_camera.up_direction = tuple(camera.up)
        client_camera.look_at = tuple(camera.target)


def camera_source(camera: Camera) -> str:
    """Python that builds `camera` exactly (float reprs round-trip)."""
    return (f"ssrlab.Camera(position={tuple(camera.position)!r}, target={tuple(camera.target)!r}, "
            f"up={tuple(camera.up)!r}, fov_y={camera.fov_y!r}, near={camera.near!r}, far={camera.far!r})")


def snippet(scene_source: str, camera: Camera, settings, device: str, time: float | None = None,
            user_passes: str = "") -> str:
    """A script that renders the frame again with Renderer.render: the scene (`scene_source`, an
    expression), the camera, the settings that differ from the defaults and the device; run on the
    same device it gives the same pixels."""
    lines = ["import ssrlab", "", f"scene = {scene_source}"]
    if time is not None:
        lines.append(f"scene.set_time({time!r})")
    lines += [f"camera = {camera_source(camera)}",
              f"settings = ssrlab.Settings(**{settings.changed()!r})",
              f"renderer = ssrlab.Renderer({device!r})"]
    if user_passes:
        lines.append(user_passes)
    lines.append("frame = renderer.render(scene, camera, settings)")
    return "\n".join(lines) + "\n"
