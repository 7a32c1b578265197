"""The renderer and its frames.

``Renderer`` owns a headless OpenGL 4.5 context (EGL): the GPU's EGL device when there is
one, Mesa's llvmpipe otherwise. ``Renderer.render`` runs the frame's chain of passes and
returns a ``Frame`` whose images stay on the GPU until a property reads them (then they
are cached as float32 numpy arrays, row 0 at the top of the image).
"""

from __future__ import annotations

import functools
from importlib import resources
from pathlib import Path

import numpy as np

from . import _core
from .settings import Settings


def shader_dir() -> Path:
    """The GLSL sources installed with the package."""
    return Path(str(resources.files("ssrlab") / "shaders"))


class Renderer:
    """A headless renderer.

    device: "auto" (the GPU's EGL device when there is one, else llvmpipe), "gpu" (raise
    DeviceError when there is no GPU) or "cpu" (Mesa's llvmpipe).
    It renders any number of scenes, cameras and settings, and may be used from any thread, one
    call at a time (its GL context is current only during a call).
    """

    def __init__(self, device: str = "auto", *, shader_dir: str | Path | None = None):
        if device not in ("auto", "gpu", "cpu"):
            raise ValueError(f"Renderer.device must be 'auto', 'gpu' or 'cpu', got {device!r}")
        folder = Path(shader_dir) if shader_dir is not None else globals()["shader_dir"]()
        self._native = _core.Renderer(device=device, shader_dir=str(folder))
        self.device = device

    @functools.cached_property
    def info(self) -> dict:
        """Vendor, renderer, GL version and the device chosen."""
        return dict(self._native.info())

    def render(self, scene: _core.Scene, camera: _core.Camera | None = None,
               settings: Settings | None = None, **overrides) -> "Frame":
        """Renders `scene` seen by `camera` (default: the scene's own camera).

        `overrides` change single settings: ``render(scene, layers=4)``.
        """
        settings = settings if settings is not None else Settings()
        if not isinstance(settings, Settings):
            raise TypeError(f"settings must be an ssrlab.Settings, got {type(settings).__name__}")
        if overrides:
            settings = settings.replace(**overrides)
        if camera is None:
            camera = scene.camera
            if camera is None:
                raise ValueError("render: the scene has no default camera; pass camera=ssrlab.Camera(...)")
        native = self._native.render(scene, camera, settings.to_native())
        return Frame(native, settings, renderer=self, scene=scene)

    def sample_reflections(self, sampling: str, alpha: float, view, count: int, *, seed: int = 0,
                           stratified: bool = False) -> dict[str, np.ndarray]:
        """Reflection directions drawn by the very GLSL the tracers use, for a view direction
        in the local frame where the surface normal is +z (view.z > 0) and GGX alpha.

        Returns l (count, 3), weight (count,), pdf (count,) and u (count, 2), the uniform
        numbers used; with stratified=True they form a randomly offset Hammersley set.
        """
        a = self._native.sample_reflections(sampling, float(alpha), tuple(map(float, view)), int(count),
                                            int(seed), bool(stratified))
        return {"l": a[:, :3], "weight": a[:, 3], "pdf": a[:, 4], "u": a[:, 5:7]}

    def compile(self, *stages: str, defines: dict | None = None) -> int:
        """Compiles shader stages (paths under the shader folder); raises ShaderError."""
        return self._native.compile(list(stages), {k: str(v) for k, v in (defines or {}).items()})

    def __repr__(self) -> str:
        i = self.info
        return f"Renderer(device={i['device']!r}, renderer={i['renderer']!r}, gl={i['gl_version']!r})"


