"""The evaluations of the seeds, reproduced: each function runs the paper's experiment as
sweeps (``ssrlab.bench``) at a scale, and checks each of the paper's findings against what
was measured, with a verdict computed from the numbers (never written by hand).

    exp = experiments.layers(scale="small")     # seed 000, Figs. 3.3, 3.4, 3.6
    print(exp.table())                          # claim | ours | verdict

Scales: "small" (96x54 images, one timed run, 16 reference rays: seconds, for tests) and
"full" (640x360, median of 5 runs after 2 warm-ups, 256 reference rays: minutes, by hand); with
TAA the runs are the frames of one sequence (see TAA below).
Errors are reported against two references: the thesis's own ground truth (32 rays per
pixel, 16 layers, stride 1, screen space: how the thesis made its figures) and the converged
reference traced against the triangles (the truth). The thesis's findings are judged on the
reference the thesis used.

TAA: the thesis measured every figure with its temporal anti-aliasing on (seed 000, 2.5 and
3.2: two alternating quarter-pixel jitters, the mean of this frame and the previous one), so
the thesis's experiments (`layers`, `downscale_rays_stride`) default to ``taa="thesis"``: each
configuration renders one sequence of the static camera (``run.sweep(sequence=True)``),
warm-up frames first (they fill the one-frame history), then the timed frames; times are the medians
over the timed frames, per pass (reproject and taa included), and the error is the mean over
the timed frames (each draws new rays, so one frame's error is one seed's draw; the mean is the
expected error of a TAA frame). Both references are unjittered: the thesis's ground truth (as
the thesis made it) and the converged reference. TAA's blend of two jittered frames smooths the
noise of the rays but also spreads every edge over the two jittered positions, each a quarter
pixel off that unjittered image's, so TAA lowers the error where the rays' noise dominates
(reflections) and can raise it where edges do. ``taa="off"`` measures single frames, without
TAA (the README's earlier table). Seed 002 states no TAA for its tracing claims, and TAA does
not change what a trace costs or fetches, so `hiz_vs_linear` defaults to ``taa="off"``.

Timing findings are judged only on timings that can bear a verdict (``timing_doubt``): at
least MIN_JUDGED_REPEATS timed runs per configuration (so a spread is measured), times of at
least MIN_JUDGED_MS, and a difference larger than the spread of the repeats (their
interquartile ranges). Otherwise the verdict is "too small to judge" and `ours` says why; at
the "small" scale (one timed run) every timing finding is.

Used by notebooks/*.ipynb and benchmarks/studies/thesis_findings.py.
"""

from __future__ import annotations

import dataclasses
import os

import numpy as np

from . import plan, run
from .timing import MIN_JUDGED_MS, MIN_JUDGED_REPEATS, TOO_SMALL, target_verdict, timing_doubt  # noqa: F401

SCALES = {
    "small": dict(width=96, height=54, repeats=1, warmup=1, reference_rays=16),
    "full": dict(width=640, height=360, repeats=5, warmup=2, reference_rays=256),
}

# Seed 000, 3.2: four rays per pixel, stride 4, half-resolution tracing, 250 steps (and TAA).
THESIS_SETTINGS = dict(rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250)

REFERENCES = ("thesis", "converged")
TAA_MODES = ("off", "thesis", "clamped")  # Settings.taa


def _check_taa(taa) -> str:
    if taa not in TAA_MODES:
        raise ValueError(f"taa must be one of {', '.join(TAA_MODES)}, got {taa!r}")
    return taa


@dataclasses.dataclass
class Finding:
    source: str   # where the paper says it
    claim: str    # what the paper found
    ours: str     # what we measured, with figures
    verdict: str  # "agree", "partly", "disagree" or TOO_SMALL (timings that cannot bear a verdict)


