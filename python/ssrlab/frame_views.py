"""Views of what a frame holds: its deep G-buffer, its rays and its reprojections, as arrays
(layers or rays first, row 0 at the top of the image)."""

from __future__ import annotations

import numpy as np


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
    motion       (layers, height, width, 2) with Settings.motion_vectors (or a temporal technique that
                 reprojects, which reads it): where each sample was in
                 the previous frame of the sequence minus where it is, in pixels of these arrays
                 (x right, y down: previous (row, col) = (row + motion[..., 1], col + motion[..., 0]));
                 0 outside a sequence and where nothing moved
    """

    def __init__(self, frame: "Frame"):
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
    def motion(self) -> np.ndarray:
        if "gbuffer.motion" not in self._frame.texture_names:
            raise KeyError("gbuffer.motion: this frame was rendered without Settings.motion_vectors=True (and "
                           "without a temporal technique that reprojects, which writes it too)")
        m = np.array(self._frame.read("gbuffer.motion")[..., :2])
        m[..., 1] *= -1.0  # the texture's y runs up the image (GL window coordinates), the arrays' rows down
        m.setflags(write=False)
        return m

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
    direction  (R, h, w, 3) view-space unit direction (0 where the pixel traces no ray)
    traced     (h, w) bool: the pixel is reflective, faces the camera and traced rays
    A pixel that traces no ray holds zeros in every field.
    """

    def __init__(self, frame: "Frame"):
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


class Reprojection:
    """The reproject pass's result (shaders/passes/reproject.comp), arrays (height, width, ...).

    pixel   (H, W, 2) previous-frame position in pixels, x = column, y = row from the top (pixel
            centres at .5, as RayResults.hit_pixel)
    uv      (H, W, 2) the same in [0, 1]^2, (0, 0) the image's top-left corner
    valid   (H, W) bool: the history there is kept
    reason  (H, W) int: 0 valid, 1 no history (first frame), 2 no surface, 3 off-screen,
            4 another surface there (depth, or with reject_layers the object, differs),
            5 normal differs, 6 disoccluded (reject_layers: the surface was there, behind layer 0),
            7 the reflection there lay elsewhere (Frame.reflection_reprojection only)
    """

    VALID, NO_HISTORY, NO_SURFACE, OFFSCREEN, DEPTH, NORMAL, DISOCCLUDED, REFLECTION = range(8)

    def __init__(self, frame: "Frame", texture: str = "reprojection"):
        self._frame = frame
        self._texture = texture

    def _raw(self) -> np.ndarray:
        return self._frame.read(self._texture)[0]

    @property
    def pixel(self) -> np.ndarray:
        r = self._raw()
        return np.stack([r[..., 0], self._frame.settings.height - r[..., 1]], axis=-1).astype(np.float32)

    @property
    def uv(self) -> np.ndarray:
        s = self._frame.settings
        return (self.pixel / np.array([s.width, s.height], np.float32)).astype(np.float32)

    @property
    def valid(self) -> np.ndarray:
        return self._raw()[..., 2] > 0.5

    @property
    def reason(self) -> np.ndarray:
        return np.rint(self._raw()[..., 3]).astype(np.int32)
