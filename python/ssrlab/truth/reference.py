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
import functools
import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from .. import _core
from .._package import __version__, shader_dir
from ..progress import progress_callback  # noqa: F401  (ssrlab.reference.progress_callback)
from ..settings import Settings

KINDS = ("converged", "thesis")
THESIS_GROUND_TRUTH = dict(rays_per_pixel=32, layers=16, stride=1.0, method="linear", downscale=1)
DEFAULT_ROUGH_RAYS = 256

# Settings that change a converged reference (the tracer's own parameters do not): those
# cpp/render/settings_fields.def flags kReference.
_CONVERGED_KEY_FIELDS = tuple(f.name for f in dataclasses.fields(Settings) if f.metadata["reference"])


def thesis_ground_truth_settings(settings: Settings) -> Settings:
    """`settings` with the thesis's ground-truth tracing: 32 rays per pixel, 16 layers, stride 1."""
    return settings.replace(**THESIS_GROUND_TRUTH, user_passes=(), user_params={}, user_modules=())


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

    def __repr__(self) -> str:
        h, w = self.reflective.shape
        return (f"<ReferenceImage {self.kind} {w}x{h}, {self.rays_per_pixel} ray(s) per pixel, "
                f"{int(self.reflective.sum())} reflective pixel(s)>")



def cache_dir(folder=None) -> Path:
    if folder is not None:
        return Path(folder)
    return Path(os.environ.get("SSRLAB_CACHE", Path.home() / ".cache" / "ssrlab")) / "references"


def _camera_key(camera) -> list:
    return [list(camera.position), list(camera.target), list(camera.up), camera.fov_y, camera.near, camera.far]


@functools.lru_cache(maxsize=None)
def shader_sources_hash() -> str:
    """A digest of every GLSL file the package renders with: a reference computed by other
    shader code is another reference."""
    h = hashlib.sha256()
    root = shader_dir()
    for f in sorted(p for p in root.rglob("*") if p.is_file()):
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    # The settings' uniform block, the records shared with the host and the blocks' binding points
    # are generated (from cpp/render/settings_fields.def, gpu_structs.def and buffer_bindings.def),
    # not files.
    h.update(_core.ssr_settings_glsl().encode())
    h.update(_core.buffer_bindings_glsl().encode())
    for name, text in sorted(_core.gpu_struct_glsl().items()):
        h.update(name.encode())
        h.update(text.encode())
    return h.hexdigest()[:16]


def reference_fields(kind: str, settings: Settings) -> dict:
    """The settings a reference of `kind` depends on (the rest of `settings` does not change it)."""
    if kind == "converged":
        return {k: getattr(settings, k) for k in _CONVERGED_KEY_FIELDS}
    return thesis_ground_truth_settings(settings).to_dict()


def cache_key(kind: str, scene, camera, settings: Settings, rays: int | None, seed: int,
              shadows: str = "traced", viewer: str = "ray") -> str:
    """The reference's content address: a digest of the scene's content, the camera, the
    settings that change it, its rays and seed, and the code (version and shader sources).
    Two machines asked for the same reference compute the same key, so a store on a shared
    path serves a whole cluster."""
    fields = reference_fields(kind, settings)
    payload = {"kind": kind, "scene": scene.content_hash(), "camera": _camera_key(camera), "settings": fields,
               "rays": rays, "seed": seed, "version": __version__, "shaders": shader_sources_hash()}
    if kind == "converged":
        payload["shadows"] = shadows
        payload["viewer"] = viewer
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:32]


def reflective_mask(frame) -> np.ndarray:
    """Pixels that reflect: layer 0 covered with reflectivity > 0 (SSR's roughness cutoff is an
    approximation of the reflection, not a reason for a pixel not to reflect)."""
    g = frame.gbuffer
    return g.coverage[0] & (g.reflectivity[0] > 0)