@dataclasses.dataclass
class Experiment:
    name: str
    scale: str
    rows: dict[str, list[dict]]  # reference kind -> sweep rows (same configurations, same order)
    findings: list[Finding]
    device: str = ""
    taa: str = "off"  # Settings.taa of every configuration ("off": single frames)

    def table(self) -> str:
        """The findings as a Markdown table."""
        lines = ["| finding (source) | ours | verdict |", "|---|---|---|"]
        for f in self.findings:
            lines.append(f"| {f.claim} ({f.source}) | {f.ours} | **{f.verdict}** |")
        return "\n".join(lines)


def _judged(ours: str, verdict: str, doubts: list[str | None]) -> tuple[str, str]:
    """(ours, verdict), or (ours with the reason, TOO_SMALL) when a timing cannot be judged."""
    doubt = next((d for d in doubts if d), None)
    if doubt is None:
        return ours, verdict
    return f"{ours} ({TOO_SMALL}: {doubt})", TOO_SMALL


def scale_parameters(scale: str | None = None) -> dict:
    """The parameters of a scale; None reads $SSRLAB_NOTEBOOK_SCALE (default "full")."""
    scale = scale or os.environ.get("SSRLAB_NOTEBOOK_SCALE", "full")
    if scale not in SCALES:
        raise ValueError(f"scale must be one of {', '.join(SCALES)}, got {scale!r}")
    return dict(SCALES[scale], name=scale)


def _sweeps(grid, scenes, base, p, references=REFERENCES, progress=False, executor=None, taa="off"):
    # TAA needs a sequence: warmup + repeats frames of the static camera (run.sweep(sequence=True)),
    # as many frames as the single-frame protocol renders.
    common = dict(grid=grid, scenes=scenes, base=dict(base, width=p["width"], height=p["height"], taa=taa),
                  repeats=p["repeats"], warmup=p["warmup"], progress=progress, executor=executor,
                  sequence=taa != "off")
    out = {}
    for ref in references:
        rays = p["reference_rays"] if ref == "converged" else None
        out[ref] = run.sweep(**common, reference=ref, reference_rays=rays)
    return out


def _series(rows, scene_label, key, value_key):
    pts = [(r[f"s_{key}"], r[value_key]) for r in rows if r["scene"] == scene_label]
    xs = np.array([p[0] for p in pts], float)
    ys = np.array([np.nan if p[1] is None else p[1] for p in pts], float)
    return xs, ys


def linear_fit(xs: np.ndarray, ys: np.ndarray) -> tuple[float, float, float]:
    """Slope, intercept and R^2 of a least-squares line."""
    slope, intercept = np.polyfit(xs, ys, 1)
    resid = ys - (slope * xs + intercept)
    r2 = 1 - np.sum(resid ** 2) / max(np.sum((ys - ys.mean()) ** 2), 1e-300)
    return float(slope), float(intercept), float(r2)


def _drops(errors: np.ndarray) -> np.ndarray:
    """Error removed by each added step: drops[i] = e[i] - e[i+1]."""
    return errors[:-1] - errors[1:]


TRACE_COLUMNS = ("gpu_trace_linear_ms", "gpu_trace_hiz_ms", "gpu_hiz_build_ms")


def trace_ms(row: dict) -> float:
    """GPU time of the ray trace itself: trace_linear, or trace_hiz plus its pyramid build."""
    return sum(row.get(k) or 0.0 for k in TRACE_COLUMNS)


def _device(rows) -> str:
    r = next(iter(rows.values()))[0]
    return f"{r['gl_renderer']} ({r['device']})"


# -- seed 000, 3.2.1: G-buffer depth ----------------------------------------------------------------
LAYER_SCENES = [{"name": "spheres_and_boxes", "with_suzanne": True}, "spheres_and_boxes", "box_stack"]


