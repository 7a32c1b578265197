"""The standard evaluation: every technique on the same scenes, budgets and references.

    ssrlab bench --suite standard [--quick] [--entry MODULE:NAME ...] --out DIR

Fixed scenes (SCENES: the procedural ones, a sample model on a glossy stage, the Mitsuba
cross-check's scene, the animated glTF stage at t = 1 s), fixed budgets (BUDGETS: size, G-buffer
layers, rays per pixel, the converged reference's rays, timed rounds), and every built-in
technique (TECHNIQUES) - and each --entry, a user module's UserPass run as
Settings(user_modules=(spec,), user_passes=(name,)) over the default technique - rendered with
the same settings but for the technique's own. Each frame is scored against the scene's one
converged reference (frame.reference("converged"), rendered once per scene and shared by every
technique): the thesis error, PSNR and FLIP (where installed) over the reflective pixels
(ssrlab.metrics.image_metrics); its GPU time is the frame's (Frame.timings["total"]) and of its
reflection passes, over the budget's rounds after 2 warm-up rounds, the techniques interleaved
round by round (ssrlab.lab.protocol). Everything is a record (ssrlab.lab.records) in
DIR/standard.jsonl; DIR/leaderboard.md is rendered from them. --quick runs it at a size for
checking, not for quoting (its records say quick: true).
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from . import records
from .protocol import Bench, device_header

# Every built-in technique: what it changes of the base settings (the budget's layers and rays).
TECHNIQUES = {
    "linear": dict(method="linear"),
    "hiz": dict(method="hiz"),
    "hiz, skip off": dict(method="hiz", skip=False),
    "bvh": dict(method="bvh"),
    "hiz + bvh fallback": dict(method="hiz", fallback="bvh"),
    "hiz + probes": dict(method="hiz", fallback="probes"),
    "glossy cone": dict(method="hiz", glossy="cone"),
    "glossy blur_mips": dict(method="hiz", glossy="blur_mips"),
    "hiz + svgf": dict(method="hiz", denoise="svgf"),
}
ENTRY_BASE = dict(method="hiz")  # what a user's pass runs over (it filters or replaces what hiz gives)
BUDGETS = {
    "full": dict(width=320, height=180, layers=4, rays_per_pixel=4, reference_rays=256, repeats=5),
    "quick": dict(width=48, height=32, layers=2, rays_per_pixel=1, reference_rays=8, repeats=3),
}
SCENES = ("hall", "spheres_and_boxes", "box_stack", "mirror_test", "crosscheck", "2CylinderEngine on glossy stage",
          "animated stage")
QUICK_SCENES = ("hall", "crosscheck")


def load_scene(name: str):
    import ssrlab

    if name == "crosscheck":
        from ..truth.crosscheck import crosscheck_scene

        return crosscheck_scene(0.2)  # its glossy floor: every technique has something to resolve
    if name == "2CylinderEngine on glossy stage":
        return ssrlab.scenes.load(str(ssrlab.models.find("2CylinderEngine")), stage="glossy")
    if name == "animated stage":
        from .animated_gltf import write_stage

        path = write_stage(Path(tempfile.mkdtemp(prefix="ssrlab_stage_")) / "stage.gltf")
        scene = ssrlab.scenes.load(str(path))
        scene.set_time(1.0)
        return scene
    return ssrlab.scenes.load(name)


def entry_name(spec: str) -> str:
    """An --entry's pass name: the attribute after the last ':' (MODULE:NAME)."""
    base, sep, attr = spec.rpartition(":")
    if not sep or not attr or "/" in attr:
        raise ValueError(f"--entry expects MODULE:NAME (a user module and its UserPass), got {spec!r}")
    return attr


def techniques(entries) -> dict[str, dict]:
    out = dict(TECHNIQUES)
    for spec in entries or ():
        name = entry_name(spec)
        out[f"entry: {name}"] = dict(ENTRY_BASE, user_modules=(spec,), user_passes=(name,))
    return out


def reflection_ms(timings: dict, user_passes=()) -> float:
    """The reflection passes' GPU ms, a user's passes counted with them (as a sweep row's are)."""
    from .run import REFLECTION_PASSES

    return float(sum(timings.get(p, 0.0) for p in (*REFLECTION_PASSES, *user_passes)))


def evaluate(renderer, *, quick: bool, entries=(), scenes=None, folder=None, log=print) -> Bench:
    """Runs the evaluation and returns its Bench (its records; written to `folder` where given)."""
    import ssrlab
    from ..truth.metrics import image_metrics

    budget = BUDGETS["quick" if quick else "full"]
    args = type("Args", (), {"records": folder, "records_quick": quick, "repeats": budget["repeats"], "set": []})
    bench = Bench("standard", args, renderer)
    techs = techniques(entries)
    for scene_name in scenes or (QUICK_SCENES if quick else SCENES):
        try:
            scene = load_scene(scene_name)
        except Exception as e:  # a missing sample model: the scene's rows are missing, and it says why
            log(f"{scene_name}: skipped ({type(e).__name__}: {e})")
            continue
        base = dict(width=budget["width"], height=budget["height"], layers=budget["layers"],
                    rays_per_pixel=budget["rays_per_pixel"])
        settings = {t: ssrlab.Settings(**base, **kw) for t, kw in techs.items()}
        first = renderer.render(scene, settings=settings["hiz"])
        ref = first.reference("converged", rays=budget["reference_rays"])
        truth, mask = np.array(ref.color), np.array(ref.reflective)
        first.release()
        scores = {}
        for t, s in settings.items():  # one scored frame each (seed fixed by the settings)
            f = renderer.render(scene, settings=s)
            scores[t] = image_metrics(f.color, truth, mask)
            f.release()
        times = bench.frames(renderer, scene, settings)
        log(f"{scene_name}: {int(mask.sum())} reflective pixels, reference {ref.rays_per_pixel} rays per pixel")
        for t in techs:
            params = dict(scene=scene_name, technique=t, width=base["width"], height=base["height"],
                          layers=base["layers"], rays_per_pixel=base["rays_per_pixel"],
                          reference_rays=budget["reference_rays"], entry=t.startswith("entry: "))
            bench.record(params, "frame", "ms", times[t]["total"])
            refl = [reflection_ms({k: v[i] for k, v in times[t].items()}, settings[t].user_passes)
                    for i in range(len(times[t]["total"]))]
            bench.record(params, "reflection", "ms", refl)
            sc = scores[t]
            bench.record(params, "thesis_error", "", [sc["thesis_error_reflective"]])
            bench.record(params, "psnr", "dB", [sc["psnr_reflective"]], better="higher")
            if sc.get("flip_ldr_reflective") is not None:
                bench.record(params, "flip", "", [sc["flip_ldr_reflective"]])
    return bench


