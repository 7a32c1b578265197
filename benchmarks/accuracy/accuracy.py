"""Accuracy of the tracers and of the ground truth, against closed forms and each other.

    python benchmarks/accuracy/accuracy.py

Prints, on mirror_test, the share of floor pixels whose mirror ray hits within 0.5 px of the
analytic mirror point (among pixels whose true hit is visible) and the median error, for the
linear (stride 1) and Hi-Z tracers at two image sizes; the hit/miss agreement of the two tracers
on every procedural scene; the converged reference against the analytic mirror image; and the
Monte-Carlo weight integral of the GLSL samplers against the GGX directional albedo. Every figure is
a record (one value: each is deterministic), and the tables are rendered from the records.

    python benchmarks/accuracy/accuracy.py [--device auto|gpu|cpu]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import ssrlab
from ssrlab.analytic import ggx_shade, mirror_test_hits, pixel_rays

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402


def directional_albedo(v, a, n=1500):
    """int f_r(v, l)(n.l) dl for GGX with Smith G and F = 1, by a midpoint rule over the half-vector CDF."""
    def g1(c):
        c2 = np.maximum(c * c, 1e-12)
        return np.where(c > 0, 2 / (1 + np.sqrt(1 + a * a * np.maximum(1 - c2, 0) / c2)), 0.0)
    u = (np.arange(n) + 0.5) / n
    T, P = np.meshgrid(np.arctan(a * np.sqrt(u / (1 - u))), 2 * np.pi * u, indexing="ij")
    h = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
    vh = h @ v
    l = 2 * vh[..., None] * h - v
    return np.where((vh > 0) & (l[..., 2] > 0), g1(l[..., 2]) * g1(v[2]) * vh / (v[2] * h[..., 2]), 0).mean()


def main() -> None:
    ap = benchmark_arguments(__doc__)
    ap.set_defaults(scenes=list(ssrlab.scenes.SCENES))  # the tracers' agreement: every procedural scene
    args = ap.parse_args()
    r = open_renderer(args)
    bench = Bench("accuracy", args, r)
    rec = bench.record
    scene = ssrlab.scenes.mirror_test()
    print("mirror_test, mirror rays: hits within 0.5 px of the analytic mirror point")
    for w, h in ((160, 90), (97, 61), (320, 180)):
        for method in ("linear", "hiz"):
            f = r.render(scene, width=w, height=h, method=method, sampling="mirror", stride=1.0)
            expected, ok = mirror_test_hits(f)
            g = f.gbuffer
            col = np.clip(np.nan_to_num(expected[..., 0]).astype(int), 0, w - 1)
            row = np.clip(np.nan_to_num(expected[..., 1]).astype(int), 0, h - 1)
            ok &= g.coverage[0] & (g.reflectivity[0] > 0.5) & g.coverage[0][row, col] & (g.reflectivity[0][row, col] < 0.5)
            err = np.linalg.norm(f.rays.hit_pixel[0] - expected, axis=-1)
            good = ok & f.rays.hit[0] & (err <= 0.5)
            params = dict(size=f"{w}x{h}", method=method, pixels=int(ok.sum()))
            rec(params, "within_half_px", "%", [100 * good.sum() / ok.sum()], better="higher")
            rec(params, "median_error", "px", [np.median(err[ok & f.rays.hit[0]])])
    bench.print_table(bench.find("within_half_px") + bench.find("median_error"), rows=("size", "method", "pixels"),
                      note=False, digits=3)
    print("\nlinear (stride 1) and Hi-Z agree on hit or miss (200x112, 2 rays per pixel)")
    for name in args.scenes:
        for layers in (1, 4):
            kw = dict(width=200, height=112, layers=layers, rays_per_pixel=2, stride=1.0)
            a = r.render(ssrlab.scenes.load(name), method="linear", **kw).rays
            b = r.render(ssrlab.scenes.load(name), method="hiz", **kw).rays
            t = np.broadcast_to(a.traced, a.hit.shape) & (a.weight > 0)
            rec(dict(scene=name, layers=layers, rays=int(t.sum())), "hit_agreement", "%",
                [100 * (a.hit == b.hit)[t].mean()], better="higher")
    bench.print_table(bench.find("hit_agreement"), rows=("scene", "layers", "rays"), note=False)
    print("\nconverged reference against the analytic mirror image (160x90, floor pixels off tile edges)")
    f = r.render(scene, width=160, height=90)
    for viewer in ("camera", "ray"):
        ref = f.reference("converged", rays=1, viewer=viewer)
        cam, d = pixel_rays(f)
        _, ok = mirror_test_hits(f)
        ok &= f.gbuffer.coverage[0] & (f.gbuffer.reflectivity[0] > 0.5)
        p = cam + d * (-cam[1] / d[..., 1])[..., None]
        # The reference's rays leave the exact floor point (no origin_bias).
        rr = d * np.array([1.0, -1.0, 1.0])
        hit = p + rr * ((ssrlab.scenes.MIRROR_WALL_Z - p[..., 2]) / rr[..., 2])[..., None]
        fx, fy = (hit[..., 0] + 4.0) % 1, hit[..., 1] % 1
        ok &= (np.minimum(fx, 1 - fx) > 1e-3) & (np.minimum(fy, 1 - fy) > 1e-3)
        tile = (np.floor(hit[..., 0] + 4.0) + np.floor(hit[..., 1])).astype(int) % 2
        albedo = np.where((tile == 0)[..., None], ssrlab.scenes.MIRROR_COLORS[0], ssrlab.scenes.MIRROR_COLORS[1])
        light = scene.lights[0]
        expected = ggx_shade(albedo, 0.0, 0.9, np.broadcast_to([0.0, 0.0, 1.0], hit.shape),
                             (cam if viewer == "camera" else p) - hit,
                             [(light.direction, np.array(light.color) * light.intensity)], scene.ambient)
        rec(dict(viewer=viewer, pixels=int(ok.sum())), "reference_max_abs_error", "",
            [np.abs(ref.reflection[ok] - expected[ok]).max()])
    bench.print_table(bench.find("reference_max_abs_error"), rows=("viewer", "pixels"), note=False, digits=6)
    print("\nGLSL samplers: Monte-Carlo weight integral over 1e5 samples against the GGX directional albedo")
    for alpha in (0.1, 0.5):
        for theta in (0, 45, 70):
            v = np.array([np.sin(np.radians(theta)), 0.0, np.cos(np.radians(theta))])
            exact = directional_albedo(v, alpha)
            rec(dict(alpha=alpha, view_deg=theta, sampling="exact"), "directional_albedo", "", [exact])
            for sampling in ("ggx", "vndf", "ggx_thesis_literal"):
                est = r.sample_reflections(sampling, alpha, v, 100_000, seed=11)["weight"].mean()
                rec(dict(alpha=alpha, view_deg=theta, sampling=sampling), "relative_error", "%",
                    [100 * (est / exact - 1)])
    print("(exact: the directional albedo; each sampler: its estimate's relative error, %)")
    bench.print_table(bench.find("directional_albedo") + bench.find("relative_error"), rows=("alpha", "view_deg"),
                      columns="sampling", note=False, digits=4)


if __name__ == "__main__":
    main()