def layers(scale: str | None = None, *, progress: bool = False, executor=None, taa: str = "thesis") -> Experiment:
    """Figs. 3.3, 3.4, 3.6: layers 1-8 on spheres_and_boxes with and without Suzanne (the thesis's
    elephant) and on box_stack, at the thesis's settings (TAA as `taa`, see the module notes)."""
    p = scale_parameters(scale)
    taa = _check_taa(taa)
    grid = {"layers": list(range(1, 9))}
    rows = _sweeps(grid, LAYER_SCENES, THESIS_SETTINGS, p, progress=progress, executor=executor, taa=taa)
    thesis = rows["thesis"]
    labels = [plan.scene_label(s) for s in LAYER_SCENES]
    findings = []

    r2s, per_layer, doubts = [], [], []
    for label in labels:
        xs, ts = _series(thesis, label, "layers", "time_frame_ms")
        slope, _, r2 = linear_fit(xs, ts)
        r2s.append(r2)
        per_layer.append(slope)
        doubts.append(timing_doubt([r for r in thesis if r["scene"] == label], "time_frame_ms"))
    findings.append(Finding(
        "seed 000, 3.2.1", "rendering time grows linearly with the number of layers",
        *_judged("frame time against layers: R² " + ", ".join(f"{r:.3f}" for r in r2s) + "; "
                 + ", ".join(f"{s:.2f}" for s in per_layer) + " ms per added layer",
                 "agree" if min(r2s) >= 0.95 else "partly" if min(r2s) >= 0.8 else "disagree", doubts)))

    tops, third_first, box_drops, share = [], [], None, []
    for label in labels:
        _, es = _series(thesis, label, "layers", "thesis_error")
        d = _drops(es)  # d[0]: 1->2, d[1]: 2->3
        tops.append(set(np.argsort(-d)[:2]) == {0, 1})
        total = es[0] - es.min()
        share.append((es[0] - es[2]) / total if total > 0 else 0.0)  # share of the best reduction done by layer 3
        if "box_stack" not in label:
            third_first.append((d[1], d[0]))
        else:
            box_drops = d
    findings.append(Finding(
        "seed 000, 3.2.1", "the 2nd and 3rd layers reduce the error most",
        f"layers 2 and 3 are the two largest error drops in {sum(tops)} of {len(tops)} scenes; they remove "
        + ", ".join(f"{100 * s:.0f} %" for s in share) + " of the largest error reduction layers reach",
        "agree" if all(tops) else "partly" if any(tops) else "disagree"))
    findings.append(Finding(
        "seed 000, 3.2.1", "with the occluder scenes, the 3rd layer lowers the error more than the 2nd",
        "; ".join(f"3rd {a:.4f} vs 2nd {b:.4f}" for a, b in third_first),
        "agree" if all(a > b for a, b in third_first) else "partly" if any(a > b for a, b in third_first)
        else "disagree"))
    if box_drops is not None:
        monotone = float(np.mean(box_drops[1:] <= box_drops[:-1] + 1e-9))
        findings.append(Finding(
            "seed 000, 3.2.1", "on the box scene each further layer lowers the error a little less",
            f"{100 * monotone:.0f} % of successive drops shrink ("
            + ", ".join(f"{x:.4f}" for x in box_drops) + ")",
            "agree" if monotone >= 0.8 else "partly" if monotone >= 0.5 else "disagree"))
    conv = rows["converged"]
    gains = []
    for label in labels:
        _, ec = _series(conv, label, "layers", "thesis_error")
        gains.append(1 - ec[-1] / ec[0] if ec[0] > 0 else 0.0)
    cost = ", ".join(f"{s:.1f}" for s in per_layer) + " ms per layer"
    if any(doubts):  # the verdict rests on the errors; the cost is quoted only when it can be trusted
        cost += f" ({TOO_SMALL})"
    findings.append(Finding(
        "seed 000, 4.2", "more layers improve reflections, at a large cost",
        "against the converged reference, 8 layers lower the error by "
        + ", ".join(f"{100 * g:.0f} %" for g in gains) + " at " + cost,
        "agree" if all(g > 0 for g in gains) else "partly" if any(g > 0 for g in gains) else "disagree"))
    return Experiment("thesis_layers", p["name"], rows, findings, _device(rows), taa)


