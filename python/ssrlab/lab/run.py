"""Run time against error: sweeps of settings scored against a reference image.

A sweep renders every combination of scene, view and grid point (the cartesian product of
the settings in `grid`, on top of the `base` settings), times each configuration and scores
its last image against a reference (``ssrlab.reference.reference_image``: the converged
reference by default, or the thesis's ground truth). Each configuration gives one row.

    rows = sweep({"layers": [1, 2, 4, 8]}, ["box_stack"], base={"width": 320, "height": 180},
                 reference="converged")
    front = pareto_front(rows)                   # the best error for each time budget
    write_results(rows, "results/layers")        # rows.csv, rows.json, pareto.csv, plots

or from a sweep file: ``ssrlab bench benchmarks/sweeps/layers.toml --out results/layers``.

Timing protocol: for every configuration, the reference is fetched first (from the disk
cache, or rendered), then `warmup` renders whose times are discarded (shader variants are
compiled and the scene uploaded on first use), then `repeats` timed renders; times are the
median over the repeats. Metrics are those of the last repeat's image: rendering is
deterministic for fixed settings (the seed is a setting), so every repeat gives the same image.

Row columns (one dict per configuration; rows.csv and rows.json hold the same):

  index                 position of the configuration in sweep order (scene, then view, then grid point)
  scene                 a readable label of the scene spec, e.g. ``spheres_and_boxes(with_suzanne=True)``
  scene_spec            the scene spec as JSON text
  view                  the view's name ("default": the scene's own camera)
  reference             the reference kind; reference_rays: the rays asked for (None: the default);
                        reference_rays_per_pixel: the rays per pixel the reference used
  repeats, warmup       the timing protocol
  frames                frames per render (sequence of a static camera; the last one is timed and scored)
  sequence              True: one sequence of warmup + repeats frames per configuration (see sweep);
                        the metrics are then the mean over the timed frames, and
                        thesis_error_frame_min/_max their smallest and largest thesis_error
  gpu_<pass>_ms         median GPU milliseconds of every key of Frame.timings, dots replaced by
                        underscores (gpu_deep_gbuffer_ms, gpu_depth_peel_ms, gpu_depth_peel_layer0_ms, gpu_total_ms, ...)
  time_frame_ms         median GPU time of the whole frame (Frame.timings["total"])
  time_reflections_ms   median of trace_linear + trace_hiz + hiz_build + resolve (+ user passes) GPU time, those
                        present: what the thesis timed (seed 000, 3.1.2: trace and resolve passes);
                        with the glossy methods' passes (preconvolve, preintegrate, cone_trace,
                        blur_mips) where Settings.glossy runs them
  wall_ms               median CPU milliseconds of the render call (Frame.wall_ms)
  <time>_min, <time>_max, <time>_iqr
  samples               {time column: every timed run's value} (rows.json; not a column of rows.csv)
                        for each of the times above (gpu_<pass>_ms, time_frame_ms, ...): the
                        fastest and slowest of the repeats and their interquartile range
                        (numpy's linear percentiles; None with a single repeat, whose spread is
                        unknown), so that a difference can be told from noise (see spread)
  thesis_error, rmse, psnr, flip_ldr, flip_hdr, ssim and each with _reflective
                        ssrlab.metrics.image_metrics of Frame.color against the reference's
                        colour, over all pixels and over the reference's reflective pixels
                        (the *_reflective ones None when no pixel reflects; FLIP and SSIM None
                        without their packages, pip install 'ssrlab[metrics]')
  reflective_pixels     how many pixels reflect in the reference
  mean_fetches          depth fetches per traced ray of the last repeat (None when no ray was traced)
  s_<field>             every ssrlab.Settings field of the configuration
  device, gl_renderer, gl_version   the worker's renderer (Renderer.info)
  device_index          N of the hardware EGL device ("gpu:N") the worker rendered on; None on llvmpipe
  reference_rendered    True when this configuration's task rendered its reference itself (none in
                        the store yet); False when a reference task or an earlier sweep had stored it
  config_key            a digest of the configuration (ssrlab.journal.config_key): its name in the journal
  worker                host:pid of the process that rendered the configuration
  ssrlab_version, git_revision      of the code that ran the sweep ("unknown" outside a git checkout)
  timestamp             UTC time the configuration finished, ISO 8601

Workers: configurations fan out over any executor with ``submit(fn, *args)`` returning
futures with ``.result()`` (concurrent.futures executors, ``dask.distributed.Client``); the
default runs them in this process, one after another. The task is the module-level function
``run_configuration`` with picklable arguments (settings as a dict, scene and view specs,
never GL objects); each worker process opens its own EGL context on its first task (see
``worker_renderer``). Parallel workers share the machine's cores, so their timings are
slower and noisier than a sequential sweep's: compare times within one sweep, and measure
times that you report with one worker.

An existing cluster: ``sweep(..., executor=distributed.Client("tcp://head:8786"))`` (or
``ssrlab bench --scheduler tcp://head:8786``) runs on any dask.distributed cluster. Each
distinct reference is one task (prepare_reference) that the configurations needing it depend
on, so every reference is rendered once per cluster into the store (cache_folder, a shared
path; content-addressed, written atomically) and read from there. With ``journal=FOLDER``
every row reaches the disk as its configuration finishes, and a rerun does only what is left
(ssrlab.journal). Rows record the worker (host:pid) and device (gl_renderer, device_index)
that produced them; Pareto fronts are per device (pareto_fronts). docs/cluster.md has more.
"""

