"""What a frame holds, as pictures the viewer can show, and a pixel's every value.

Each view is a pure function of a Frame (and, for the error, its reference) returning display
RGB floats in [0, 1] of shape (H, W, 3) at the frame's own size, with a caption that states the
scale. The colour conventions are ssrlab.display's: radiance as sRGB after clamping, normals as
0.5 n + 0.5, depth as grey (near white), counts and errors through a colour map.
"""

from __future__ import annotations

import math

import numpy as np

from .. import display

# Display floats in [0, 1] as the uint8 codes the page gets.
to_bytes = display.to_bytes

# Views of the G-buffer, per layer: name -> (GBuffer attribute, how it is shown).
GBUFFER_CHANNELS = ("depth", "normal", "albedo", "roughness", "metallic", "reflectivity", "coverage", "lit",
                    "motion", "object_id")
# Views of the rays, per ray of a pixel.
RAY_VIEWS = ("hit_layer", "hits", "steps", "source")
# Where each ray's reflection came from (Frame.fallback_stats, per ray): colours of the source view.
SOURCE_COLOURS = {"none": (0.0, 0.0, 0.0), "screen": (0.15, 0.75, 0.25), "bvh": (0.2, 0.45, 0.95),
                  "probes": (0.95, 0.6, 0.1), "environment": (0.55, 0.55, 0.55)}
SOURCE_CODES = ("none", "screen", "bvh", "probes", "environment")  # Frame.RAY_SOURCES


def names(frame) -> list[str]:
    """Every view this frame can show: 'color', 'reflection', 'gbuffer.<channel>', 'rays.<view>',
    'error' and 'texture:<name>' for each texture the frame names."""
    out = ["color", "reflection"]
    out += [f"gbuffer.{c}" for c in GBUFFER_CHANNELS if c != "motion" or "gbuffer.motion" in frame.texture_names]
    if "rays.hit" in frame.texture_names:
        out += [f"rays.{v}" for v in RAY_VIEWS]
    out.append("error")
    out += [f"texture:{t}" for t in frame.texture_names]
    return out


