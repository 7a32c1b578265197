"""Rich display of ssrlab objects in Jupyter (``_repr_png_`` / ``_repr_html_``).

One place for the pictures and tables that Frame, GBuffer, RayResults and Settings show when a notebook cell ends with one of them. Images are encoded as PNG with
matplotlib (already a dependency; it writes PNG through Pillow), never saved anywhere.

Colour conventions: radiance is shown as sRGB after clamping to [0, 1] (``ssrlab.io.linear_to_srgb``);
normals as 0.5 * n + 0.5; depth as grey, near = white, far = dark, black where a layer covers
nothing; counts (steps, hit layers) and errors through a matplotlib colour map, its scale
written in the caption.
"""

from __future__ import annotations

import base64
import html
import io as _stdio
import math

import numpy as np

from .io import linear_to_srgb, srgb8_thresholds, to_bytes  # noqa: F401 (display's names)
from .renderer import Frame, GBuffer, RayResults
from .settings import Settings

# Tiles narrower than this are enlarged (by pixel repetition) so a 64x48 test frame is visible.
MIN_TILE_WIDTH = 192
# Tiles wider than this are shrunk (by striding) so a grid of 640x360 layers stays a sane size.
MAX_TILE_WIDTH = 480
GAP = 4  # pixels between tiles


