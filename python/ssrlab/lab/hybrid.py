"""Hybrid reflections, error against time: screen space alone, screen space with the
BVH fallback, pure BVH tracing (seed 003) and, where this build has it, screen space with
reflection probes, each with and without the SVGF denoiser, on glossy floors of `hall`,
`spheres_and_boxes` and `spheres_and_boxes` with the Suzanne glTF model.

    exp = hybrid.sweep("small")       # rows per (scene, configuration)
    exp.fronts                        # the Pareto front per scene, fastest first
    print(exp.table())                # which configuration wins at which time budget, and the verdict

Every configuration renders a static camera for `frames` frames (the denoiser's history) with one
glossy ray per pixel; the last frame is timed (GPU time of the whole frame) and scored against the
converged reference (thesis error on reflective pixels). A time budget's winner is stated only when
the front's times differ beyond the timing noise (ssrlab.experiments.timing_doubt); otherwise the
table says why not and names only the least-error configuration, which is no timing claim.

Used by notebooks/hybrid.ipynb.

Whether the hybrid keeps only true hits (the confidence test, docs/guide/hybrid.md):

    hybrid.wrong_object_hits(renderer, scene, settings)   # kept screen hits on another object
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..settings import Settings
from . import experiments, report, run

SCENES = [
    {"name": "hall", "floor_roughness": 0.2},
    {"name": "spheres_and_boxes", "floor_roughness": 0.2},
    {"name": "spheres_and_boxes", "with_suzanne": True, "floor_roughness": 0.2},  # the glTF model
]
# Every configuration: one glossy GGX ray per pixel (seed 003's setting), origin bias as
# benchmarks/studies/hybrid.py uses it (rays leave the floor close enough to meet thin edges).
BASE = dict(rays_per_pixel=1, origin_bias=0.0005, shadow_map_size=1024)
FRAMES = {"small": 4, "full": 8}
# Image size per scale: "full" is 320x180 here, not experiments.SCALES' 640x360: every
# configuration renders 8-frame sequences (2 warm-ups + 5 timed), ~1000 frames per run on llvmpipe.
SIZE = {"small": (96, 54), "full": (320, 180)}
ERROR, TIME = "thesis_error_reflective", "time_frame_ms"


def probes_available() -> bool:
    """Whether this build's Settings accepts fallback="probes" (reflection probes):
    asked of the Settings validation itself, so the sweep follows what the build offers."""
    try:
        Settings(fallback="probes")
    except ValueError:
        return False
    return True


def configurations() -> dict[str, dict]:
    """Label -> Settings fields of every reflection method compared, before the denoiser axis.
    'SSR + probes' is there only when probes_available()."""
    configs = {
        "SSR only": dict(method="linear", fallback="environment"),
        "SSR + BVH fallback": dict(method="linear", fallback="bvh"),
        "pure BVH": dict(method="bvh"),
    }
    if probes_available():
        configs["SSR + probes"] = dict(method="linear", fallback="probes")
    return configs


@dataclasses.dataclass
class HybridExperiment:
    scale: str
    rows: list[dict]                 # one per (scene, configuration, denoise); "config" names it
    fronts: dict[str, list[dict]]    # scene label -> Pareto front, fastest first
    verdicts: list[dict]             # per scene: its front, why each point's budget claim is in doubt (None: none)
    device: str
    probes: bool

    def table(self) -> str:
        """Per scene, one row per Pareto-front point, fastest first: within a frame budget from its time
        up to the next point's, it has the least error. That is a timing claim, so it "wins" only
        when its time differs from both neighbours' on the front beyond the repeats' spread
        (timing_doubt); otherwise the row says why it is too small to judge."""
        lines = ["| scene | within (frame GPU ms) | least error | thesis error | verdict |", "|---|---|---|---|---|"]
        for v in self.verdicts:
            front = v["front"]
            for i, r in enumerate(front):
                upper = f" to {front[i + 1][TIME]:.0f}" if i + 1 < len(front) else " on"
                doubt = v["doubts"][i]
                verdict = "**wins**" if doubt is None else f"**{experiments.TOO_SMALL}** (timings: {doubt})"
                iqr = r.get(TIME + "_iqr")
                spread = "" if iqr is None else f" (IQR {iqr:.0f})"
                lines.append(f"| {v['scene']} | from {r[TIME]:.0f}{spread}{upper} | "
                             f"{r['config']} | {r[ERROR]:.4f} | {verdict} |")
        return "\n".join(lines)


def sweep(scale: str | None = None, *, progress: bool = False, executor=None) -> HybridExperiment:
    """Runs every configuration on every scene at `scale` ("small": 96x54, 4 frames, one timed run,
    16 reference rays; "full": 320x180, 8 frames, median of 5 after 2 warm-ups, 256 reference rays)."""
    p = experiments.scale_parameters(scale)
    frames = FRAMES[p["name"]]
    width, height = SIZE[p["name"]]
    configs = configurations()
    rows: list[dict] = []
    for label, fields in configs.items():
        part = run.sweep(grid={"denoise": ["none", "svgf"]}, scenes=SCENES,
                           base=dict(BASE, **fields, width=width, height=height),
                           repeats=p["repeats"], warmup=p["warmup"], reference="converged",
                           reference_rays=p["reference_rays"], executor=executor, progress=progress, frames=frames)
        for r in part:
            r["_config"] = label
            r["config"] = label + (" + SVGF" if r["s_denoise"] == "svgf" else "")
        rows += part
    fronts, verdicts = {}, []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        sel = [r for r in rows if r["scene"] == scene]
        front = report.pareto_front(sel, TIME, ERROR)
        fronts[scene] = front
        # Each front point's budget is bounded by its neighbours' times: its claim stands when
        # both steps are beyond the repeats' spread (a one-point front still needs timings that
        # can be judged at all).
        doubts = []
        for i in range(len(front)):
            pairs = [front[j:j + 2] for j in (i - 1, i) if j >= 0 and j + 1 < len(front)] or [front[i:i + 1]]
            doubts.append(next((d for d in (experiments.timing_doubt(p, TIME, pairwise=True) for p in pairs) if d),
                               None))
        verdicts.append(dict(scene=scene, front=front, doubts=doubts, best=min(sel, key=lambda r: r[ERROR])))
    r0 = rows[0]
    return HybridExperiment(scale=p["name"], rows=rows, fronts=fronts, verdicts=verdicts,
                            device=f"{r0['gl_renderer']} ({r0['device']})", probes="SSR + probes" in configs)


def kept_screen_hits(frame) -> np.ndarray:
    """(R, h, w) bool: the rays whose screen-space hit the frame kept at full strength (the
    'screen' share of Frame.fallback_stats: hit layer > 0 and fade >= 1, on a ray with a weight).
    With fallback="bvh" these are the hits the confidence test vouched for; every other ray was
    retraced against the triangles."""
    rays = frame.rays
    return rays.hit & (rays.fade >= 1.0) & (rays.weight > 0)


def hit_objects(frame) -> np.ndarray:
    """(R, h, w) int: the G-buffer object id at each ray's screen hit (the hit layer's sample at
    rays.hit_pixel, which with fallback="bvh" is the pixel the confidence test settled on); -1
    where the ray has no screen hit."""
    rays, g, s = frame.rays, frame.gbuffer, frame.settings
    px = np.floor(rays.hit_pixel).astype(np.int64)
    layer = np.clip(rays.hit_layer - 1, 0, g.layers - 1)
    row, col = np.clip(px[..., 1], 0, s.height - 1), np.clip(px[..., 0], 0, s.width - 1)
    return np.where(rays.hit, g.object_id[layer, row, col], -1)


def wrong_object_hits(renderer, scene, settings: Settings | None = None, *, camera=None, against_bvh: bool = True,
                      threshold: float = 0.02) -> dict:
    """Renders the hybrid frame (`settings`, fallback "bvh" unless they say otherwise), traces the
    very rays it traced against the triangles (the per-ray reference) and counts the screen hits it
    kept on another object than the one the ray meets: each is a reflection of the wrong thing,
    reported as a hit.

    Returns {'rays': rays traced, 'kept': screen hits kept, 'wrong': kept hits on another object
    than the per-ray reference's (a true miss counts: its object is -1), 'screen', 'bvh',
    'rejected': Frame.fallback_stats' shares, 'frame': the hybrid frame, 'truth': its per-ray
    reference}; with `against_bvh`, also 'visible': of the wrong ones, those on a reflective
    layer-0 pixel whose reflection differs from pure BVH's (method="bvh", the same rays) by more
    than `threshold` in some channel, 'differs': all such pixels, and 'bvh_frame'."""
    settings = settings if settings is not None else Settings(fallback="bvh")
    frame = renderer.render(scene, camera, settings=settings)
    truth = frame.reference("per_ray")
    kept = kept_screen_hits(frame)
    wrong = kept & (hit_objects(frame) != truth.object)
    stats = frame.fallback_stats
    out = {"rays": stats["rays"], "kept": int(kept.sum()), "wrong": int(wrong.sum()), "screen": stats["screen"],
           "bvh": stats["bvh"], "rejected": stats["rejected"], "frame": frame, "truth": truth}
    if against_bvh:
        b = renderer.render(scene, camera, settings=settings.replace(method="bvh"))
        differs = np.abs(frame.reflection[..., :3] - b.reflection[..., :3]).max(axis=-1) > threshold
        differs &= frame.rays.traced
        out.update(visible=int((wrong & differs[None]).sum()), differs=int(differs.sum()), bvh_frame=b)
    return out