# -- seed 000, 3.2.2-3.2.4: downscaling, rays per pixel, stride ----------------------------------------
PARAMETER_SCENE = "hall"  # our stand-in for the Sibenik scene of Fig. 3.7 (one layer suffices)


def downscale_rays_stride(scale: str | None = None, *, progress: bool = False, executor=None,
                          taa: str = "thesis") -> Experiment:
    """Figs. 3.8, 3.9, 3.10 on the hall: downscale 1, 2, 4; rays per pixel 1-16; stride 1-16
    (TAA as `taa`, see the module notes)."""
    p = scale_parameters(scale)
    taa = _check_taa(taa)
    base = dict(THESIS_SETTINGS, layers=1)
    sweeps = {
        "downscale": _sweeps({"downscale": [1, 2, 4]}, [PARAMETER_SCENE], base, p, progress=progress,
                             executor=executor, taa=taa),
        "rays_per_pixel": _sweeps({"rays_per_pixel": [1, 2, 4, 8, 16]}, [PARAMETER_SCENE], base, p,
                                  progress=progress, executor=executor, taa=taa),
        "stride": _sweeps({"stride": [1.0, 2.0, 4.0, 8.0, 16.0]}, [PARAMETER_SCENE], base, p, progress=progress,
                          executor=executor, taa=taa),
    }
    label = plan.scene_label(PARAMETER_SCENE)
    findings = []

    _, e = _series(sweeps["downscale"]["thesis"], label, "downscale", "thesis_error")
    _, t = _series(sweeps["downscale"]["thesis"], label, "downscale", "time_reflections_ms")
    err_up, time_down = e[1] / e[0] - 1, 1 - t[1] / t[0]
    down_rows = [r for r in sweeps["downscale"]["thesis"] if r["scene"] == label]
    findings.append(Finding(
        "seed 000, 3.2.2", "half resolution costs little error for much time",
        *_judged(f"full→half: error {100 * err_up:+.0f} %, reflection time {-100 * time_down:+.0f} %",
                 "agree" if err_up < time_down else "disagree",
                 [timing_doubt(down_rows[:2], "time_reflections_ms", pairwise=True)])))
    d1, d2 = e[1] - e[0], e[2] - e[1]
    findings.append(Finding(
        "seed 000, 3.2.2", "half→quarter raises the error far more than full→half",
        f"error +{d1:.4f} full→half, +{d2:.4f} half→quarter",
        "agree" if d2 > 2 * d1 else "partly" if d2 > d1 else "disagree"))

    xs, t = _series(sweeps["rays_per_pixel"]["thesis"], label, "rays_per_pixel", "time_reflections_ms")
    _, _, r2 = linear_fit(xs, t)
    findings.append(Finding(
        "seed 000, 3.2.3", "time grows linearly with rays per pixel",
        *_judged(f"reflection time against rays: R² {r2:.3f}, " + ", ".join(f"{v:.1f}" for v in t) + " ms",
                 "agree" if r2 >= 0.95 else "partly" if r2 >= 0.8 else "disagree",
                 [timing_doubt([r for r in sweeps["rays_per_pixel"]["thesis"] if r["scene"] == label],
                               "time_reflections_ms")])))
    _, e = _series(sweeps["rays_per_pixel"]["thesis"], label, "rays_per_pixel", "thesis_error")
    d = _drops(e)  # 1->2, 2->4, 4->8, 8->16
    findings.append(Finding(
        "seed 000, 3.2.3", "2→4 rays per pixel lowers the error much more than other steps",
        "error drops 1→2, 2→4, 4→8, 8→16: " + ", ".join(f"{x:.4f}" for x in d),
        "agree" if int(np.argmax(d)) == 1 else "disagree"))

    stride_rows = [r for r in sweeps["stride"]["thesis"] if r["scene"] == label]
    t = np.array([r["time_reflections_ms"] for r in stride_rows])  # trace + resolve: the thesis's measure
    tt = np.array([trace_ms(r) for r in stride_rows])               # the trace alone
    _, e = _series(sweeps["stride"]["thesis"], label, "stride", "thesis_error")
    r12, r24 = tt[1] / tt[0], t[2] / t[1]
    findings.append(Finding(
        "seed 000, 3.2.4", "stride 1→2: almost all rays finish in half the time",
        *_judged(f"trace time ×{r12:.2f} (with the resolve ×{t[1] / t[0]:.2f})",
                 "agree" if r12 <= 0.65 else "partly" if r12 <= 0.8 else "disagree",
                 [timing_doubt(stride_rows[:2], TRACE_COLUMNS, pairwise=True)])))
    findings.append(Finding(
        "seed 000, 4.1", "stride 2→4 cuts the rendering time by about 25 %",
        *_judged(f"trace + resolve time {100 * (r24 - 1):+.0f} % (trace alone {100 * (tt[2] / tt[1] - 1):+.0f} %)",
                 "agree" if 0.6 <= r24 <= 0.85 else "partly" if r24 < 0.95 else "disagree",
                 [timing_doubt(stride_rows[1:3], "time_reflections_ms", pairwise=True)])))
    rising = float(np.mean(np.diff(e) >= -1e-9))
    findings.append(Finding(
        "seed 000, 3.2.4", "the error rises steadily with stride",
        "errors " + ", ".join(f"{x:.4f}" for x in e) + f" ({100 * rising:.0f} % of steps rise)",
        "agree" if rising == 1.0 else "partly" if rising >= 0.5 else "disagree"))

    rows = {f"{k}/{ref}": v for k, s in sweeps.items() for ref, v in s.items()}
    return Experiment("thesis_downscale_rays_stride", p["name"], rows, findings, _device(rows), taa)