from __future__ import annotations

import concurrent.futures
import datetime
import json
import os
import socket
import subprocess
import threading
from pathlib import Path
from typing import Any

import numpy as np

from ..settings import Settings
from ..truth.metrics import METRIC_KEYS, image_metrics
from .journal import Journal, config_key
from .plan import SETTINGS_PREFIX, _check_count, plan_sweep, scene_label, view_camera
from .timing import time_column, with_spread

# Passes whose GPU time the thesis counted as the cost of reflections (trace and resolve),
# with the Hi-Z pyramid build that Hi-Z tracing needs.
REFLECTION_PASSES = ("trace_linear", "trace_hiz", "hiz_build", "resolve",
                     "preconvolve", "preintegrate", "cone_trace", "blur_mips")  # the glossy methods' passes
# Row columns that are times (with every gpu_<pass>_ms column).
TIME_KEYS = ("time_frame_ms", "time_reflections_ms", "wall_ms")

# Columns that differ between two runs of the same sweep even though the images do not
# (with every gpu_<pass>_ms column, see is_volatile).
VOLATILE_KEYS = ("time_frame_ms", "time_reflections_ms", "wall_ms", "timestamp", "worker", "reference_rendered", "samples")


def is_volatile(column: str) -> bool:
    """True for the columns that change from run to run of the same configuration: times and
    their spread, the timestamp, the worker and whether the reference was in the store.
    Everything else, the metrics included, is deterministic."""
    column = time_column(column)
    return column in VOLATILE_KEYS or (column.startswith("gpu_") and column.endswith("_ms"))


# -- the worker ----------------------------------------------------------------------------------------------
class _WorkerState(threading.local):
    """What a worker keeps between tasks, per thread (threads of a pool render at the same time, and
    a Renderer serves one call at a time) and per process (a forked child must not use its
    parent's context)."""

    def __init__(self):
        self.pid = os.getpid()
        self.renderers: dict[str, Any] = {}
        self.scenes: dict[str, Any] = {}


_STATE = _WorkerState()
# Renderers opened by this process: (pid, thread id, device). Also keeps every Renderer a
# forked child inherited alive, so their destructors never run on a copied context.
_OPENED: list[tuple[int, int, str]] = []
_INHERITED: list[Any] = []


def _state() -> _WorkerState:
    if _STATE.pid != os.getpid():  # a forked child: its parent's renderers are not ours
        _INHERITED.extend(_STATE.renderers.values())
        _STATE.__init__()
    return _STATE


def worker_renderer(device: str = "auto"):
    """This process's (and thread's) Renderer for `device`, opened on first use.

    Each worker process opens its own EGL context lazily, on its first configuration, and
    keeps it for every later one: EGL contexts cannot be shared between processes, and
    opening one (and compiling shader variants) costs far more than a small render.
    """
    state = _state()
    if device not in state.renderers:
        from ..renderer import Renderer

        state.renderers[device] = Renderer(device)
        _OPENED.append((os.getpid(), threading.get_ident(), device))
    renderer = state.renderers[device]
    # The user passes registered in this process (ssrlab.UserPass) serve every sweep's renderer
    # (in-process and thread executors); those of Settings.user_modules are registered by every
    # worker's render, wherever it runs.
    from ..user_pass import declared

    for name, p in declared().items():
        if name not in renderer.user_passes:
            renderer.register_pass(p)
    return renderer