def _at_size(rgb: np.ndarray, height: int, width: int) -> np.ndarray:
    """A (h, w, 3) picture shown at (height, width): repeated (trace resolution of downscale) or cut."""
    h, w = rgb.shape[:2]
    if (h, w) == (height, width):
        return rgb
    rows = np.minimum((np.arange(height) * h) // height, h - 1)
    cols = np.minimum((np.arange(width) * w) // width, w - 1)
    return rgb[rows][:, cols]


def source_codes(frame) -> np.ndarray:
    """(rays, h, w) int8 index into SOURCE_CODES of where each ray's reflection came from
    (Frame.ray_sources)."""
    return frame.ray_sources()


def error_image(color: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, float]:
    """|color - reference| summed over the channels, through a colour map up to its 99th percentile."""
    e = np.abs(np.asarray(color, np.float64) - np.asarray(reference, np.float64)).sum(axis=-1)
    top = float(np.percentile(e, 99)) if e.size else 0.0
    top = top if top > 0 else 1.0
    return display.colormap(e, 0.0, top, "inferno"), top


COLOR_CAPTION = "colour (sRGB, clamped)"


def picture(frame, view: str, *, exposure: float = 1.0, color: np.ndarray | None = None,
            **kw) -> tuple[np.ndarray, str]:
    """render()'s picture as the page gets it, uint8 (H, W, 3), and its caption. A frame's own
    colour is encoded on the device (Frame.srgb8, the same codes as to_bytes of render's): the
    float colour never comes to the CPU."""
    if view == "color" and color is None:
        return frame.srgb8(exposure), COLOR_CAPTION
    rgb, caption = render(frame, view, exposure=exposure, color=color, **kw)
    return to_bytes(rgb), caption


def render(frame, view: str, *, layer: int = 0, ray: int = 0, reference=None, exposure: float = 1.0,
           color: np.ndarray | None = None) -> tuple[np.ndarray, str]:
    """The picture of `view` (one of names(frame)) and its caption. `color`: the image the colour
    view shows in place of frame.color (an accumulation of several frames). ValueError naming the
    view when the frame does not hold it."""
    s = frame.settings
    H, W = s.height, s.width
    if view == "color":
        return display.srgb(frame.color if color is None else color, exposure), COLOR_CAPTION
    if view == "reflection":
        return display.srgb(frame.reflection, exposure), "resolved reflection c_r (sRGB, clamped)"
    if view == "error":
        if reference is None:
            raise ValueError("view 'error' needs the converged reference: switch 'reference' on")
        rgb, top = error_image(frame.color if color is None else color, reference.color)
        return rgb, f"|colour - reference| summed over RGB, 0 (black) to {top:.3g} (yellow)"
    if view.startswith("gbuffer."):
        channel = view[len("gbuffer."):]
        if channel not in GBUFFER_CHANNELS:
            raise ValueError(f"no G-buffer view {view!r}; views: {', '.join(names(frame))}")
        g = frame.gbuffer
        layer = min(max(int(layer), 0), s.layers - 1)
        covered = g.coverage[layer]
        where = f"layer {layer}"
        if channel == "depth":
            rgb, (lo, hi) = display.depth_grey(g.depth[layer], covered)
            return rgb, f"{where} view depth, {lo:.3g} (white) to {hi:.3g} m (dark); black: empty"
        if channel == "normal":
            return display.normals(g.normal[layer], covered), f"{where} view-space normal as 0.5 n + 0.5"
        if channel in ("albedo", "lit"):
            return display.srgb(getattr(g, channel)[layer]), f"{where} {channel} (sRGB, clamped)"
        if channel in ("roughness", "metallic", "reflectivity"):
            v = getattr(g, channel)[layer]
            return display.colormap(np.where(covered, v, 0.0), 0.0, 1.0), f"{where} {channel}, 0 to 1 (viridis)"
        if channel == "coverage":
            return np.repeat(covered[..., None].astype(np.float32), 3, -1), f"{where} coverage: white = a surface"
        if channel == "object_id":
            ids = g.object_id[layer]
            rng = np.random.default_rng(12345)
            lut = rng.uniform(0.2, 1.0, (max(int(ids.max()) + 2, 2), 3)).astype(np.float32)
            lut[0] = 0.0
            return lut[ids + 1], f"{where} object index, one colour each; black: none"
        if channel == "motion":
            m = g.motion[layer]
            mag = np.hypot(m[..., 0], m[..., 1])
            top = max(float(mag.max()), 1e-6)
            return display.colormap(mag, 0.0, top), f"{where} motion, 0 to {top:.3g} pixels (viridis)"
    if view.startswith("rays."):
        if "rays.hit" not in frame.texture_names:
            raise ValueError(f"view {view!r}: this frame traced no rays")
        r = frame.rays
        ray = min(max(int(ray), 0), r.hit_layer.shape[0] - 1)
        where = f"ray {ray}"
        v = view[len("rays."):]
        if v == "hit_layer":
            hl = r.hit_layer[ray]
            rgb = np.where((hl > 0)[..., None], display.colormap(hl, 1, max(s.layers, 2), "plasma"), 0.0)
            return _at_size(rgb, H, W), f"{where} hit layer, 1 to {s.layers} (plasma); black: miss"
        if v == "hits":
            traced = r.traced
            hit = r.hit[ray]
            rgb = np.zeros(hit.shape + (3,), np.float32)
            rgb[traced & hit] = (0.15, 0.75, 0.25)
            rgb[traced & ~hit] = (0.85, 0.2, 0.2)
            return _at_size(rgb, H, W), f"{where}: green hit, red miss, black no ray"
        if v == "steps":
            steps = r.steps[ray]
            top = max(float(steps.max()), 1.0)
            return _at_size(display.colormap(steps, 0.0, top, "magma"), H, W), \
                f"{where} depth fetches, 0 to {top:.0f} (magma)"
        if v == "source":
            codes = source_codes(frame)[ray]
            lut = np.array([SOURCE_COLOURS[k] for k in SOURCE_CODES], np.float32)
            legend = ", ".join(f"{k} {'rgb(%d,%d,%d)' % tuple(int(255 * c) for c in SOURCE_COLOURS[k])}"
                               for k in SOURCE_CODES)
            return _at_size(lut[codes], H, W), f"{where} source: {legend}"
        raise ValueError(f"no ray view {view!r}; views: {', '.join(names(frame))}")
    if view.startswith("texture:"):
        name = view[len("texture:"):]
        if name not in frame.texture_names:
            raise ValueError(f"this frame names no texture {name!r}; it has {', '.join(frame.texture_names)}")
        t = frame.read(name)
        layer = min(max(int(layer), 0), t.shape[0] - 1)
        x = np.nan_to_num(t[layer, ..., :3].astype(np.float64), posinf=0.0, neginf=0.0)
        lo, hi = float(x.min()), float(x.max())
        rgb = ((x - lo) / (hi - lo)).astype(np.float32) if hi > lo else np.zeros_like(x, np.float32)
        return _at_size(rgb, H, W), f"{name} layer {layer}, RGB scaled from [{lo:.3g}, {hi:.3g}] to [0, 1]"
    raise ValueError(f"no view {view!r}; views: {', '.join(names(frame))}")




def _fmt(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        return str(bool(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    f = float(v)
    return "nan" if math.isnan(f) else f"{f:.5g}"


def inspect(frame, row: int, col: int) -> dict:
    """Every value of pixel (row, col) (row 0 at the top): per layer every G-buffer channel, per ray
    its hit, and the final colour and reflection."""
    s = frame.settings
    if not (0 <= row < s.height and 0 <= col < s.width):
        raise ValueError(f"pixel ({row}, {col}) is outside the {s.width}x{s.height} frame")
    g = frame.gbuffer
    out = {"pixel": (int(row), int(col)), "color": [float(c) for c in frame.color[row, col]],
           "reflection": [float(c) for c in frame.reflection[row, col]], "layers": [], "rays": []}
    for k in range(s.layers):
        out["layers"].append({
            "coverage": bool(g.coverage[k, row, col]), "depth": float(g.depth[k, row, col]),
            "normal": [float(c) for c in g.normal[k, row, col]], "albedo": [float(c) for c in g.albedo[k, row, col]],
            "roughness": float(g.roughness[k, row, col]), "metallic": float(g.metallic[k, row, col]),
            "reflectivity": float(g.reflectivity[k, row, col]), "object_id": int(g.object_id[k, row, col]),
            "lit": [float(c) for c in g.lit[k, row, col]],
            **({"motion": [float(c) for c in g.motion[k, row, col]]} if "gbuffer.motion" in frame.texture_names
               else {})})
    if "rays.hit" in frame.texture_names:
        r = frame.rays
        h, w = r.hit_layer.shape[1:]
        tr, tc = min(row * h // s.height, h - 1), min(col * w // s.width, w - 1)
        codes = source_codes(frame)
        for i in range(r.hit_layer.shape[0]):
            out["rays"].append({
                "hit_layer": int(r.hit_layer[i, tr, tc]), "hit_pixel": [float(c) for c in r.hit_pixel[i, tr, tc]],
                "fade": float(r.fade[i, tr, tc]), "weight": float(r.weight[i, tr, tc]), "pdf": float(r.pdf[i, tr, tc]),
                "steps": int(r.steps[i, tr, tc]), "source": SOURCE_CODES[int(codes[i, tr, tc])],
                "direction": [float(c) for c in r.direction[i, tr, tc]]})
    return out


def inspect_markdown(values: dict) -> str:
    """The inspector's values as a Markdown table."""
    row, col = values["pixel"]
    lines = [f"**pixel** row {row}, column {col}  ", f"colour {' '.join(map(_fmt, values['color']))}, "
             f"reflection {' '.join(map(_fmt, values['reflection']))}", ""]
    if values["layers"]:
        keys = [k for k in values["layers"][0]]
        lines += ["| layer | " + " | ".join(keys) + " |", "|---" * (len(keys) + 1) + "|"]
        for i, layer in enumerate(values["layers"]):
            cells = [" ".join(map(_fmt, v)) if isinstance(v, list) else _fmt(v) for v in layer.values()]
            lines.append(f"| {i} | " + " | ".join(cells) + " |")
    if values["rays"]:
        keys = list(values["rays"][0])
        lines += ["", "| ray | " + " | ".join(keys) + " |", "|---" * (len(keys) + 1) + "|"]
        for i, ray in enumerate(values["rays"]):
            cells = [" ".join(map(_fmt, v)) if isinstance(v, list) else (v if isinstance(v, str) else _fmt(v))
                     for v in ray.values()]
            lines.append(f"| {i} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