class Frame:
    """One rendered frame. Image properties read from the GPU on first access."""

    def __init__(self, native: _core.Frame, settings: Settings, renderer: "Renderer | None" = None, scene=None):
        self._native = native
        self.settings = settings
        self._renderer = renderer
        self._scene = scene
        self._cache: dict[str, np.ndarray] = {}

    # -- metadata -------------------------------------------------------------------------------
    @property
    def timings(self) -> dict[str, float]:
        """GPU milliseconds per pass (GL timestamp queries); parts such as
        ``depth_peel.layer0`` are listed beside their pass, ``total`` sums the passes."""
        return dict(self._native.timings)

    @property
    def wall_ms(self) -> float:
        """CPU milliseconds of the render call, until the GPU finished."""
        return self._native.wall_ms

    @property
    def passes(self) -> list[str]:
        return list(self._native.passes)

    @property
    def layer_samples(self) -> list[int]:
        """Samples each G-buffer layer's geometry wrote (0: an empty layer, whose draws and
        every deeper layer's were skipped on the GPU)."""
        return list(self._native.layer_samples)

    @property
    def camera(self) -> _core.Camera:
        return self._native.camera

    @property
    def view_matrix(self) -> np.ndarray:
        return np.asarray(self._native.view_matrix)

    @property
    def projection_matrix(self) -> np.ndarray:
        return np.asarray(self._native.projection_matrix)

    @property
    def texture_names(self) -> list[str]:
        return list(self._native.texture_names)

    # -- images -------------------------------------------------------------------------------
    def read(self, name: str, level: int = 0) -> np.ndarray:
        """Every layer of a texture as float32 (layers, height, width, 4), cached."""
        key = f"{name}@{level}"
        if key not in self._cache:
            self._cache[key] = self._native.read(name, level)
        return self._cache[key]

    @property
    def color(self) -> np.ndarray:
        """The final image: linear radiance, float32 (height, width, 3)."""
        return self.read("color")[0, :, :, :3]

    @property
    def reflection(self) -> np.ndarray:
        """The resolved reflection colour c_r, float32 (height, width, 3); 0 where a pixel does
        not reflect (or nothing was traced)."""
        if "reflection" not in self.texture_names:
            return np.zeros((self.settings.height, self.settings.width, 3), np.float32)
        return self.read("reflection")[0, :, :, :3]

    @functools.cached_property
    def gbuffer(self) -> "GBuffer":
        return GBuffer(self)

    @functools.cached_property
    def rays(self) -> "RayResults":
        """Per-ray results of the trace pass (raises if the frame traced no rays)."""
        if "rays.hit" not in self.texture_names:
            raise ValueError("this frame traced no rays (method='off', or no surface has reflectivity > 0)")
        return RayResults(self)

    def reference(self, kind: str = "converged", *, rays: int | None = None, seed: int = 0,
                  sampling: str = "vndf", viewer: str = "camera"):
        """Ground truth for this frame, traced against the scene's triangles (ssrlab.reference).

        kind="converged": `rays` rays per pixel (default 256; one for mirror pixels) drawn with
        `sampling`, the true reflection and final image. kind="per_ray": the rays this frame's
        SSR traced, each with its true hit. viewer="camera" shades the surfaces rays hit as the
        camera sees them, like the lit G-buffer SSR fetches from (so the two differ only by what
        screen space cannot see); viewer="ray" views them from the ray's origin (the physical
        reflection; only view-dependent specular changes).
        """
        if viewer not in ("camera", "ray"):
            raise ValueError(f"viewer must be 'camera' or 'ray', got {viewer!r}")
        from .reference import ConvergedReference, PerRayReference

        if self._renderer is None or self._scene is None:
            raise ValueError("this frame does not know its renderer and scene")
        if kind == "per_ray":
            timings = self._renderer._native.reference(self._scene, self._native, "per_ray", 1, seed, sampling,
                                                      viewer)
            for name in ("reference.hit", "reference.position", "reference.radiance"):
                self._cache.pop(f"{name}@0", None)
            return PerRayReference(self, dict(timings))
        if kind == "converged":
            rays = 256 if rays is None else int(rays)
            timings = self._renderer._native.reference(self._scene, self._native, "converged", rays, seed, sampling,
                                                      viewer)
            for name in ("reference.reflection", "reference.color", "reference.accum"):
                self._cache.pop(f"{name}@0", None)
            return ConvergedReference(self, rays, dict(timings))
        raise ValueError(f"reference kind must be 'converged' or 'per_ray', got {kind!r}")

    def save(self, folder, *, overwrite: bool = False, exposure: float = 1.0, extra: dict | None = None) -> list[Path]:
        """Writes color.png, gbuffer_layer<i>.exr and timings.json into `folder` (see ssrlab.io)."""
        from .io import write_frame

        return write_frame(self, folder, overwrite=overwrite, exposure=exposure, extra=extra)

    # -- display (ssrlab.display) ---------------------------------------------------------------
    def __repr__(self) -> str:
        s = self.settings
        total = self.timings.get("total")
        passes = [p for p in self.passes]
        ms = f", total {total:.2f} ms GPU" if total is not None else ""
        return (f"<Frame {s.width}x{s.height}, {s.layers} layer(s), method={s.method!r}, "
                f"passes {', '.join(passes)}{ms}>")

    def _repr_png_(self) -> bytes:
        """The final image, sRGB (Jupyter shows it when a cell ends with a frame)."""
        from .display import frame_png

        return frame_png(self)

    def _repr_html_(self) -> str:
        """The final image beside a table of GPU time per pass."""
        from .display import frame_html

        return frame_html(self)