# -- seed 002: Hi-Z against linear marching ------------------------------------------------------------
HIZ_SCENES = ["hall", "spheres_and_boxes"]
LENGTH_BINS = ((0, 16), (16, 64), (64, 256), (256, 1e9))


def fetches_by_ray_length(renderer, scene, settings_a, settings_b, bins=LENGTH_BINS) -> list[dict]:
    """Mean depth fetches per ray of two tracers over the same rays, binned by the screen
    distance (pixels) from the ray's origin to the hit both found."""
    a = renderer.render(scene, settings=settings_a).rays
    b = renderer.render(scene, settings=settings_b).rays
    both = a.hit & b.hit
    _, h, w = a.hit.shape
    d = settings_a.downscale
    jj, ii = np.meshgrid((np.arange(w) * d + d // 2) + 0.5, (np.arange(h) * d + d // 2) + 0.5)
    dist = np.linalg.norm(b.hit_pixel - np.stack([jj, ii], -1)[None], axis=-1)
    out = []
    for lo, hi in bins:
        m = both & (dist >= lo) & (dist < hi)
        out.append({"lo": lo, "hi": hi, "rays": int(m.sum()),
                    "fetches_a": float(a.steps[m].mean()) if m.any() else float("nan"),
                    "fetches_b": float(b.steps[m].mean()) if m.any() else float("nan")})
    return out


def hiz_vs_linear(scale: str | None = None, *, progress: bool = False, executor=None, renderer=None,
                  taa: str = "off") -> Experiment:
    """Seed 002's claim that hierarchical tracing is far faster than linear marching, most for long
    rays: time and error of linear (stride 1-8) and Hi-Z, and fetches per ray by ray length.
    Single frames by default: seed 002 states no TAA for these claims (see the module notes);
    the fetch counts are always of single frames (TAA does not change a trace)."""
    from ..settings import Settings

    p = scale_parameters(scale)
    taa = _check_taa(taa)
    base = dict(rays_per_pixel=1, layers=1)
    linear = _sweeps({"stride": [1.0, 2.0, 4.0, 8.0]}, HIZ_SCENES, dict(base, method="linear"), p,
                     references=("converged",), progress=progress, executor=executor, taa=taa)
    hiz = _sweeps({"method": ["hiz"]}, HIZ_SCENES, base, p, references=("converged",), progress=progress,
                  executor=executor, taa=taa)  # Hi-Z ignores the stride: one configuration per scene
    conv = linear["converged"] + hiz["converged"]
    rows = {"converged": conv}
    renderer = renderer or run.worker_renderer()
    findings, ratios, time_ratios, err_pairs, short_ratios, long_ratios, doubts = [], [], [], [], [], [], []
    from .. import scenes as scene_builders

    for name in HIZ_SCENES:
        label = plan.scene_label(name)
        lin = next(r for r in conv if r["scene"] == label and r["s_method"] == "linear" and r["s_stride"] == 1.0)
        hiz = next(r for r in conv if r["scene"] == label and r["s_method"] == "hiz")
        time_ratios.append(trace_ms(lin) / trace_ms(hiz))
        doubts.append(timing_doubt([lin, hiz], TRACE_COLUMNS, pairwise=True))
        err_pairs.append((lin["thesis_error"], hiz["thesis_error"]))
        s = Settings(width=p["width"], height=p["height"], **base)
        bins = fetches_by_ray_length(renderer, scene_builders.load(name), s.replace(method="linear", stride=1.0),
                                     s.replace(method="hiz"))
        filled = [b for b in bins if b["rays"] >= 20]
        ratios.append((label, filled))
        short_ratios.append(filled[0]["fetches_a"] / filled[0]["fetches_b"])
        long_ratios.append(filled[-1]["fetches_a"] / filled[-1]["fetches_b"])
    equal = all(abs(a - b) <= 0.05 * max(a, b, 1e-12) for a, b in err_pairs)
    findings.append(Finding(
        "seed 002, 4.3", "Hi-Z tracing is orders of magnitude faster than linear marching",
        *_judged("at equal error (" + ", ".join(f"{a:.4f} vs {b:.4f}" for a, b in err_pairs) + "), linear/1 traces in "
                 + ", ".join(f"{x:.1f}×" for x in time_ratios) + " Hi-Z's time (its pyramid build included)",
                 "agree" if min(time_ratios) >= 10 and equal else "partly" if min(time_ratios) > 1.5 else "disagree",
                 doubts)))
    findings.append(Finding(
        "seed 002, 4.3", "linear marching is only fast for short travels; the longer the ray, the more Hi-Z wins",
        "; ".join(f"{label}: fetch ratio " + ", ".join(
            f"{b['lo']:g}–{b['hi']:g}px {b['fetches_a'] / b['fetches_b']:.1f}×" if b["hi"] < 1e9 else
            f"≥{b['lo']:g}px {b['fetches_a'] / b['fetches_b']:.1f}×" for b in filled) for label, filled in ratios),
        "agree" if all(l > 2 * s for l, s in zip(long_ratios, short_ratios)) else "partly"
        if all(l > s for l, s in zip(long_ratios, short_ratios)) else "disagree"))
    findings.append(Finding(
        "seed 002, 4.7.1", "near the starting surface linear steps are cheaper than the Hi-Z traversal",
        "rays under 16 px: linear/Hi-Z fetch ratio " + ", ".join(f"{x:.2f}×" for x in short_ratios),
        "agree" if all(x < 1 for x in short_ratios) else "disagree"))
    exp = Experiment("hiz_vs_linear", p["name"], rows, findings, _device(rows), taa)
    exp.length_bins = ratios  # for plots
    return exp


def findings_table(experiments: list[Experiment]) -> str:
    """One Markdown table of every experiment's findings."""
    lines = ["| experiment | finding (source) | ours | verdict |", "|---|---|---|---|"]
    for exp in experiments:
        for f in exp.findings:
            lines.append(f"| {exp.name} | {f.claim} ({f.source}) | {f.ours} | **{f.verdict}** |")
    return "\n".join(lines)
