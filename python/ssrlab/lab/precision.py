"""Depth precision against the near/far ratio (seed 000 2.3.4 depth linearisation,
seed 002 4.6.3 reversed depth).

A fixed scene (a mirror floor with boxes at 15 to 320 units, each 10 % of its distance tall,
so every one covers about as many pixels) is rendered with the far plane at 1000 and the near
plane at far / ratio, in both depth conventions. For every ratio and mode:

* view-depth reconstruction error: frame.gbuffer.depth (from the depth buffer) against the
  exact view depth of the primary ray's first hit (Embree on the CPU, float64 geometry), as a
  relative error, per distance bin;
* hit-position error: SSR mirror rays against the per-ray reference (the very rays traced
  against the triangles), in pixels, per distance bin of the ray origin; an SSR hit where the
  true ray hits nothing on screen (a false hit, depth acne) counts as an infinite error.

Only pixels farther than 12 units are scored, so the near plane (at most 10) clips nothing
that is scored and every ratio scores the same pixels.
"""

from __future__ import annotations

import numpy as np

from .. import _core
from ..scene import Camera, Environment, Material, Scene, directional_light
from ..settings import Settings

FAR = 1000.0
RATIOS = (1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8)
MODES = ("standard", "reversed_z")
DISTANCE_BINS = (12.0, 25.0, 50.0, 100.0, 200.0, 450.0)
WALL_DISTANCE = 450.0
BOX_DISTANCES = (15.0, 30.0, 60.0, 120.0, 240.0, 320.0)


def precision_scene() -> Scene:
    s = Scene()
    s.name = "depth_precision"
    s.add_plane((0, 0, -0.5 * (WALL_DISTANCE + 11.0)), (2000, WALL_DISTANCE - 11.0), name="floor",
                material=Material(base_color=(0.6, 0.6, 0.6), roughness=0.0, metallic=1.0, reflectivity=1.0))
    # A back wall, so that every floor pixel's mirror ray truly hits something on screen.
    s.add_box((0, 60, -WALL_DISTANCE - 5), (2000, 120, 10), name="wall",
              material=Material(base_color=(0.3, 0.5, 0.8)))
    for i, d in enumerate(BOX_DISTANCES):
        size = 0.1 * d
        x = (-1) ** i * 0.08 * d
        s.add_box((x, size / 2, -d), (size, size, size), rotation_y=25.0 * i, name=f"box{d:g}",
                  material=Material(base_color=(0.9, 0.4 + 0.08 * i, 0.2)))
    s.add_light(directional_light((0.4, -1.0, -0.3), cast_shadow=False))
    s.environment = Environment.constant((0.3, 0.35, 0.4))
    return s


def camera(ratio: float) -> Camera:
    return Camera(position=(0.0, 3.0, 0.0), target=(0.0, 0.0, -60.0), fov_y=40.0, near=FAR / ratio, far=FAR)


def primary_view_depth(scene: Scene, frame) -> np.ndarray:
    """(H, W) exact view depth of each pixel's first hit (inf where the ray hits nothing)."""
    s = frame.settings
    V = np.asarray(frame.view_matrix, np.float64)
    P = np.asarray(frame.projection_matrix, np.float64)
    # View rays from the projection's x and y scales only: no far-plane point (analytic.pixel_rays
    # un-projects ndc z = 1, which a float32 matrix cannot resolve at far/near = 1e8).
    j, i = np.meshgrid(np.arange(s.width) + 0.5, np.arange(s.height) + 0.5)
    x_ndc, y_ndc = j / s.width * 2 - 1, 1 - i / s.height * 2
    view_dir = np.stack([x_ndc / P[0, 0], y_ndc / P[1, 1], -np.ones_like(j)], -1)
    inv_v = np.linalg.inv(V)
    cam = inv_v[:3, 3]
    d = view_dir @ inv_v[:3, :3].T
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    h, w = d.shape[:2]
    o = np.broadcast_to(cam, (h * w, 3)).astype(np.float32)
    hits = _core.embree_intersect(scene, o, d.reshape(-1, 3).astype(np.float32), 0.0, 1e30)
    t = np.where(hits["object"] >= 0, hits["t"], np.inf).reshape(h, w).astype(np.float64)
    forward = -np.asarray(frame.view_matrix, np.float64)[2, :3]  # the camera's viewing axis, world space
    return t * (d @ forward)


