"""Views of what a frame holds: its deep G-buffer, its rays and its reprojections, as arrays
(layers or rays first, row 0 at the top of the image)."""

from __future__ import annotations

import numpy as np


class MissingChannel(KeyError, AttributeError):
    """A view's channel that this frame does not hold (no pass of its chain wrote the texture that
    declares it)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


# What a channel needs that a frame may not have, for the message when it is missing.
_NEEDS = {
    "motion": "Settings.motion_vectors=True (or a temporal technique that reprojects, which writes it too)",
    "emission": "a scene with an emissive texture",
    "specular_f0": "a scene with a KHR_materials_specular texture",
}


def _decode(raw: np.ndarray, decode: str, height: int) -> np.ndarray:
    """A channel's stored components as its view gives them (render_pass.h, ChannelDecode)."""
    if decode == "value":
        out = raw
    elif decode == "flag":
        out = raw > 0.5
    elif decode == "integer":
        out = np.rint(raw).astype(np.int32)
    elif decode == "byte_id_minus_one":
        b = np.rint(raw * 255).astype(np.int32)
        out = b[..., 0] + 256 * b[..., 1] - 1
    elif decode == "window_point":
        out = np.stack([raw[..., 0], height - raw[..., 1]], axis=-1)
    elif decode == "window_vector":
        out = np.stack([raw[..., 0], -raw[..., 1]], axis=-1)
    else:
        raise ValueError(f"unknown channel decoding {decode!r}")
    if out.dtype == np.float64:
        out = out.astype(np.float32)
    if out.ndim == raw.ndim and out.shape[-1] == 1:
        out = out[..., 0]
    return out


class ChannelView:
    """A view of a frame's textures made from what their channels mean, as the passes that wrote
    them declared (ResourceDesc::channels in cpp/render/render_pass.h; Frame.channels): every
    declared channel of this view is an attribute, decoded as declared, cached and read-only.
    `channels` lists them with their texture, components and meaning."""

    view = ""

    def __init__(self, frame: "Frame", texture: str | None = None, view: str | None = None):
        self._frame = frame
        self._texture = texture
        self._values: dict[str, np.ndarray] = {}
        if view is not None:
            self.view = view

    @property
    def channels(self) -> list[dict]:
        """The channels this view has in this frame: dicts of name, texture, layered, first, count,
        decode, doc (Frame.channels)."""
        return [c for c in self._frame.channels
                if c["view"] == self.view and (self._texture is None or c["texture"] == self._texture)]

    def __getattr__(self, name: str) -> np.ndarray:
        if name.startswith("_"):
            raise AttributeError(name)
        values = self.__dict__.get("_values")
        if values is not None and name in values:
            return values[name]
        self._frame._check_live(f"the {self.view} channel {name!r}")
        for c in self.channels:
            if c["name"] == name:
                raw = self._frame.read(c["texture"])[..., c["first"]:c["first"] + c["count"]]
                out = _decode(raw, c["decode"], self._frame.settings.height)
                if not c["layered"]:  # a 2D texture: (height, width, ...)
                    out = out[0]
                out = np.ascontiguousarray(out)
                out.setflags(write=False)
                self._values[name] = out
                return out
        have = ", ".join(c["name"] for c in self.channels) or "none"
        needs = f"; it comes with {_NEEDS[name]}" if name in _NEEDS else ""
        raise MissingChannel(f"{type(self).__name__}.{name}: this frame holds no {self.view} channel {name!r} "
                             f"(it has: {have}){needs}")

    def __dir__(self):
        return sorted(set(super().__dir__()) | {c["name"] for c in self.channels})

    def describe(self) -> str:
        """A Markdown table of this view's channels in this frame: name, texture, components, meaning."""
        rows = ["| channel | texture | components | meaning |", "|---|---|---|---|"]
        for c in self.channels:
            comps = "rgba"[c["first"]:c["first"] + c["count"]]
            rows.append(f"| {c['name']} | {c['texture']} | {comps} | {c['doc']} |")
        return "\n".join(rows)


class GBuffer(ChannelView):
    """The deep G-buffer of a frame: per-layer arrays (layers, height, width[, channels]), one
    attribute per channel the G-buffer's passes declare (cpp/passes/gbuffer_layout.cpp): depth,
    window_depth, normal, albedo, roughness, metallic, reflectivity, coverage, object_id, lit, and
    where the frame has them motion, emission, specular_f0. ``describe()`` gives each one's meaning."""

    view = "gbuffer"

    @property
    def layers(self) -> int:
        return self._frame.settings.layers

    def __repr__(self) -> str:
        s = self._frame.settings
        return f"<GBuffer {s.layers} layer(s) of {s.width}x{s.height}>"


class RayResults(ChannelView):
    """Per-ray results, arrays of shape (rays_per_pixel, h, w, ...) at the trace resolution
    (h, w) = ceil((height, width) / downscale), row 0 at the top: one attribute per channel the
    trace passes declare (TracePass::ray_texture: hit_position, hit_layer, fade, weight, pdf,
    steps, traced_ray, direction; ``describe()`` gives each one's meaning), and what follows from
    them:

    hit_uv     (R, h, w, 2) hit position in [0, 1]^2, (0, 0) the image's top-left corner,
               pixel (row i, column j) centred at ((j + 0.5)/W, (i + 0.5)/H); 0 for misses
    hit_pixel  (R, h, w, 2) the same in pixels (x = column, y = row from the top); 0 for misses
    hit        (R, h, w) bool, hit_layer > 0
    traced     (h, w) bool: the pixel is reflective, faces the camera and traced rays
    A pixel that traces no ray holds zeros in every field.
    """

    view = "rays"

    @property
    def hit(self) -> np.ndarray:
        return self.hit_layer > 0

    @property
    def hit_pixel(self) -> np.ndarray:
        p = np.where(self.hit[..., None], self.hit_position, np.float32(0.0)).astype(np.float32)
        return p

    @property
    def hit_uv(self) -> np.ndarray:
        s = self._frame.settings
        return (self.hit_pixel / np.array([s.width, s.height], np.float32)).astype(np.float32)

    @property
    def traced(self) -> np.ndarray:
        return self.traced_ray[0]

    def mean_fetches(self) -> float:
        """Mean depth fetches per traced ray."""
        m = np.broadcast_to(self.traced, self.steps.shape)
        return float(self.steps[m].mean()) if m.any() else 0.0

    def __repr__(self) -> str:
        n, h, w = self.hit.shape
        return f"<RayResults {n} ray(s) per pixel at {w}x{h}, mean {self.mean_fetches():.1f} fetches per ray>"


class Reprojection(ChannelView):
    """The reproject pass's result (shaders/passes/reproject.comp), arrays (height, width, ...):
    one attribute per channel ReprojectPass::texture declares (pixel, valid, reason; ``describe()``
    gives each one's meaning), and uv, the pixel in [0, 1]^2 ((0, 0) the image's top-left corner).
    reason's codes are the constants below."""

    VALID, NO_HISTORY, NO_SURFACE, OFFSCREEN, DEPTH, NORMAL, DISOCCLUDED, REFLECTION = range(8)

    view = "reprojection"

    def __init__(self, frame: "Frame", texture: str = "reprojection"):
        super().__init__(frame, texture)

    @property
    def uv(self) -> np.ndarray:
        s = self._frame.settings
        return (self.pixel / np.array([s.width, s.height], np.float32)).astype(np.float32)