class _FrameResult:
    """A result computed into textures a frame holds, which a later call on the same frame (another
    reference) overwrites. The frame keeps a weak list of its live results and, before any such
    call, asks each to copy what it reads into arrays of its own (``_keep``): a result keeps the
    values it computed, whatever is computed after it, and costs no read-back while it is the
    newest one."""

    TEXTURES: tuple[str, ...] = ()

    def __init__(self, frame):
        self._frame = frame
        self._owned: dict[str, np.ndarray] | None = None
        frame._results.add(self)

    def _keep(self) -> None:
        """Copies this result's textures out of the frame (once), before the frame overwrites them."""
        if self._owned is None and not self._frame.released:
            self._owned = {name: self._frame.read(name) for name in self.TEXTURES}

    def _read(self, name: str) -> np.ndarray:
        if self._owned is not None:
            return self._owned[name]
        if self._frame.released:
            raise ValueError(f"cannot read this {type(self).__name__}: its frame was released (Frame.release() or "
                             "the end of its with block) before the result was read; read it before releasing")
        return self._frame.read(name)


class ConvergedReference(_FrameResult):
    """The converged reference of a frame: `rays_per_pixel` rays per reflective pixel (one for
    mirrors) traced against the triangles and shaded like the G-buffer."""

    kind = "converged"
    TEXTURES = ("reference.reflection", "reference.color")

    def __init__(self, frame, rays_per_pixel: int, timings: dict):
        super().__init__(frame)
        self.rays_per_pixel = rays_per_pixel
        self.timings = timings  # milliseconds of the reference passes (and the wavefront's stages)
        self.rays_traced = None  # rays Embree traced (the wavefront only)

    @property
    def reflection(self) -> np.ndarray:
        """(H, W, 3) the true reflection c_r (0 where a pixel does not reflect)."""
        return self._read("reference.reflection")[0, :, :, :3]

    @property
    def color(self) -> np.ndarray:
        """(H, W, 3) the frame's final image with the true reflection, composited like the frame."""
        return self._read("reference.color")[0, :, :, :3]

    @property
    def reflective(self) -> np.ndarray:
        return reflective_mask(self._frame)

    def __repr__(self) -> str:
        s = self._frame.settings
        return f"<ConvergedReference {s.width}x{s.height}, {self.rays_per_pixel} ray(s) per reflective pixel>"




# Relative view-depth tolerance when matching a true hit to a G-buffer sample (in_gbuffer).
IN_GBUFFER_DEPTH_TOLERANCE = 1e-3