def measure(renderer, ratio: float, mode: str, width: int = 320, height: int = 180, method: str = "linear",
            scene: Scene | None = None) -> dict:
    """One ratio and depth mode: per distance bin, the view-depth error and hit-position error."""
    import warnings

    scene = scene if scene is not None else precision_scene()
    # Default settings but for mirror rays (one deterministic ray per pixel), no border fade and
    # rays long enough to reach the back wall.
    s = Settings(width=width, height=height, depth_mode=mode, method=method, sampling="mirror",
                 max_steps=4096, fade_border=0.0, shadow_map_size=0, max_distance=2000.0)
    with warnings.catch_warnings():  # the study renders past the safe ratio on purpose
        warnings.simplefilter("ignore")
        frame = renderer.render(scene, camera(ratio), s)
    g = frame.gbuffer
    truth_depth = primary_view_depth(scene, frame)
    scored = g.coverage[0] & np.isfinite(truth_depth) & (truth_depth > DISTANCE_BINS[0])
    with np.errstate(invalid="ignore"):
        depth_err = np.abs(g.depth[0].astype(np.float64) - truth_depth) / truth_depth

    truth = frame.reference("per_ray")
    rays = frame.rays
    # Every SSR hit is scored: against the true hit when the ray truly hits something on
    # screen, as infinitely wrong when it does not (a false hit: depth acne).
    both = rays.hit[0] & scored & rays.traced
    err_px = np.where(truth.on_screen[0], np.linalg.norm(rays.hit_pixel[0] - truth.hit_pixel[0], axis=-1), np.inf)
    true_hits = truth.on_screen[0] & scored & rays.traced

    row = {"ratio": ratio, "mode": mode, "near": FAR / ratio, "far": FAR, "width": width, "height": height,
           "bins": []}
    for lo, hi in zip(DISTANCE_BINS[:-1], DISTANCE_BINS[1:]):
        inb = (truth_depth >= lo) & (truth_depth < hi)
        dm, hm, tm = scored & inb, both & inb, true_hits & inb
        row["bins"].append({
            "lo": lo, "hi": hi, "pixels": int(dm.sum()),
            "depth_rel_median": float(np.median(depth_err[dm])) if dm.any() else np.nan,
            "depth_rel_p99": float(np.percentile(depth_err[dm], 99)) if dm.any() else np.nan,
            "rays": int(hm.sum()),
            "hit_px_median": float(np.median(err_px[hm])) if hm.any() else np.nan,
            "hit_px_p95": float(np.percentile(err_px[hm], 95)) if hm.any() else np.nan,
            "found": float((hm & tm).sum() / tm.sum()) if tm.any() else np.nan,
            "false_hits": float((hm & ~tm).sum() / hm.sum()) if hm.any() else np.nan,
        })
    row["depth_rel_p99"] = float(np.percentile(depth_err[scored], 99)) if scored.any() else np.nan
    row["depth_rel_median"] = float(np.median(depth_err[scored])) if scored.any() else np.nan
    row["hit_px_median"] = float(np.median(err_px[both])) if both.any() else np.nan
    row["hit_px_p95"] = float(np.percentile(err_px[both], 95)) if both.any() else np.nan
    row["found"] = float((both & true_hits).sum() / true_hits.sum()) if true_hits.any() else np.nan
    row["false_hits"] = float((both & ~true_hits).sum() / both.sum()) if both.any() else np.nan
    row["rays"] = int(both.sum())
    frame.release()
    return row


def study(renderer, ratios=RATIOS, modes=MODES, width: int = 320, height: int = 180, method: str = "linear"):
    """Every (ratio, mode) of measure(), in order."""
    scene = precision_scene()
    return [measure(renderer, r, m, width, height, method, scene) for m in modes for r in ratios]


def worst_bin_p95(row: dict) -> float:
    """The largest 95th-percentile hit-position error over the distance bins that have rays."""
    vals = [b["hit_px_p95"] for b in row["bins"] if b["rays"] > 0]
    return max(vals) if vals else float("nan")


def under_one_pixel(row: dict, baseline_found: float) -> bool:
    """The criterion the README states: in every distance bin the 95th percentile of the
    hit-position error (false hits counted as infinite) is under one pixel, and SSR still finds
    at least 90 % as many of the true on-screen hits as at the smallest ratio."""
    return bool(row["rays"] > 0 and worst_bin_p95(row) < 1.0 and row["found"] >= 0.9 * baseline_found)


def largest_safe_ratio(rows, mode: str) -> float | None:
    """The largest ratio up to which every ratio of `mode` meets under_one_pixel (None: not even
    the smallest)."""
    mine = sorted((r for r in rows if r["mode"] == mode), key=lambda r: r["ratio"])
    if not mine:
        return None
    best = None
    for r in mine:
        if not under_one_pixel(r, mine[0]["found"]):
            break
        best = r["ratio"]
    return best


def table(rows) -> str:
    """A text table: one line per (mode, ratio)."""
    lines = ["| mode | far/near | near | view-depth rel. error (median / p99) | hit error median / p95 (px) "
             "| worst distance bin p95 (px) | false hits | true hits found |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['mode']} | {r['ratio']:.0e} | {r['near']:.0e} | {r['depth_rel_median']:.1e} / "
                     f"{r['depth_rel_p99']:.1e} | {r['hit_px_median']:.2f} / {r['hit_px_p95']:.2f} | {worst_bin_p95(r):.2f} | "
                     f"{100 * r['false_hits']:.1f} % | {100 * r['found']:.1f} % |")
    return "\n".join(lines)