def opened_renderers() -> list[dict]:
    """The Renderers this process opened for sweeps (pid, thread, device): lets a caller check
    that every worker process opened its own EGL context (``client.run(opened_renderers)``)."""
    return [{"pid": pid, "thread": tid, "device": dev} for pid, tid, dev in _OPENED if pid == os.getpid()]


def _scene(spec):
    """The scene of a spec, built once per worker (building and uploading cost time)."""
    from .. import scenes

    state = _state()
    key = json.dumps(spec, sort_keys=True)
    if key not in state.scenes:
        if isinstance(spec, dict):
            state.scenes[key] = scenes.load(spec["name"], **{k: v for k, v in spec.items() if k != "name"})
        else:
            state.scenes[key] = scenes.load(str(spec))
    return state.scenes[key]


def _timing_column(key: str) -> str:
    return "gpu_" + key.replace(".", "_") + "_ms"


def _reference_settings(s: Settings, frames: int, sequence: bool) -> Settings:
    # frames > 1: every render is a sequence of `frames` frames of the static camera (what TAA
    # and temporal accumulation need); the last frame is timed and scored. The
    # reference is that of the unjittered camera (TAA averages the jitter out).
    return s.replace(taa="off") if frames > 1 or sequence else s


def reference_group(task: tuple) -> str:
    """What a configuration's reference depends on (scene spec, view, the reference's kind, rays
    and the settings that change it), as text: configurations with the same group share one
    reference, which a sweep renders once (prepare_reference) before them."""
    from ..truth.reference import reference_fields

    scene_spec, view, _, settings, _, _, reference, reference_rays, _, _, frames, sequence = task
    s = _reference_settings(Settings.from_dict(settings), frames, sequence)
    return json.dumps([scene_spec, view, reference, reference_rays, reference_fields(reference, s)], sort_keys=True,
                      default=str)


def prepare_reference(scene_spec, view, settings: dict, reference: str, reference_rays: int | None, device: str,
                      cache_folder: str | None, frames: int = 1, sequence: bool = False) -> dict:
    """Puts a configuration's reference into the store (`cache_folder`, shared by the workers
    of a cluster) unless it is there: the sweep's reference task, one per reference_group, run
    before the configurations that need it. Returns {"key", "computed" (True: rendered now),
    "worker"}."""
    from ..truth.reference import reference_image, reference_path

    renderer = worker_renderer(device)
    scene = _scene(scene_spec)
    camera = view_camera(view, scene)
    s = _reference_settings(Settings.from_dict(settings), frames, sequence)
    path = reference_path(scene, camera, s, kind=reference, rays=reference_rays, folder=cache_folder)
    computed = not path.is_file()
    if computed:
        reference_image(renderer, scene, camera, s, kind=reference, rays=reference_rays, cache=True,
                        folder=cache_folder)
    return {"key": path.stem, "computed": computed, "worker": f"{socket.gethostname()}:{os.getpid()}",
            "timestamp": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}


def _run_after_reference(_reference: dict, *args) -> dict:
    """run_configuration once its reference task has finished (a dask dependency: the
    reference's future is the first argument)."""
    return run_configuration(*args)