class PerRayReference(_FrameResult):
    """The rays an SSR frame traced, each traced again against the triangles: (R, h, w) arrays at
    the trace resolution, like Frame.rays.

    hit         the ray truly hits a surface (within max_distance)
    object      index of the object hit, -1 for a miss
    t           distance to the hit
    position    (R, h, w, 3) view-space hit point
    hit_pixel   (R, h, w, 2) where the hit point projects (x = column, y = row from the top)
    on_screen   the hit point projects inside the image, in front of the camera
    radiance    (R, h, w, 3) what the ray truly brings back (shaded hit or environment)
    in_gbuffer  (R, h, w) the G-buffer layer (0-based) holding the true hit at its pixel, -1 if
                none does: what screen space could possibly find
    """

    kind = "per_ray"
    TEXTURES = ("reference.hit", "reference.position", "reference.radiance")

    def __init__(self, frame, timings: dict):
        super().__init__(frame)
        self.timings = timings

    def _hit(self):
        return self._read("reference.hit")

    @property
    def hit(self) -> np.ndarray:
        return self._hit()[..., 2] > 0.5

    @property
    def object(self) -> np.ndarray:
        return np.rint(self._hit()[..., 2]).astype(np.int32) - 1

    @property
    def t(self) -> np.ndarray:
        return self._hit()[..., 3]

    @property
    def hit_pixel(self) -> np.ndarray:
        h = self._hit()
        px = np.stack([h[..., 0], self._frame.settings.height - h[..., 1]], -1).astype(np.float32)
        px[~self.hit] = 0.0
        return px

    @property
    def position(self) -> np.ndarray:
        return self._read("reference.position")[..., :3]

    @property
    def on_screen(self) -> np.ndarray:
        return self.hit & (self._read("reference.position")[..., 3] > 0.5)

    @property
    def radiance(self) -> np.ndarray:
        return self._read("reference.radiance")[..., :3]

    @property
    def in_gbuffer(self) -> np.ndarray:
        """Layer holding the true hit at its pixel: the same object, at the same view depth (within
        IN_GBUFFER_DEPTH_TOLERANCE relative plus two pixel footprints), or -1."""
        depth_tolerance = IN_GBUFFER_DEPTH_TOLERANCE
        g = self._frame.gbuffer
        layers = np.full(self.hit.shape, -1, np.int32)
        m = self.on_screen
        px = np.floor(self.hit_pixel[m]).astype(np.int64)
        s = self._frame.settings
        row = np.clip(px[:, 1], 0, s.height - 1)
        col = np.clip(px[:, 0], 0, s.width - 1)
        depth = -self.position[m][:, 2]
        obj = self.object[m]
        found = np.full(len(depth), -1, np.int32)
        for k in range(g.layers - 1, -1, -1):  # the front-most match wins
            same = (g.object_id[k][row, col] == obj) & g.coverage[k][row, col] & \
                   (np.abs(g.depth[k][row, col] - depth) <= depth_tolerance * depth + 2 * self._pixel_depth_span(depth))
            found = np.where(same, k, found)
        layers[m] = found
        return layers

    def __repr__(self) -> str:
        n, h, w = self.hit.shape
        traced = np.broadcast_to(self._frame.rays.traced, self.hit.shape)
        share = f", {100 * self.hit[traced].mean():.1f} % of the traced rays truly hit" if traced.any() else ""
        return f"<PerRayReference {n} ray(s) per pixel at {w}x{h}{share}>"


    def _pixel_depth_span(self, depth: np.ndarray) -> np.ndarray:
        """World size of one pixel at view depth `depth`: the G-buffer stores a pixel's centre while
        the true hit lies anywhere in it, so a tilted surface's depth differs by about this much."""
        P = self._frame.projection_matrix
        return depth * 2.0 / (P[1, 1] * self._frame.settings.height)


def ssr_found(frame, truth: PerRayReference, tolerance_px: float = 1.0) -> np.ndarray:
    """(R, h, w) bool: the SSR ray hit the surface the reference ray hits: the same object, or a
    point within `tolerance_px` pixels of the true hit on screen and within the frame's
    thickness in depth (rays can land on a neighbouring object across an edge)."""
    rays, g = frame.rays, frame.gbuffer
    found = np.zeros(rays.hit.shape, bool)
    both = rays.hit & truth.hit
    if not both.any():
        return found
    layer = np.clip(rays.hit_layer[both] - 1, 0, g.layers - 1)
    px = np.floor(rays.hit_pixel[both]).astype(np.int64)
    s = frame.settings
    row, col = np.clip(px[:, 1], 0, s.height - 1), np.clip(px[:, 0], 0, s.width - 1)
    same_object = g.object_id[layer, row, col] == truth.object[both]
    close = (np.linalg.norm(rays.hit_pixel[both] - truth.hit_pixel[both], axis=-1) <= tolerance_px) & \
        (np.abs(g.depth[layer, row, col] + truth.position[both][:, 2]) <= s.thickness)
    found[both] = same_object | close
    return found


def coverage(frame, truth: PerRayReference | None = None, *, tolerance_px: float = 1.0) -> float:
    """Share of the rays that truly hit a surface for which SSR found that surface (1 when no
    ray truly hits anything)."""
    truth = truth if truth is not None else frame.reference("per_ray")
    traced = np.broadcast_to(frame.rays.traced, truth.hit.shape) & (frame.rays.weight > 0)
    real = truth.hit & traced
    if not real.any():
        return 1.0
    return float(ssr_found(frame, truth, tolerance_px)[real].mean())


def hit_position_error(frame, truth: PerRayReference | None = None) -> np.ndarray:
    """Screen distance in pixels between SSR's hit and the true hit, for the rays where both hit
    and the true hit is on screen (a flat array)."""
    truth = truth if truth is not None else frame.reference("per_ray")
    m = frame.rays.hit & truth.on_screen
    return np.linalg.norm(frame.rays.hit_pixel[m] - truth.hit_pixel[m], axis=-1)