class GBuffer:
    """The deep G-buffer of a frame: per-layer arrays (layers, height, width[, channels]).

    depth        positive view-space depth (distance along the view axis); the far-plane
                 distance where a layer covers nothing
    window_depth the stored depth-buffer value, in the frame's depth convention
    normal       view-space unit normal (x right, y up, z toward the camera)
    albedo       linear base colour
    roughness    perceptual roughness (GGX alpha = roughness**2)
    metallic, reflectivity
    coverage     True where the layer holds a surface
    lit          direct lighting of every layer (the colour a reflection ray fetches)
    """

    def __init__(self, frame: Frame):
        self._frame = frame

    @property
    def layers(self) -> int:
        return self._frame.settings.layers

    @property
    def depth(self) -> np.ndarray:
        return self._frame.read("linear_depth")[..., 0]

    @property
    def window_depth(self) -> np.ndarray:
        return self._frame.read("gbuffer.depth")[..., 0]

    @property
    def normal(self) -> np.ndarray:
        return self._frame.read("gbuffer.normal")[..., :3]

    @property
    def roughness(self) -> np.ndarray:
        return self._frame.read("gbuffer.normal")[..., 3]

    @property
    def albedo(self) -> np.ndarray:
        return self._frame.read("gbuffer.albedo")[..., :3]

    @property
    def metallic(self) -> np.ndarray:
        return self._frame.read("gbuffer.albedo")[..., 3]

    @property
    def reflectivity(self) -> np.ndarray:
        return self._frame.read("gbuffer.material")[..., 0]

    @property
    def coverage(self) -> np.ndarray:
        return self._frame.read("gbuffer.material")[..., 1] > 0.5

    @property
    def object_id(self) -> np.ndarray:
        """(layers, H, W) int32 index of the scene object each layer shows, -1 where none."""
        m = self._frame.read("gbuffer.material")
        return (np.rint(m[..., 2] * 255).astype(np.int32) + 256 * np.rint(m[..., 3] * 255).astype(np.int32)) - 1

    @property
    def lit(self) -> np.ndarray:
        return self._frame.read("lit")[..., :3]

    def __repr__(self) -> str:
        s = self._frame.settings
        return f"<GBuffer {s.layers} layer(s) of {s.width}x{s.height}>"

    def _repr_png_(self) -> bytes:
        """A grid: one row per layer, columns lit colour, normal and depth."""
        from .display import gbuffer_png

        return gbuffer_png(self)

    def _repr_html_(self) -> str:
        from .display import gbuffer_html

        return gbuffer_html(self)


class RayResults:
    """Per-ray results, arrays of shape (rays_per_pixel, h, w, ...) at the trace resolution
    (h, w) = ceil((height, width) / downscale), row 0 at the top.

    hit_uv     (R, h, w, 2) hit position in [0, 1]^2, (0, 0) the image's top-left corner,
               pixel (row i, column j) centred at ((j + 0.5)/W, (i + 0.5)/H); 0 for misses
    hit_layer  (R, h, w) int32 G-buffer layer hit, 1-based; 0 = miss (as the thesis stores it)
    hit        (R, h, w) bool, hit_layer > 0
    weight     (R, h, w) f_r cos / pdf without Fresnel; 0 for no ray or an invalid sample
    pdf        (R, h, w) solid-angle pdf of the direction; 0 for mirror (Dirac) directions
    steps      (R, h, w) depth fetches the ray spent
    fade       (R, h, w) 1 = hit kept, 0 = replaced by the environment
    direction  (R, h, w, 3) view-space unit direction
    traced     (h, w) bool: the pixel is reflective and traced rays
    """

    def __init__(self, frame: Frame):
        self._frame = frame

    def _hit(self) -> np.ndarray:
        return self._frame.read("rays.hit")

    def _sample(self) -> np.ndarray:
        return self._frame.read("rays.sample")

    @property
    def hit_uv(self) -> np.ndarray:
        h = self._hit()
        s = self._frame.settings
        uv = np.stack([h[..., 0] / s.width, 1.0 - h[..., 1] / s.height], axis=-1).astype(np.float32)
        uv[~self.hit] = 0.0
        return uv

    @property
    def hit_pixel(self) -> np.ndarray:
        """(R, h, w, 2) hit position in pixels (x = column, y = row from the top); 0 for misses."""
        return self.hit_uv * np.array([self._frame.settings.width, self._frame.settings.height], np.float32)

    @property
    def hit_layer(self) -> np.ndarray:
        return np.rint(self._hit()[..., 2]).astype(np.int32)

    @property
    def hit(self) -> np.ndarray:
        return self.hit_layer > 0

    @property
    def fade(self) -> np.ndarray:
        return self._hit()[..., 3]

    @property
    def weight(self) -> np.ndarray:
        return self._sample()[..., 0]

    @property
    def pdf(self) -> np.ndarray:
        return self._sample()[..., 1]

    @property
    def steps(self) -> np.ndarray:
        return self._sample()[..., 2]

    @property
    def traced(self) -> np.ndarray:
        return self._sample()[0, ..., 3] > 0.5

    @property
    def direction(self) -> np.ndarray:
        return self._frame.read("rays.direction")[..., :3]

    def mean_fetches(self) -> float:
        """Mean depth fetches per traced ray."""
        m = np.broadcast_to(self.traced, self.steps.shape)
        return float(self.steps[m].mean()) if m.any() else 0.0

    def __repr__(self) -> str:
        n, h, w = self.hit.shape
        return f"<RayResults {n} ray(s) per pixel at {w}x{h}, mean {self.mean_fetches():.1f} fetches per ray>"

    def _repr_png_(self) -> bytes:
        """Hit share per pixel, hit layer of the first ray, depth fetches per ray."""
        from .display import rays_png

        return rays_png(self, self._frame.settings.layers)

    def _repr_html_(self) -> str:
        from .display import rays_html

        return rays_html(self, self._frame.settings.layers)