def leaderboard(recs: list[dict], header: str = "") -> str:
    """The leaderboard's Markdown, rendered from the suite's records: the techniques over every
    scene (mean error, PSNR and FLIP, geometric mean of the frame's median time), then per scene."""
    techs = list(dict.fromkeys(r["params"]["technique"] for r in recs))
    scenes = list(dict.fromkeys(r["params"]["scene"] for r in recs))
    metrics = [m for m in ("thesis_error", "psnr", "flip", "frame", "reflection")
               if any(r["metric"] == m for r in recs)]

    def values(t, m):
        return [float(np.median(r["samples"])) for r in records.select(recs, m, technique=t)]

    def mean(v, geo=False):
        v = [x for x in v if x is not None and math.isfinite(x)]
        if not v:
            return "-"
        return f"{math.exp(sum(math.log(max(x, 1e-12)) for x in v) / len(v)):.3f}" if geo else f"{sum(v) / len(v):.4g}"

    rows = []
    for t in sorted(techs, key=lambda t: (mean(values(t, "thesis_error")) == "-",
                                          float(mean(values(t, "thesis_error"))) if mean(values(t, "thesis_error"))
                                          != "-" else 0.0)):
        rows.append([t] + [mean(values(t, m), geo=m in ("frame", "reflection")) for m in metrics]
                    + [str(len(values(t, "frame")))])
    names = {"thesis_error": "thesis error (mean)", "psnr": "PSNR dB (mean)", "flip": "FLIP (mean)",
             "frame": "frame ms (geo. mean)", "reflection": "reflection ms (geo. mean)"}
    out = ["# The standard evaluation", "", header, "",
           "Every technique on every scene below, scored on the reflective pixels against the scene's converged "
           "reference (one per scene, shared by every technique); errors are lower-is-better, PSNR higher; "
           "times are the median GPU ms of the timed rounds, the techniques interleaved round by round. "
           "Rows sorted by thesis error. Rendered from the records (`standard.jsonl`) by ssrlab.lab.standard.", "",
           "## Over all scenes", "", records.markdown(["technique", *[names[m] for m in metrics], "scenes"], rows), ""]
    for s in scenes:
        sub = [r for r in recs if r["params"]["scene"] == s]
        p = sub[0]["params"]
        out += [f"## {s}", "",
                f"{p['width']}x{p['height']}, {p['layers']} layer(s), {p['rays_per_pixel']} ray(s) per pixel; "
                f"reference {p['reference_rays']} rays per pixel", "",
                records.table(sub, ["technique"], "metric", digits=4, order=metrics), "",
                records.spread_note([r for r in sub if r["unit"] == "ms"]), ""]
    return "\n".join(out)


def run_suite(args) -> int:
    """`ssrlab bench --suite standard`: runs evaluate() and writes DIR/leaderboard.md."""
    import ssrlab

    if args.out is None:
        raise SystemExit("ssrlab: --suite standard needs --out DIR")
    if args.sweep_file is not None:
        raise SystemExit("ssrlab: --suite standard takes no SWEEP_FILE")
    for spec in args.entry:
        try:
            entry_name(spec)
        except ValueError as e:
            raise SystemExit(f"ssrlab: {e}") from None
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    jsonl = out / "standard.jsonl"
    if jsonl.exists() and not args.overwrite:
        print(f"ssrlab: {jsonl} exists (an earlier evaluation); --overwrite replaces it", file=sys.stderr)
        return 1
    jsonl.unlink(missing_ok=True)
    renderer = ssrlab.Renderer(args.device)
    print(device_header(renderer), flush=True)
    bench = evaluate(renderer, quick=args.quick, entries=args.entry, folder=out,
                     log=lambda s: print(s, flush=True))
    recs = bench.recorder.records
    budget = "quick" if args.quick else "full"
    header = (f"{renderer.info['renderer']} ({renderer.info['device']}), {renderer.info['vendor']}, OpenGL "
              f"{renderer.info['gl_version']}; commit {bench.recorder.commit}; `{bench.recorder.command}`; budget "
              f"{budget}" + (" (for checking, not for quoting)" if args.quick else ""))
    text = leaderboard(recs, header)
    (out / "leaderboard.md").write_text(text + "\n")
    print(text)
    print(f"wrote {out / 'leaderboard.md'} and {jsonl}")
    return 0


__all__ = ["TECHNIQUES", "BUDGETS", "SCENES", "QUICK_SCENES", "load_scene", "techniques", "evaluate", "leaderboard",
           "run_suite"]