def wrong_hits(frame, truth: PerRayReference | None = None, *, tolerance_px: float = 2.0) -> dict:
    """How often SSR's accepted hits are wrong: of the rays this frame's screen-space
    tracer kept a hit for (rays.hit after any confidence test; a rejected hit is a miss there),
    the share whose true hit (the per-ray reference) is another surface or elsewhere: the true
    ray misses, or hits an object other than the one the G-buffer shows at SSR's hit pixel, or
    projects more than `tolerance_px` pixels from SSR's hit. Returns {'accepted': rays with a
    kept hit, 'wrong': of those, wrong, 'wrong_share': wrong / accepted (0 without any),
    'wrong_of_rays': wrong / rays traced}."""
    truth = truth if truth is not None else frame.reference("per_ray")
    rays, g, s = frame.rays, frame.gbuffer, frame.settings
    traced = np.broadcast_to(rays.traced, truth.hit.shape) & (rays.weight > 0)
    accepted = rays.hit & traced
    right = np.zeros(accepted.shape, bool)
    both = accepted & truth.hit & truth.on_screen
    if both.any():
        layer = np.clip(rays.hit_layer[both] - 1, 0, g.layers - 1)
        px = np.floor(rays.hit_pixel[both]).astype(np.int64)
        row, col = np.clip(px[:, 1], 0, s.height - 1), np.clip(px[:, 0], 0, s.width - 1)
        same_object = g.object_id[layer, row, col] == truth.object[both]
        close = np.linalg.norm(rays.hit_pixel[both] - truth.hit_pixel[both], axis=-1) <= tolerance_px
        right[both] = same_object & close
    wrong = accepted & ~right
    n_acc, n_wrong, n = int(accepted.sum()), int(wrong.sum()), int(traced.sum())
    return {"accepted": n_acc, "wrong": n_wrong, "wrong_share": n_wrong / n_acc if n_acc else 0.0,
            "wrong_of_rays": n_wrong / n if n else 0.0}


def reference_path(scene, camera=None, settings: Settings | None = None, *, kind: str = "converged",
                   rays: int | None = None, seed: int = 0, folder=None, shadows: str = "traced",
                   viewer: str = "ray") -> Path:
    """Where reference_image keeps (or would keep) this reference in the store `folder`."""
    settings = settings if settings is not None else Settings()
    camera = camera if camera is not None else scene.camera
    return cache_dir(folder) / f"{cache_key(kind, scene, camera, settings, rays, seed, shadows, viewer)}.npz"


def reference_image(renderer, scene, camera=None, settings: Settings | None = None, *, kind: str = "converged",
                    rays: int | None = None, seed: int = 0, cache: bool = True,
                    folder=None, shadows: str = "traced", viewer: str = "ray", progress=None) -> ReferenceImage:
    """The reference image of `kind` for this scene, camera and settings (cached on disk).
    Converged only: `shadows` "traced" (exact) or "map" (the frame's shadow map); `viewer` "ray"
    (the physical view of reflected surfaces) or "camera" (as the lit G-buffer sees them);
    `progress` as Frame.reference's (Ctrl-C stops it between sample rounds, caching nothing)."""
    if kind not in KINDS:
        raise ValueError(f"reference kind must be one of {', '.join(KINDS)}, got {kind!r}")
    settings = settings if settings is not None else Settings()
    camera = camera if camera is not None else scene.camera
    if camera is None:
        raise ValueError("reference_image: the scene has no default camera; pass camera=")
    path = cache_dir(folder) / f"{cache_key(kind, scene, camera, settings, rays, seed, shadows, viewer)}.npz"
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
        frame = renderer.render(scene, camera, settings.replace(method="off", user_passes=(), user_params={}))
        converged = frame.reference("converged", rays=rays, seed=seed, shadows=shadows, viewer=viewer,
                                    progress=progress)
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