# -- images ---------------------------------------------------------------------------------------
def srgb(linear: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """Linear radiance (h, w, 3) as display sRGB floats in [0, 1]."""

    return linear_to_srgb(np.nan_to_num(np.asarray(linear, np.float32)), exposure)


def normals(n: np.ndarray, covered: np.ndarray | None = None) -> np.ndarray:
    """Unit normals (h, w, 3) as colours 0.5 n + 0.5 (black where not covered)."""
    rgb = np.clip(0.5 * np.nan_to_num(np.asarray(n, np.float32)) + 0.5, 0.0, 1.0)
    if covered is not None:
        rgb = np.where(np.asarray(covered)[..., None], rgb, 0.0)
    return rgb


def depth_grey(depth: np.ndarray, covered: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
    """View depth (h, w) as grey (near white, far dark, uncovered black) and the depth range shown."""
    d = np.asarray(depth, np.float64)
    covered = np.asarray(covered, bool) & np.isfinite(d)
    if not covered.any():
        return np.zeros(d.shape + (3,), np.float32), (math.nan, math.nan)
    lo, hi = float(d[covered].min()), float(d[covered].max())
    t = (d - lo) / (hi - lo) if hi > lo else np.zeros_like(d)
    grey = np.where(covered, 1.0 - 0.8 * np.clip(t, 0.0, 1.0), 0.0).astype(np.float32)
    return np.repeat(grey[..., None], 3, axis=-1), (lo, hi)


def colormap(values: np.ndarray, vmin: float, vmax: float, cmap: str = "viridis") -> np.ndarray:
    """Scalars (h, w) through a matplotlib colour map over [vmin, vmax], as RGB floats."""
    from matplotlib import colormaps

    v = np.nan_to_num(np.asarray(values, np.float64))
    t = (v - vmin) / (vmax - vmin) if vmax > vmin else np.zeros_like(v)
    return colormaps[cmap](np.clip(t, 0.0, 1.0))[..., :3].astype(np.float32)


def _fit(tile: np.ndarray) -> np.ndarray:
    """Enlarges small tiles and shrinks large ones by integer factors (no smoothing, no new deps)."""
    w = tile.shape[1]
    if w < MIN_TILE_WIDTH:
        k = max(1, MIN_TILE_WIDTH // w)
        tile = np.repeat(np.repeat(tile, k, axis=0), k, axis=1)
    elif w > MAX_TILE_WIDTH:
        k = math.ceil(w / MAX_TILE_WIDTH)
        tile = tile[::k, ::k]
    return tile


def grid(rows: list[list[np.ndarray]]) -> np.ndarray:
    """Tiles (h, w, 3) in rows and columns on a white background, each fitted to display size."""
    rows = [[_fit(np.asarray(t, np.float32)) for t in row] for row in rows if row]
    if not rows:
        raise ValueError("grid: no tiles")
    cols = max(len(r) for r in rows)
    th = max(t.shape[0] for r in rows for t in r)
    tw = max(t.shape[1] for r in rows for t in r)
    out = np.ones((len(rows) * (th + GAP) - GAP, cols * (tw + GAP) - GAP, 3), np.float32)
    for i, row in enumerate(rows):
        for j, t in enumerate(row):
            y, x = i * (th + GAP), j * (tw + GAP)
            out[y:y + t.shape[0], x:x + t.shape[1]] = t[..., :3]
    return out


def png(rgb: np.ndarray) -> bytes:
    """PNG bytes of an (h, w, 3) float image in [0, 1] (already display-encoded)."""
    from matplotlib.image import imsave

    buf = _stdio.BytesIO()
    imsave(buf, np.clip(np.nan_to_num(np.asarray(rgb, np.float32)), 0.0, 1.0), format="png")
    return buf.getvalue()


def img_tag(data: bytes, alt: str = "") -> str:
    return (f'<img src="data:image/png;base64,{base64.b64encode(data).decode()}" alt="{html.escape(alt)}" '
            f'style="image-rendering: pixelated; max-width: 100%"/>')


# -- HTML --------------------------------------------------------------------------------------------
def _cell(v) -> str:
    if isinstance(v, float):
        return "–" if not math.isfinite(v) else f"{v:.4g}"
    return "–" if v is None else html.escape(str(v))


def table(header: list[str], rows: list[list], caption: str = "") -> str:
    """A small HTML table; floats with 4 significant digits."""
    cap = f"<caption style='text-align:left'>{html.escape(caption)}</caption>" if caption else ""
    head = "".join(f"<th style='text-align:left'>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td style='text-align:left'>{_cell(c)}</td>" for c in r) + "</tr>"
                   for r in rows)
    return f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def figure(tiles: list[tuple[np.ndarray, str]]) -> str:
    """Images side by side, each with its caption below."""
    cells = "".join(f"<td style='text-align:center; vertical-align:top'>{img_tag(png(_fit(t)), c)}"
                    f"<br/><small>{html.escape(c)}</small></td>" for t, c in tiles)
    return f"<table><tr>{cells}</tr></table>"


def timings_rows(timings: dict[str, float]) -> list[list]:
    """Pass timings in frame order with parts (``depth_peel.layer0``) under their pass and the
    total last, as [name, ms] rows."""
    total = timings.get("total")
    rows = [[("  " + k.split(".", 1)[1]) if "." in k else k, v] for k, v in timings.items() if k != "total"]
    if total is not None:
        rows.append(["total", total])
    return rows


# -- per class --------------------------------------------------------------------------------------
def frame_png(frame) -> bytes:
    return png(_fit(srgb(frame.color)))


def frame_html(frame) -> str:
    s = frame.settings
    title = (f"Frame {s.width}x{s.height}, {s.layers} layer(s), method={s.method!r}, "
             f"{s.rays_per_pixel} ray(s) per pixel")
    times = table(["pass", "GPU ms"], timings_rows(frame.timings), caption=f"wall {frame.wall_ms:.1f} ms")
    return (f"<div><b>{html.escape(title)}</b><table><tr><td style='vertical-align:top'>"
            f"{img_tag(frame_png(frame), 'final image')}</td><td style='vertical-align:top'>{times}</td></tr>"
            f"</table></div>")


def _gbuffer_tiles(g) -> list[list[tuple[np.ndarray, str]]]:
    lit, normal, depth, coverage = g.lit, g.normal, g.depth, g.coverage
    out = []
    for k in range(g.layers):
        grey, (lo, hi) = depth_grey(depth[k], coverage[k])
        span = f"{lo:.3g}–{hi:.3g}" if math.isfinite(lo) else "empty"
        out.append([(srgb(lit[k]), f"layer {k}: lit"), (normals(normal[k], coverage[k]), f"layer {k}: normal"),
                    (grey, f"layer {k}: depth {span}")])
    return out


def gbuffer_png(g) -> bytes:
    return png(grid([[t for t, _ in row] for row in _gbuffer_tiles(g)]))


def gbuffer_html(g) -> str:
    cov = g.coverage.reshape(g.layers, -1).mean(axis=1)
    rows = "".join(f"<tr><td>{figure(tiles)}</td></tr>" for tiles in _gbuffer_tiles(g))
    return (f"<div><b>GBuffer, {g.layers} layer(s); coverage "
            + ", ".join(f"{100 * c:.0f} %" for c in cov) + f"</b><table>{rows}</table></div>")


def _ray_tiles(rays, layers: int) -> list[tuple[np.ndarray, str]]:
    hit = rays.hit
    steps = rays.steps
    traced = rays.traced
    n = hit.shape[0]
    top = float(np.percentile(steps[np.broadcast_to(traced, steps.shape)], 99)) if traced.any() else 1.0
    mean_steps = steps.mean(axis=0)
    return [
        (colormap(hit.mean(axis=0), 0.0, 1.0, "gray"), f"hits: share of the {n} ray(s) per pixel"),
        (colormap(rays.hit_layer[0], 0.0, float(layers), "viridis"), f"hit layer of ray 0: 0 = miss … {layers}"),
        (colormap(mean_steps, 0.0, max(top, 1.0), "magma"), f"depth fetches per ray: 0 … {top:.0f}"),
    ]


def rays_png(rays, layers: int) -> bytes:
    return png(grid([[t for t, _ in _ray_tiles(rays, layers)]]))


def rays_html(rays, layers: int) -> str:
    hit, traced = rays.hit, rays.traced
    n, h, w = hit.shape
    m = np.broadcast_to(traced, hit.shape)
    share = float(hit[m].mean()) if m.any() else math.nan
    stats = table(["rays", "traced pixels", "hit share", "mean fetches"],
                  [[f"{n} x {w}x{h}", int(traced.sum()), share, rays.mean_fetches()]])
    return f"<div><b>RayResults</b>{stats}{figure(_ray_tiles(rays, layers))}</div>"


def settings_html(settings) -> str:
    from dataclasses import fields

    meta = {f.name: f for f in fields(settings)}
    changed = settings.changed()
    if not changed:
        return "<div><b>Settings</b>: every field at its default (<code>Settings.describe()</code> lists them)</div>"
    rows = [[k, repr(v), repr(meta[k].default), meta[k].metadata.get("unit", ""), meta[k].metadata.get("doc", "")]
            for k, v in changed.items()]
    return ("<div>" + table(["field", "value", "default", "unit", "meaning"], rows,
                            caption=f"Settings: {len(rows)} field(s) differ from the defaults") + "</div>")


# -- Jupyter ---------------------------------------------------------------------------------------
# The result classes know nothing of how they are drawn: this module, the view, gives them their
# rich representations, so that the renderer, the settings and the references never import it.

def install() -> None:
    """Gives the result classes their Jupyter representations (done when ssrlab is imported)."""
    Frame._repr_png_ = lambda self: frame_png(self)  # the final image, sRGB
    Frame._repr_html_ = lambda self: frame_html(self)  # the image beside a table of GPU time per pass
    GBuffer._repr_png_ = lambda self: gbuffer_png(self)  # per layer: lit colour, normal, depth
    GBuffer._repr_html_ = lambda self: gbuffer_html(self)
    RayResults._repr_png_ = lambda self: rays_png(self, self._frame.settings.layers)
    RayResults._repr_html_ = lambda self: rays_html(self, self._frame.settings.layers)
    Settings._repr_html_ = lambda self: settings_html(self)  # the fields that differ from the defaults
