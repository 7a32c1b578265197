"""Ground truth for screen-space reflections.

Three references, each an image of the same frame that SSR approximates:

``converged``  reflection rays traced against the scene's real triangles (a BVH, watertight
               ray-triangle test) and shaded by the same GLSL lighting as the G-buffer:
               many rays per pixel (default 256, 1 for mirrors), no screen-space limits.
``per_ray``    the very rays an SSR frame traced, against the real triangles: per-ray
               hit/miss and hit-position truth (``Frame.reference("per_ray")``).
``thesis``     the thesis's own ground truth (seed 000, 3.1.2): screen-space tracing with
               32 rays per pixel, 16 layers and stride 1.

``reference_image`` returns a converged or thesis reference for (scene, camera, settings),
cached on disk (``$SSRLAB_CACHE``, default ``~/.cache/ssrlab``) under a key made of the
scene's content hash, the camera, and the settings that change the reference.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from .settings import Settings

KINDS = ("converged", "thesis")
THESIS_GROUND_TRUTH = dict(rays_per_pixel=32, layers=16, stride=1.0, method="linear", downscale=1)
DEFAULT_ROUGH_RAYS = 256

# Settings that change a converged reference (the tracer's own parameters do not).
_CONVERGED_KEY_FIELDS = ("width", "height", "depth_mode", "backface_culling", "shadow_map_size",
                         "shadow_normal_offset", "shadow_pcf_radius", "roughness_cutoff", "origin_bias",
                         "max_distance", "composite")


def thesis_ground_truth_settings(settings: Settings) -> Settings:
    """`settings` with the thesis's ground-truth tracing: 32 rays per pixel, 16 layers, stride 1."""
    return settings.replace(**THESIS_GROUND_TRUTH)


@dataclasses.dataclass
class ReferenceImage:
    kind: str
    color: np.ndarray       # (H, W, 3) final image with the reference reflection
    reflection: np.ndarray  # (H, W, 3) reference reflection c_r (0 where a pixel does not reflect)
    reflective: np.ndarray  # (H, W) bool: pixels that reflect (layer 0 covered, reflectivity > 0, below the cutoff)
    rays_per_pixel: int

    def save(self, path: Path) -> None:
        np.savez_compressed(path, kind=self.kind, color=self.color, reflection=self.reflection,
                            reflective=self.reflective, rays_per_pixel=self.rays_per_pixel)

    @classmethod
    def load(cls, path: Path) -> "ReferenceImage":
        with np.load(path) as z:
            return cls(str(z["kind"]), z["color"], z["reflection"], z["reflective"], int(z["rays_per_pixel"]))


def cache_dir(folder=None) -> Path:
    if folder is not None:
        return Path(folder)
    return Path(os.environ.get("SSRLAB_CACHE", Path.home() / ".cache" / "ssrlab")) / "references"


def _camera_key(camera) -> list:
    return [list(camera.position), list(camera.target), list(camera.up), camera.fov_y, camera.near, camera.far]


def cache_key(kind: str, scene, camera, settings: Settings, rays: int | None, seed: int) -> str:
    from . import __version__

    if kind == "converged":
        fields = {k: getattr(settings, k) for k in _CONVERGED_KEY_FIELDS}
    else:
        fields = thesis_ground_truth_settings(settings).to_dict()
    payload = {"kind": kind, "scene": scene.content_hash(), "camera": _camera_key(camera), "settings": fields,
               "rays": rays, "seed": seed, "version": __version__}
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:32]


def reflective_mask(frame) -> np.ndarray:
    """Pixels that reflect: layer 0 covered, reflectivity > 0 and roughness within the cutoff."""
    g = frame.gbuffer
    return g.coverage[0] & (g.reflectivity[0] > 0) & (g.roughness[0] <= frame.settings.roughness_cutoff)


def reference_image(renderer, scene, camera=None, settings: Settings | None = None, *, kind: str = "converged",
                    rays: int | None = None, seed: int = 0, cache: bool = True,
                    folder=None) -> ReferenceImage:
    """The reference image of `kind` for this scene, camera and settings (cached on disk)."""
    if kind not in KINDS:
        raise ValueError(f"reference kind must be one of {', '.join(KINDS)}, got {kind!r}")
    settings = settings if settings is not None else Settings()
    camera = camera if camera is not None else scene.camera
    if camera is None:
        raise ValueError("reference_image: the scene has no default camera; pass camera=")
    path = cache_dir(folder) / f"{cache_key(kind, scene, camera, settings, rays, seed)}.npz"
    if cache and path.is_file():
        try:
            return ReferenceImage.load(path)
        except (OSError, ValueError, KeyError):
            pass  # a damaged cache entry is recomputed
    if kind == "thesis":
        frame = renderer.render(scene, camera, thesis_ground_truth_settings(settings).replace(seed=seed))
        ref = ReferenceImage("thesis", frame.color.copy(), frame.reflection.copy(), reflective_mask(frame),
                             THESIS_GROUND_TRUTH["rays_per_pixel"])
    else:
        frame = renderer.render(scene, camera, settings.replace(method="off"))
        converged = frame.reference("converged", rays=rays, seed=seed)
        ref = ReferenceImage("converged", converged.color, converged.reflection, converged.reflective,
                             converged.rays_per_pixel)
    if cache:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".ref-", suffix=".npz", dir=path.parent)
        os.close(fd)
        try:
            ref.save(Path(tmp))
            os.replace(tmp, path)  # atomic: concurrent sweep workers may compute the same entry
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    return ref