def run_configuration(scene_spec, view, view_label: str, settings: dict, repeats: int, warmup: int,
                      reference: str, reference_rays: int | None, device: str,
                      cache_folder: str | None, frames: int = 1, sequence: bool = False) -> dict:
    """Renders one configuration and measures it: the sweep's task, run in a worker.

    Module-level with picklable arguments, so any executor can ship it to another process.
    Returns the row's measured columns (see the module documentation); the caller adds the
    sweep's own columns (index, provenance of the sweep).
    """
    from ..truth.reference import reference_image, reference_path

    renderer = worker_renderer(device)
    scene = _scene(scene_spec)
    camera = view_camera(view, scene)
    s = Settings.from_dict(settings)
    ref_settings = _reference_settings(s, frames, sequence)
    # False where the sweep's reference task (prepare_reference) or an earlier sweep put the
    # reference in the store: a cluster renders each reference once.
    rendered_here = not reference_path(scene, camera, ref_settings, kind=reference, rays=reference_rays,
                                       folder=cache_folder).is_file()
    ref = reference_image(renderer, scene, camera, ref_settings, kind=reference, rays=reference_rays, cache=True,
                          folder=cache_folder)

    def render():
        if frames == 1:
            return renderer.render(scene, camera, s)
        last = None
        for last in renderer.render_sequence(scene, [camera] * frames, s):
            pass
        return last

    reflective = np.asarray(ref.reflective, dtype=bool)
    frames_timings, walls, reflections, scores = [], [], [], []
    frame = None

    def record(f) -> None:
        t = f.timings
        frames_timings.append(t)
        walls.append(f.wall_ms)
        reflections.append(sum(t.get(p, 0.0) for p in (*REFLECTION_PASSES, *s.user_passes)))

    if sequence:
        # One sequence of warmup + repeats frames of the static camera: the warm-up frames fill
        # the temporal history (and compile), every later frame is timed and scored. Each frame
        # draws new rays (seed + i), so the metrics are the mean over the scored frames: the
        # expected error of a frame in steady state, not one seed's draw.
        for i, f in enumerate(renderer.render_sequence(scene, [camera] * (warmup + repeats), s)):
            if i >= warmup:
                frame = f
                record(f)
                scores.append(image_metrics(f.color, ref.color, reflective))
    else:
        for _ in range(warmup):
            render()
        for _ in range(repeats):
            frame = render()
            record(frame)
    timing_keys = sorted({k for t in frames_timings for k in t})
    row: dict[str, Any] = {
        "scene": scene_label(scene_spec),
        "scene_spec": json.dumps(scene_spec, sort_keys=True),
        "view": view_label,
        "reference": reference,
        "reference_rays": reference_rays,
        "reference_rays_per_pixel": int(ref.rays_per_pixel),
        "reference_rendered": rendered_here,
        "repeats": repeats,
        "warmup": warmup,
        "frames": warmup + repeats if sequence else frames,
        "sequence": sequence,
    }
    with_spread(row, "time_frame_ms", [t["total"] for t in frames_timings])
    with_spread(row, "time_reflections_ms", reflections)
    with_spread(row, "wall_ms", walls)
    if sequence:
        for k in METRIC_KEYS:
            values = [m[k] for m in scores if m[k] is not None]
            row[k] = float(np.mean(values)) if values else None
        errors = [m["thesis_error"] for m in scores]
        row.update(thesis_error_frame_min=float(min(errors)), thesis_error_frame_max=float(max(errors)))
    else:
        row.update(image_metrics(frame.color, ref.color, reflective))
    row["reflective_pixels"] = int(reflective.sum())
    row["mean_fetches"] = frame.rays.mean_fetches() if "rays.hit" in frame.texture_names else None
    for k in timing_keys:
        with_spread(row, _timing_column(k), [t[k] for t in frames_timings if k in t])
    # The settings as they ran (a technique's overrides written in: cone tracing's one mirror ray),
    # never a figure of work that was not done. Tuples (user_passes) as lists: a row reads back
    # from rows.json as it was written.
    ran = s.as_run().to_dict()
    row.update({SETTINGS_PREFIX + k: list(v) if isinstance(v, tuple) else v for k, v in ran.items()})
    row.update({SETTINGS_PREFIX + k: v for k, v in s.user_params.items()})  # one column per user parameter
    info = renderer.info
    row.update(device=info.get("device", "unknown"), device_index=info.get("device_index") or None,
               gl_renderer=info.get("renderer", "unknown"),
               gl_version=info.get("gl_version", "unknown"), worker=f"{socket.gethostname()}:{os.getpid()}",
               timestamp=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"))
    return row


# -- provenance ------------------------------------------------------------------------------------------
def git_revision() -> str:
    """`git rev-parse --short HEAD` of the ssrlab source checkout: the package's own folder
    when ssrlab runs from its checkout, else the working folder if it is one (a checkout
    that holds python/ssrlab); "unknown" otherwise."""
    for folder in (Path(__file__).resolve().parent, Path.cwd()):
        try:
            top = subprocess.run(["git", "-C", str(folder), "rev-parse", "--show-toplevel"], capture_output=True,
                                 text=True, timeout=10)
            if top.returncode != 0 or not (Path(top.stdout.strip()) / "python" / "ssrlab").is_dir():
                continue
            rev = subprocess.run(["git", "-C", str(folder), "rev-parse", "--short", "HEAD"], capture_output=True,
                                 text=True, timeout=10)
            if rev.returncode == 0 and rev.stdout.strip():
                return rev.stdout.strip()
        except (OSError, subprocess.SubprocessError):
            continue
    return "unknown"


# -- how many workers may time ---------------------------------------------------------------------------
def render_threads() -> int:
    """CPU threads one render keeps busy: llvmpipe rasterises with $LP_NUM_THREADS threads (by
    default one per core); a GPU render needs about one CPU thread."""
    cores = os.cpu_count() or 1
    try:
        lp = int(os.environ.get("LP_NUM_THREADS", ""))
    except ValueError:
        lp = 0
    return max(1, min(lp, cores)) if lp > 0 else cores


def max_timing_workers(device: str = "cpu") -> int:
    """The most worker processes whose renders can be timed side by side without fighting for
    the same hardware: on llvmpipe ("cpu"), the cores divided by the threads each render uses
    (render_threads); on a GPU ("gpu"), one (every worker would share the one GPU, and its timer
    queries would measure the others' work too); for "auto", the smaller of the two, since
    which device a worker gets is known only once it opens one."""
    cpu = max(1, (os.cpu_count() or 1) // render_threads())
    if device == "cpu":
        return cpu
    return 1


def check_timing_workers(workers: int, device: str = "auto") -> None:
    """ValueError explaining why `workers` concurrent workers would time noise rather than the
    configurations, when there are more than max_timing_workers(device)."""
    limit = max_timing_workers(device)
    if workers <= limit:
        return
    cores = os.cpu_count() or 1
    if device == "cpu":
        why = (f"each llvmpipe render uses {render_threads()} thread(s) (LP_NUM_THREADS) and this machine has "
               f"{cores} core(s)")
    else:
        why = (f"device={device!r} renders on one GPU (or, without one, on llvmpipe with {render_threads()} "
               f"thread(s) per render on {cores} core(s)), which the workers would share")
    raise ValueError(f"{workers} timing workers would run their renders side by side: {why}, so each time would "
                     f"include the other workers' work. Use at most {limit} worker(s), or pass --timing-workers "
                     f"to time with {workers} anyway (compare those times only within the sweep)")


def _is_dask_client(executor) -> bool:
    return type(executor).__module__.split(".")[0] == "distributed"


def _completed(futures: list):
    """Futures in completion order where the executor's futures allow it, else in order."""
    if futures and all(isinstance(f, concurrent.futures.Future) for f in futures):
        return concurrent.futures.as_completed(futures)
    if futures and type(futures[0]).__module__.split(".")[0] == "distributed":
        from distributed import as_completed

        return as_completed(futures)
    return iter(futures)


def sweep(grid: dict[str, list], scenes: list, views: list | None = None, base: dict | Settings | None = None,
          repeats: int = 5, warmup: int = 2, reference: str = "converged", reference_rays: int | None = None,
          executor=None, device: str = "auto", progress: bool = True, cache_folder=None,
          frames: int = 1, sequence: bool = False, journal=None, force_mix: bool = False) -> list[dict]:
    """Measures every (scene, view, grid point) configuration; returns one row per
    configuration, in that order (scenes outermost, grid points innermost), whatever order
    the executor completes them in (a list of dicts, SweepRows, which a notebook shows as the
    error against time of plot_error_vs_time).

    grid       Settings field -> list of values; the cartesian product is swept (expand_grid)
    scenes     scene specs: a procedural scene name (ssrlab.scenes.SCENES), a .gltf/.glb path,
               or a dict {"name": <procedural scene>, **builder options}
    views      None (each scene's default camera) or a list of "default", dicts
               {"name", "position", "target"[, "up", "fov_y", "near", "far"]} (missing
               values from the scene's camera), or ssrlab.Camera objects (named camera<i>)
    base       Settings (or a dict of fields) every configuration starts from
    repeats    timed renders per configuration (medians are reported); warmup: untimed renders first
    reference  reference kind ("converged" or "thesis", see ssrlab.reference); reference_rays:
               its rays per pixel (None: the reference's default)
    executor   None (this process, sequentially) or an object with submit(fn, *args) returning
               futures (concurrent.futures executors, dask.distributed.Client)
    device     the Renderer device of every worker ("auto", "gpu", "gpu:N", "cpu"); "auto" takes
               each worker's $SSRLAB_DEVICE where set (workers pinned one per GPU, docs/cluster.md)
    progress   show progress on stderr (a tqdm bar on a terminal or in Jupyter, else a line per step)
    cache_folder  the reference store (None: $SSRLAB_CACHE or ~/.cache/ssrlab on each worker); on a
               cluster, a path every worker sees (a shared file system), so that each reference is
               rendered once for the whole cluster
    journal    a results folder: every configuration's row is appended to its journal.jsonl as soon
               as it finishes (ssrlab.journal), and a configuration that already has a row there is
               not run again (resume). A journal of another definition or code version raises
               ssrlab.journal.SweepMismatchError unless force_mix=True.
    frames     1: every render is a single frame; N > 1: a sequence of N frames of the static
               camera (Renderer.render_sequence: TAA and temporal settings need frames), whose
               last frame is timed and scored, against the reference with taa="off"
    sequence   True: each configuration is one sequence of warmup + repeats frames of the static
               camera (frames must be 1): the first `warmup` frames fill the temporal history
               and are not timed (at least 1), each later frame is timed (medians over them)
               and scored (the mean of its metrics), against the reference with taa="off".
               What the thesis measured (TAA on, a running sequence) at the cost of single frames.

    Every argument is checked before anything renders: ValueError names the bad one.
    """
    from .._package import __version__
    from ..truth.reference import KINDS
    from ..renderer import check_device

    configurations = plan_sweep(grid, scenes, views, base)
    repeats = _check_count(repeats, "repeats", 1)
    warmup = _check_count(warmup, "warmup", 0)
    frames = _check_count(frames, "frames", 1)
    if not isinstance(sequence, bool):
        raise ValueError(f"sequence must be True or False, got {sequence!r}")
    if sequence and frames != 1:
        raise ValueError(f"sequence=True renders warmup + repeats frames as one sequence; frames must be 1, "
                         f"got {frames}")
    if sequence and warmup < 1:
        raise ValueError("sequence=True needs warmup >= 1: the first frame of a sequence has no history")
    if reference not in KINDS:
        raise ValueError(f"reference must be one of {', '.join(KINDS)}, got {reference!r}")
    if reference_rays is not None:
        _check_count(reference_rays, "reference_rays", 1)
        if reference != "converged":
            raise ValueError(f"reference_rays applies to the converged reference only; the {reference!r} "
                             f"reference has its own rays per pixel")
    check_device(device, "device")
    if executor is not None and not callable(getattr(executor, "submit", None)):
        raise ValueError(f"executor must have a submit(fn, *args) method, got {type(executor).__name__}")
    cache = None if cache_folder is None else str(Path(cache_folder).expanduser().resolve())
    tasks = [(c["scene_spec"], c["view"], c["view_name"], c["settings"], repeats, warmup, reference, reference_rays,
              device, cache, frames, sequence) for c in configurations]

    provenance = {"ssrlab_version": __version__, "git_revision": git_revision()}
    keys = [config_key(t[:9] + t[10:]) for t in tasks]  # the store's path is no part of a configuration
    book = None
    if journal is not None:
        from ..truth.reference import shader_sources_hash

        definition = dict(grid=grid, scenes=scenes, views=views,
                          base=base.to_dict() if isinstance(base, Settings) else base, repeats=repeats, warmup=warmup,
                          reference=reference, reference_rays=reference_rays, device=device, frames=frames,
                          sequence=sequence)
        try:
            definition = json.loads(json.dumps(definition))
        except TypeError as e:
            raise ValueError(f"journal: the sweep's arguments must be JSON (scene specs, view dicts, settings "
                             f"dicts) to be run again from the journal: {e}") from None
        code = {**provenance, "shaders": shader_sources_hash()}
        book = Journal(journal, definition, keys, code, force_mix=force_mix)
    rows: list[dict | None] = [None] * len(tasks)
    pending = []
    for i, key in enumerate(keys):
        if book is not None and key in book.rows:
            rows[i] = {**book.rows[key], "index": i}  # done by an earlier run of this sweep
        else:
            pending.append(i)
    bar = None
    if progress:
        from ..progress import progress_bar

        bar = progress_bar(total=len(tasks), initial=len(tasks) - len(pending), desc="ssrlab bench", unit="config")

    def finish(i: int, measured: dict) -> None:
        rows[i] = {"index": i, "config_key": keys[i], **measured, **provenance}
        if book is not None:
            book.add(keys[i], rows[i])
        if bar is not None:
            bar.update(1)

    def noted(info: dict) -> dict:
        if book is not None:
            book.note({"type": "reference", **info})
        return info

    # One reference task per distinct reference among the configurations still to run, each
    # before the configurations that need it: every reference is rendered once (by whichever
    # worker takes its task) into the store, and the configurations find it there.
    groups: dict[str, list[int]] = {}
    for i in pending:
        groups.setdefault(reference_group(tasks[i]), []).append(i)

    def reference_args(i: int) -> tuple:
        t = tasks[i]
        return (t[0], t[1], t[3], t[6], t[7], t[8], t[9], t[10], t[11])

    try:
        if executor is None:
            for i in pending:
                finish(i, run_configuration(*tasks[i]))
        elif _is_dask_client(executor):
            # dask caches "pure" tasks by their arguments: a second sweep on the same client
            # would return the first one's timings without rendering. pure=False renders. A
            # configuration's task takes its reference's future as an argument: dask runs it
            # once that reference is in the store, wherever the two run.
            ref_futures = {g: executor.submit(prepare_reference, *reference_args(members[0]), pure=False, priority=10)
                           for g, members in groups.items()}
            futures = [executor.submit(_run_after_reference, ref_futures[reference_group(tasks[i])], *tasks[i],
                                       pure=False) for i in pending]
            index = {f.key: i for f, i in zip(futures, pending)}
            references = {f.key for f in ref_futures.values()}
            try:
                from distributed import as_completed

                for f in as_completed([*ref_futures.values(), *futures]):
                    if f.key in references:
                        noted(f.result())
                    else:
                        finish(index[f.key], f.result())
            except BaseException:
                for f in [*futures, *ref_futures.values()]:
                    f.cancel()
                raise
        else:
            ref_futures = [executor.submit(prepare_reference, *reference_args(m[0])) for m in groups.values()]
            futures = []
            try:
                for f in _completed(ref_futures):
                    noted(f.result())
                futures = [executor.submit(run_configuration, *tasks[i]) for i in pending]
                index = {id(f): i for f, i in zip(futures, pending)}
                for f in _completed(futures):
                    finish(index[id(f)], f.result())
            except BaseException:
                for f in [*ref_futures, *futures]:
                    f.cancel()
                raise
    finally:
        if bar is not None:
            bar.close()
    _warn_shared_gpus(rows)  # type: ignore[arg-type]
    from .report import SweepRows

    return SweepRows(rows)  # a list of dicts; a notebook shows it as its error against time


def _warn_shared_gpus(rows: list[dict]) -> None:
    """Warns where two worker processes of one host rendered on one GPU (the same device_index):
    their timings include each other's work (docs/cluster.md: one SSRLAB_DEVICE per worker)."""
    import warnings

    users: dict[tuple, set] = {}
    for r in rows:
        if r.get("device_index") is not None and r.get("worker"):
            host = str(r["worker"]).rsplit(":", 1)[0]
            users.setdefault((host, r["device_index"]), set()).add(r["worker"])
    shared = {k: v for k, v in users.items() if len(v) > 1}
    if shared:
        what = "; ".join(f"gpu:{gpu} on {host}: {', '.join(sorted(w))}" for (host, gpu), w in shared.items())
        warnings.warn(f"sweep: several workers timed on one GPU ({what}); pin one worker per GPU with "
                      f"SSRLAB_DEVICE=gpu:N", stacklevel=3)


__all__ = ["REFLECTION_PASSES", "TIME_KEYS", "VOLATILE_KEYS", "METRIC_KEYS", "is_volatile", "sweep",
           "run_configuration", "prepare_reference", "reference_group", "worker_renderer", "opened_renderers",
           "git_revision", "render_threads", "max_timing_workers", "check_timing_workers"]
