"""The ssrlab command line.

    ssrlab info                         the device and OpenGL implementation chosen
    ssrlab scenes                       the procedural scenes
    ssrlab settings                     every render setting: default, unit, range, meaning
    ssrlab render [--scene NAME|FILE]   render a scene, write its image, G-buffer and timings
         [--repeats N]                  time N renders after a warm-up: median (min-max) per pass
         [--reference converged|thesis] score the image: thesis error, RMSE, PSNR, FLIP, SSIM; write
                                        reference.exr and error.png
    ssrlab bench SWEEP_FILE             sweep settings, measure run time against error (ssrlab.bench)
    ssrlab bench compare OLD NEW        two folders of benchmark records: NEW/OLD and a verdict per figure
    ssrlab bench history FOLDER B M     a figure of the committed records over commits (--plot PNG)
    ssrlab bench --suite standard       every technique on fixed scenes and budgets: DIR/leaderboard.md
    ssrlab view [SCENE]                 a live view in the browser: camera, settings, views, numbers
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def _settings_from_args(args) -> "Settings":
    from .lab.protocol import parse_set  # the one parser of --set, the benchmarks' too
    from .settings import Settings

    try:
        changes = parse_set(args.set)
    except ValueError as e:
        raise SystemExit(f"ssrlab: {e}") from None
    for name in ("width", "height", "layers"):
        if getattr(args, name) is not None:
            changes[name] = getattr(args, name)
    try:
        return Settings().replace(**changes)
    except ValueError as e:
        raise SystemExit(f"ssrlab: {e}") from None


def _device_arg(text: str) -> str:
    from .renderer import check_device

    try:
        return check_device(text, "--device")
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def cmd_info(args) -> int:
    from ._core import DeviceError
    from .renderer import Renderer, devices

    found = devices(probe=True)
    print(f"EGL devices ({len(found)}; device='gpu:N' takes the hardware device N, $SSRLAB_DEVICE pins a process):")
    for d in found:
        name = f"gpu:{d['index']}" if d["index"] is not None else "software"
        what = f"{d['vendor']}, {d['renderer']}, {d['gl_version']}" if d["renderer"] else f"no context: {d['error']}"
        extra = "".join(f", {k} {d[k]}" for k in ("drm_device", "cuda_device") if d[k] not in (None, ""))
        print(f"  {name:<9} {what}{extra}")
        print(f"  {'':<9} EGL device extensions: {d['egl_device_extensions'] or '-'}")
    print()
    try:
        info = Renderer(args.device).info
    except DeviceError as e:
        print(f"ssrlab: DeviceError: {e}", file=sys.stderr)
        return 1
    print(f"device={args.device!r} opens:")
    width = max(len(k) for k in info)
    for k, v in info.items():
        if v:
            print(f"{k:<{width}}  {v}")
    return 0


def cmd_scenes(args) -> int:
    from . import scenes

    for name, builder in scenes.SCENES.items():
        print(f"{name:<20} {(builder.__doc__ or '').strip().splitlines()[0]}")
    return 0


def _camera_path(args, scene):
    from .sequence import CameraPath

    if args.frames < 1:
        raise SystemExit(f"ssrlab: --frames must be >= 1, got {args.frames}")
    cam = scene.camera
    positions = [tuple(cam.position)]
    if args.path:
        try:
            positions = [tuple(float(v) for v in key.split(",")) for key in args.path.split(";") if key.strip()]
        except ValueError:
            raise SystemExit(f"ssrlab: --path expects X,Y,Z;X,Y,Z;..., got {args.path!r}") from None
    try:
        return CameraPath(positions, [tuple(cam.target)], args.frames, up=tuple(cam.up), fov_y=cam.fov_y,
                          near=cam.near, far=cam.far)
    except ValueError as e:
        raise SystemExit(f"ssrlab: --path: {e}") from None


def cmd_render_sequence(args) -> int:
    import json as _json

    from . import scenes
    from .io import OutputFolder, linear_to_srgb, write_image
    from .renderer import Renderer

    settings = _settings_from_args(args)
    out = Path(args.out) if args.out else Path("renders") / (Path(args.scene).stem + "_sequence")
    renderer = Renderer(args.device, max_triangles=args.max_triangles)
    kwargs = {"seed": args.seed} if args.seed is not None else {}
    if getattr(args, "stage", None) is not None:
        kwargs.update(stage=args.stage, stage_roughness=args.stage_roughness)
    scene = scenes.load(args.scene, **kwargs)
    path = _camera_path(args, scene)
    names = [f"frame_{i:04d}.png" for i in range(len(path))] + ["frames.gif", "timings.json"]
    folder = OutputFolder(out, overwrite=args.overwrite)
    try:
        folder.check(names)
    except FileExistsError as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    images, timings = [], []
    for i, frame in enumerate(renderer.render_sequence(scene, path, settings)):
        srgb = linear_to_srgb(frame.color, args.exposure)
        folder.write(names[i], lambda p, a=srgb: write_image(p, a))
        images.append(srgb)
        timings.append(frame.timings)
        print(f"frame {i}: {frame.timings['total']:.3f} ms (GPU)")
    try:  # Pillow comes with matplotlib; without it the numbered images stand alone
        from PIL import Image

        import numpy as np

        def gif(p):
            pics = [Image.fromarray(np.clip(np.rint(a * 255), 0, 255).astype(np.uint8)) for a in images]
            pics[0].save(p, format="GIF", save_all=True, append_images=pics[1:], duration=40, loop=0)

        folder.write("frames.gif", gif)
    except ImportError:
        pass
    folder.write("timings.json", lambda p: p.write_text(_json.dumps(
        {"scene": scene.name, "device": renderer.info, "settings": settings.to_dict(), "frames": timings}, indent=1)))
    print(f"wrote {len(images)} frames to {out}")
    return 0


def cmd_settings(args) -> int:
    from .settings import Settings

    print(Settings.describe())
    return 0


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("ssrlab")
    except PackageNotFoundError:
        return "0+unknown"


def _render_names(settings, reference: str | None) -> list[str]:
    names = ["color.png", "color.exr", *[f"gbuffer_layer{i}.exr" for i in range(settings.layers)], "timings.json"]
    return names + (["reference.exr", "error.png"] if reference else [])


def _warnings_through(bar):
    """A warnings.showwarning that writes "ssrlab: Category: message" lines on stderr, through
    tqdm's write where `bar` is a tqdm bar (the bar is redrawn below the line, not cut by it)."""
    def show(message, category, filename, lineno, file=None, line=None):
        text = f"ssrlab: {category.__name__}: {message}"
        write = getattr(bar, "write", None)
        if write is not None:
            write(text, file=sys.stderr)
        else:
            print(text, file=sys.stderr, flush=True)
    return show


def cmd_render(args) -> int:
    import warnings

    from .progress import progress_bar

    if args.frames != 1 or args.path:
        with warnings.catch_warnings():  # a scene's warnings as lines of their own, as below
            warnings.showwarning = _warnings_through(None)
            return cmd_render_sequence(args)

    from . import scenes
    from .lab import bench
    from .io import OutputFolder, write_image
    from .renderer import Renderer

    settings = _settings_from_args(args)
    if args.repeats < 1:
        raise SystemExit(f"ssrlab: --repeats must be >= 1, got {args.repeats}")
    warmup = args.warmup if args.warmup is not None else (1 if args.repeats > 1 else 0)
    if warmup < 0:
        raise SystemExit(f"ssrlab: --warmup must be >= 0, got {warmup}")
    if args.rays is not None and args.reference != "converged":
        raise SystemExit("ssrlab: --rays applies to --reference converged (the thesis reference has 32 rays "
                         "per pixel)")
    if args.rays is not None and args.rays < 1:
        raise SystemExit(f"ssrlab: --rays must be >= 1, got {args.rays}")
    out = Path(args.out) if args.out else Path("renders") / Path(args.scene).stem
    try:  # refuse before rendering, not after, when the results could not be written
        OutputFolder(out, overwrite=args.overwrite).check(_render_names(settings, args.reference))
    except (FileExistsError, NotADirectoryError) as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    renders = warmup + args.repeats
    steps = 4 + renders + (1 if args.reference else 0)
    timings, ref = [], None
    with progress_bar(total=steps, desc="ssrlab render", unit="step", file=sys.stderr,
                      bar_format="{desc}: {n}/{total} {postfix}") as bar, warnings.catch_warnings():
        # A scene's warnings (what it does not draw, long work before a render) as lines of their own.
        warnings.showwarning = _warnings_through(bar)
        bar.set_postfix_str("opening the GL device")
        renderer = Renderer(args.device, max_triangles=args.max_triangles)
        bar.update(1)
        bar.set_postfix_str(f"building scene {args.scene}")
        kwargs = {"seed": args.seed} if args.seed is not None else {}
        if args.stage is not None:
            kwargs.update(stage=args.stage, stage_roughness=args.stage_roughness)
        scene = scenes.load(args.scene, **kwargs)
        bar.update(1)
        for i in range(renders):
            what = "warm-up" if i < warmup else f"timed {i - warmup + 1}/{args.repeats}"
            work = renderer.estimate(scene, settings)  # long work says what it is (and warns as it starts)
            long = f"; {work.describe()}" if work.long else ""
            bar.set_postfix_str(f"rendering {settings.width}x{settings.height}, {settings.layers} layer(s), "
                                f"{what}{long}")
            frame = renderer.render(scene, settings=settings)
            if i >= warmup:
                timings.append(frame.timings)
            bar.update(1)
        if args.reference:
            from .truth.reference import reference_image

            bar.set_postfix_str(f"{args.reference} reference")
            ref = reference_image(renderer, scene, None, settings, kind=args.reference, rays=args.rays)
            bar.update(1)
        bar.set_postfix_str(f"writing {out}")
        stats = {k: bench.spread([t[k] for t in timings if k in t]) for k in timings[-1]}
        extra = {"scene": scene.name, "scene_source": args.scene, "triangles": scene.triangle_count,
                 "device": renderer.info, "repeats": args.repeats, "warmup": warmup,
                 "timings_median_ms": {k: v["median"] for k, v in stats.items()},
                 "timings_min_ms": {k: v["min"] for k, v in stats.items()},
                 "timings_max_ms": {k: v["max"] for k, v in stats.items()}}
        scores = None
        if ref is not None:
            from .truth.metrics import image_metrics
            from .truth.views import error_tile

            scores = image_metrics(frame.color, ref.color, ref.reflective)
            error_rgb, error_top = error_tile(frame.color, ref.color)
            extra["reference"] = {"kind": ref.kind, "rays_per_pixel": ref.rays_per_pixel,
                                  "error_png_top": error_top, **scores}
        try:
            files = frame.save(out, overwrite=args.overwrite, exposure=args.exposure, extra=extra)
            if ref is not None:
                folder = OutputFolder(out, overwrite=args.overwrite)
                files.append(folder.write("reference.exr", lambda p: write_image(p, ref.color, ["R", "G", "B"])))
                files.append(folder.write("error.png", lambda p: write_image(p, error_rgb)))
        except FileExistsError as e:
            bar.close()
            print(f"ssrlab: {e}", file=sys.stderr)
            return 1
        bar.update(bar.total - bar.n)
        bar.set_postfix_str("done")
    print(f"{renderer.info['renderer']} ({renderer.info['device']}): {scene}")
    if args.repeats == 1:
        note = " (warm-up first)" if warmup else " (a single render: --repeats N for medians after a warm-up)"
        print(f"GPU time per pass{note}:")
        for name, v in sorted(stats.items()):
            print(f"  {name:<24} {v['median']:9.3f} ms")
    else:
        print(f"GPU time per pass, median (min - max) of {args.repeats} renders after {warmup} warm-up:")
        for name, v in sorted(stats.items()):
            print(f"  {name:<24} {v['median']:9.3f} ms  ({v['min']:.3f} - {v['max']:.3f})")
    if scores is not None:
        def fmt(v, spec):
            return "-" if v is None else format(v, spec)

        print(f"against the {ref.kind} reference ({ref.rays_per_pixel} ray(s) per pixel), "
              f"{int(ref.reflective.sum())} reflective pixel(s):")
        print(f"  {'':<14} {'thesis error':>12} {'RMSE':>10} {'PSNR dB':>8} {'LDR-FLIP':>9} {'HDR-FLIP':>9} "
              f"{'SSIM':>7}")
        for label, sfx in (("all pixels", ""), ("reflective", "_reflective")):
            print(f"  {label:<14} {fmt(scores['thesis_error' + sfx], '12.5f')} {fmt(scores['rmse' + sfx], '10.5f')} "
                  f"{fmt(scores['psnr' + sfx], '8.2f')} {fmt(scores['flip_ldr' + sfx], '9.5f')} "
                  f"{fmt(scores['flip_hdr' + sfx], '9.5f')} {fmt(scores['ssim' + sfx], '7.4f')}")
        if scores["flip_ldr"] is None:
            print("  (FLIP and SSIM: pip install 'ssrlab[metrics]')")
        print(f"  error.png: per-pixel thesis error, black 0 to bright yellow {error_top:.4g} (inferno colour map; "
              f"its top is the 99th percentile)")
    for f in files:
        print(f"wrote {f}")
    return 0


def _format_cell(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return "-" if value is None else str(value)


def _table(rows: list[dict], columns: list[str]) -> str:
    """A plain text table of some columns of rows."""
    cells = [columns] + [[_format_cell(r.get(c)) for c in columns] for r in rows]
    widths = [max(len(line[i]) for line in cells) for i in range(len(columns))]
    return "\n".join("  ".join(c.rjust(w) for c, w in zip(line, widths)) for line in cells)


def _bench_config(args):
    """(config, out folder) of `ssrlab bench`: from the sweep file, or with --resume from the
    folder's journal (the sweep file, when given too, must match it unless --force-mix)."""
    from .lab import bench, journal

    config = None
    if args.sweep_file is not None:
        config = bench.load_sweep(args.sweep_file)
    if args.resume is not None:
        out = Path(args.resume)
        if args.out is not None and Path(args.out).resolve() != out.resolve():
            raise SystemExit("ssrlab: --resume FOLDER continues the sweep in FOLDER; do not give another --out")
        stored = journal.definition_of(out)
        if config is None:
            config = dict(stored)
        return config, out
    if config is None:
        raise SystemExit("ssrlab: bench needs SWEEP_FILE, or --resume FOLDER to finish an interrupted sweep")
    out = Path(args.out) if args.out else Path("results") / Path(args.sweep_file).stem
    old = out / journal.JOURNAL_NAME
    if old.is_file():
        # A new run starts a new journal; the earlier one is kept beside it, never deleted (it may
        # hold hours of rows: --resume FOLDER would have continued it).
        import datetime

        stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y%m%dT%H%M%S%f")
        kept = old.with_name(f"journal.{stamp}.jsonl")
        old.rename(kept)
        print(f"ssrlab: {out} held the journal of an earlier run, kept as {kept.name} (--resume {out} continues "
              f"a sweep instead of starting again)", file=sys.stderr)
    return config, out


def cmd_bench_history(argv) -> int:
    """ssrlab bench history FOLDER BENCHMARK METRIC: one figure at each commit that changed the
    committed records (ssrlab.lab.records.history), as a table and, with --plot, a PNG."""
    from .lab import records
    from .lab.protocol import parse_set

    ap = argparse.ArgumentParser(
        prog="ssrlab bench history",
        description="A figure of the committed benchmark records over commits: for each commit that changed "
                    "FOLDER (a results folder relative to the repository, e.g. "
                    "benchmarks/results/llvmpipe-llvm-15-0-6-256-bits), the latest record of BENCHMARK's METRIC "
                    "whose params hold every --param, with its median [25th-75th percentile].")
    ap.add_argument("folder", metavar="FOLDER")
    ap.add_argument("benchmark", metavar="BENCHMARK")
    ap.add_argument("metric", metavar="METRIC")
    ap.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                    help="only the figures whose params have this value (repeatable)")
    ap.add_argument("--commits", nargs="+", help="these commits instead of those that changed FOLDER")
    ap.add_argument("--last", type=int, default=20, help="how many of the commits that changed FOLDER (default 20)")
    ap.add_argument("--plot", metavar="PNG", help="also draw the figure over the commits into this file")
    args = ap.parse_args(argv)
    try:
        commits = args.commits or records.commits_of(args.folder, args.last)
        rows = records.history(args.folder, args.benchmark, args.metric, parse_set(args.param), commits)
    except (ValueError, FileNotFoundError) as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    print(f"{args.benchmark} / {args.metric} under {args.folder}: {len(rows)} record(s) at "
          f"{len({r['commit'] for r in rows})} of {len(commits)} commit(s)")
    print(records.history_table(rows))
    if args.plot:
        records.plot_history(rows, args.plot, title=f"{args.benchmark}: {args.metric}")
        print(f"wrote {args.plot}")
    return 0


def cmd_bench_compare(argv) -> int:
    """ssrlab bench compare OLD NEW: every figure of both result folders side by side (see
    ssrlab.lab.records.figure_verdict for the verdict's rule)."""
    from .lab import records

    ap = argparse.ArgumentParser(
        prog="ssrlab bench compare", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Compares two folders of benchmark records (benchmarks/results/<device>/*.jsonl, or "
                    "git:<commit>:<folder> for a commit's committed records): every figure (benchmark, params, "
                    "metric) present in both, NEW/OLD of the medians with its 95 %% bootstrap interval, each "
                    "side's median [25th-75th percentile] and a verdict: same where the whole interval lies "
                    "within the band (default 2 %%), faster / slower (better / worse for a figure that is not a "
                    "time) where it lies wholly beyond it, else undecided (also with fewer than 3 samples).")
    ap.add_argument("old", metavar="OLD")
    ap.add_argument("new", metavar="NEW")
    ap.add_argument("--band", type=float, default=records.SAME_BAND,
                    help="practical equivalence: NEW/OLD within 1 +- BAND is the same (default: %(default)s)")
    ap.add_argument("--benchmark", nargs="+", help="only these benchmarks' figures")
    ap.add_argument("--changed", action="store_true", help="print only the figures whose verdict is not 'same'")
    ap.add_argument("--json", metavar="FILE", help="also write the comparison as JSON")
    args = ap.parse_args(argv)
    try:
        old, new = records.read_records(args.old), records.read_records(args.new)
    except (ValueError, FileNotFoundError) as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    if args.benchmark:
        old = [r for r in old if r["benchmark"] in args.benchmark]
        new = [r for r in new if r["benchmark"] in args.benchmark]
    rows = records.compare(old, new, band=args.band)
    counts = {}
    for r in rows:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
    shown = [r for r in rows if r["verdict"] != "same"] if args.changed else rows
    print(f"OLD {args.old} ({len(records.latest(old))} figures), NEW {args.new} ({len(records.latest(new))} "
          f"figures): {len(rows)} in both; " + ", ".join(f"{v} {n}" for v, n in sorted(counts.items())))
    if shown:
        print(records.compare_table(shown))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


def cmd_bench(args) -> int:
    from .lab import bench

    if args.suite is not None:
        from .lab import standard

        return standard.run_suite(args)
    if args.entry or args.quick:
        raise SystemExit("ssrlab: --entry and --quick apply to --suite standard")
    try:
        config, out = _bench_config(args)
    except (ValueError, FileNotFoundError, FileExistsError) as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    if args.workers is not None and args.executor != "dask":
        raise SystemExit("ssrlab: --workers applies to --executor dask")
    if args.workers is not None and args.workers < 1:
        raise SystemExit(f"ssrlab: --workers must be >= 1, got {args.workers}")
    if args.scheduler is not None and (args.executor == "dask" or args.workers is not None):
        raise SystemExit("ssrlab: --scheduler runs on an existing cluster; --executor dask and --workers start a "
                         "local one")
    if args.device != "auto" or "device" not in config:  # --device given on the command line wins
        config["device"] = args.device
    if not (args.time_key in bench.TIME_KEYS or (args.time_key.startswith("gpu_") and args.time_key.endswith("_ms"))):
        raise SystemExit(f"ssrlab: --time-key must be one of {', '.join(bench.TIME_KEYS)} or a gpu_<pass>_ms "
                         f"column, got {args.time_key!r}")
    # Refuse before a long sweep, not after it, when the results could not be written.
    grid = config.get("grid") or {}
    varying = [k for k, v in grid.items() if isinstance(v, list) and len(set(map(repr, v))) > 1]
    try:
        from .io import OutputFolder

        OutputFolder(out, overwrite=args.overwrite).check(bench.result_names(varying))
    except (FileExistsError, NotADirectoryError) as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1

    where = args.sweep_file if args.sweep_file is not None else f"{out}/journal.jsonl"
    try:  # every scene file, view and setting checked before a cluster starts
        bench.plan_sweep(config.get("grid") or {}, config.get("scenes"), config.get("views"), config.get("base"))
    except (ValueError, FileNotFoundError) as e:
        print(f"ssrlab: {where}: {e}", file=sys.stderr)
        return 1
    if args.executor == "dask":
        workers = args.workers or bench.max_timing_workers(config["device"])
        try:
            bench.check_timing_workers(workers, config["device"])
        except ValueError as e:
            if not args.timing_workers:
                print(f"ssrlab: {e}", file=sys.stderr)
                return 1
            print(f"ssrlab: warning: --timing-workers: {e.args[0].split('. Use at most')[0]}", file=sys.stderr)

    cluster = client = None
    store = str(Path(args.reference_store).expanduser().resolve()) if args.reference_store else None
    try:
        if args.executor == "dask" or args.scheduler is not None:
            try:
                from distributed import Client, LocalCluster
            except ImportError:
                raise SystemExit("ssrlab: --executor dask and --scheduler need dask.distributed: "
                                 "pip install 'ssrlab[dask]'")
        if args.scheduler is not None:
            try:
                client = Client(args.scheduler, timeout=args.connect_timeout)
            except (OSError, TimeoutError) as e:
                print(f"ssrlab: --scheduler {args.scheduler}: no dask scheduler answered ({e})", file=sys.stderr)
                return 1
            n = len(client.scheduler_info().get("workers", {}))
            print(f"dask: the cluster at {args.scheduler}, {n} worker(s) now", file=sys.stderr)
        elif args.executor == "dask":
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
            client = Client(cluster)
            print(f"dask: {workers} worker process(es), one thread each", file=sys.stderr)
        rows = bench.sweep(**config, executor=client, progress=True, cache_folder=store, journal=out,
                           force_mix=args.force_mix)
    except KeyboardInterrupt:
        print(f"ssrlab: interrupted; every finished configuration is in {out}/journal.jsonl: "
              f"ssrlab bench --resume {out} runs the rest", file=sys.stderr)
        return 130
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    if client is not None and any(r.get("reference_rendered") for r in rows):
        print(f"ssrlab: warning: {sum(bool(r.get('reference_rendered')) for r in rows)} configuration(s) rendered "
              f"their reference again: their workers do not see the reference store the reference tasks wrote; "
              f"give every worker one shared path (--reference-store)", file=sys.stderr)

    try:
        files = bench.write_results(rows, out, time_key=args.time_key, error_key=args.error_key,
                                    overwrite=args.overwrite)
    except FileExistsError as e:
        print(f"ssrlab: {e}", file=sys.stderr)
        return 1
    fronts = bench.pareto_fronts(rows, args.time_key, args.error_key)
    first = rows[0]
    devices = sorted({str(r.get("gl_renderer")) for r in rows})
    print(f"{len(rows)} configuration(s) on {', '.join(devices)} ({first['device']}), reference "
          f"{first['reference']}, ssrlab {first['ssrlab_version']} ({first['git_revision']})")
    spread_cols = [c for c in (args.time_key + "_min", args.time_key + "_max", args.time_key + "_iqr")
                   if any(r.get(c) is not None for r in rows)]
    columns = [*[bench.SETTINGS_PREFIX + k for k in bench.varying_settings(rows)], args.time_key, *spread_cols,
               args.error_key]
    for key, front in fronts.items():
        on = f" on {key[2]}" if len(key) > 2 else ""  # rows of several devices: a front per device
        print(f"Pareto front of {key[0]}, view {key[1]}{on} ({args.error_key} against {args.time_key}):")
        print(_table(front, list(dict.fromkeys(columns))))
    for f in files:
        print(f"wrote {f}")
    return 0


def cmd_view(args) -> int:
    import time

    from .viewer import view

    settings = _settings_from_args(args)
    viewer = view(args.scene, settings, host=args.host, port=args.port, lossless=args.lossless, out=args.out,
                  device=args.view_device or args.device, accumulate=args.accumulate, frames=args.frames,
                  moving_fps=args.moving_fps)
    print(f"ssrlab view: {viewer.url}  (scene {viewer.scene.name!r} on {viewer.renderer.info['renderer']})")
    if args.host in ("127.0.0.1", "localhost", "::1"):
        print(f"  from another machine: ssh -N -L {viewer.port}:127.0.0.1:{viewer.port} THIS_HOST, then open "
              f"http://127.0.0.1:{viewer.port}/ there")
    print("  Ctrl-C stops it", flush=True)
    try:
        while True:
            time.sleep(3600)
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="ssrlab", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"ssrlab {_version()}",
                        help="print ssrlab's version and exit")
    parser.add_argument("--device", default="auto", type=_device_arg, metavar="{auto,gpu,gpu:N,cpu}",
                        help="EGL device: the GPU when there is one, or $SSRLAB_DEVICE where set (auto), the GPU "
                             "or fail (gpu), the N-th GPU as `ssrlab info` lists them (gpu:N), llvmpipe (cpu)")
    sub = parser.add_subparsers(dest="command", required=True)

    sub.add_parser("info", help="show the device and OpenGL implementation").set_defaults(func=cmd_info)
    sub.add_parser("scenes", help="list the procedural scenes").set_defaults(func=cmd_scenes)
    sub.add_parser("settings", help="list every render setting (ssrlab.Settings.describe())").set_defaults(
        func=cmd_settings)

    r = sub.add_parser("render", help="render a scene and write its image, G-buffer layers and timings",
                       description="Renders a scene and writes color.png, color.exr, gbuffer_layer<i>.exr and "
                                   "timings.json into --out; with --reference also reference.exr and error.png. "
                                   "Never replaces a file ssrlab did not write (--overwrite to force).")
    r.add_argument("--scene", default="spheres_and_boxes", help="a procedural scene name or a .gltf/.glb file")
    r.add_argument("--seed", type=int, help="seed of a procedural scene's layout (not the rays': --set seed=N)")
    r.add_argument("--stage", choices=["mirror", "glossy"],
                   help="a glTF file only: put a reflective metal floor under the model (scenes.load's stage)")
    r.add_argument("--stage-roughness", type=float,
                   help="the glossy stage's perceptual roughness in [0, 1] (default 0.25)")
    r.add_argument("--width", type=int, help="image width in pixels (Settings.width)")
    r.add_argument("--height", type=int, help="image height in pixels (Settings.height)")
    r.add_argument("--layers", type=int, help="depth-peeled G-buffer layers (Settings.layers)")
    r.add_argument("--set", action="append", metavar="FIELD=VALUE",
                   help="any ssrlab.Settings field, e.g. --set depth_mode=reversed_z (repeatable; "
                        "`ssrlab settings` lists them)")
    r.add_argument("--out", help="output folder (default: renders/<scene>)")
    r.add_argument("--exposure", type=float, default=1.0, help="scale of linear radiance before sRGB encoding")
    r.add_argument("--overwrite", action="store_true",
                   help="replace existing files even if ssrlab did not write them")
    r.add_argument("--frames", type=int, default=1,
                   help="render a sequence of this many frames (Renderer.render_sequence), written as "
                        "frame_NNNN.png, frames.gif and timings.json")
    r.add_argument("--path", metavar="X,Y,Z;X,Y,Z;...",
                   help="camera position keyframes of the sequence (ssrlab.CameraPath), looking at the scene "
                        "camera's target; default: the scene camera, static")
    r.add_argument("--repeats", type=int, default=1, metavar="N",
                   help="time N renders and print each pass's median (min - max) GPU time (default: 1)")
    r.add_argument("--warmup", type=int, metavar="W",
                   help="untimed renders before the timed ones (default: 1 with --repeats > 1, else 0)")
    r.add_argument("--reference", choices=("converged", "thesis"),
                   help="score the image against this reference (ssrlab.reference.reference_image, cached in "
                        "$SSRLAB_CACHE): print thesis error, RMSE, PSNR, FLIP and SSIM, write reference.exr and "
                        "error.png")
    r.add_argument("--rays", type=int, metavar="N",
                   help="rays per reflective pixel of the converged reference (default: 256; mirrors use one)")
    r.add_argument("--max-triangles", type=int, metavar="N",
                   help="refuse a scene of more than N drawn triangles (instances included) instead of rendering "
                        "it (Renderer(max_triangles=N); default: $SSRLAB_MAX_TRIANGLES where set, else no budget; "
                        "0: none). A render estimated to take long warns before it starts either way")
    r.set_defaults(func=cmd_render)

    v = sub.add_parser("view", help="a live view of a scene in the browser (ssrlab.view)",
                       description="Serves a live view of SCENE (a procedural scene's name or a .gltf/.glb file): "
                                   "the page's camera drives ssrlab's frames, every setting is a control, every "
                                   "channel a view. Binds 127.0.0.1 unless --host says otherwise.")
    v.add_argument("scene", nargs="?", default="hall", metavar="SCENE",
                   help="a procedural scene name (`ssrlab scenes`) or a .gltf/.glb file (default: hall)")
    v.add_argument("--set", action="append", metavar="FIELD=VALUE", help="any ssrlab.Settings field (repeatable)")
    v.add_argument("--width", type=int, help=argparse.SUPPRESS)
    v.add_argument("--height", type=int, help=argparse.SUPPRESS)
    v.add_argument("--layers", type=int, help="G-buffer layers (Settings.layers)")
    v.add_argument("--host", default="127.0.0.1",
                   help="address to serve on (default: %(default)s, this machine only; 0.0.0.0 serves every "
                        "network the machine is on)")
    v.add_argument("--port", type=int, help="port (default: a free one)")
    v.add_argument("--device", dest="view_device", type=_device_arg, metavar="{auto,gpu,gpu:N,cpu}",
                   help="EGL device (as `ssrlab --device`)")
    v.add_argument("--lossless", action="store_true", help="send frames as PNG instead of JPEG")
    from .viewer.server import FRAMES, moving_fps_arg

    v.add_argument("--frames", choices=FRAMES, default=FRAMES[0],
                   help="how the page shows frames: the 3D view's background (every layout of the page) or an "
                        "image over it (a shorter path in the page, for which the panel stays docked)")
    v.add_argument("--moving-fps", default="off", metavar="FPS", type=moving_fps_arg,
                   help="frames a second a moving camera renders at most (default off: as many as the device "
                        "gives; a limit leaves cores to a page on the same machine, and costs frames)")
    v.add_argument("--accumulate", type=int, default=8, metavar="N",
                   help="frames of new seeds averaged while the camera rests (default: %(default)s)")
    v.add_argument("--out", default="renders/view", help="folder of saved frames and camera paths")
    v.set_defaults(func=cmd_view)

    bench_error_keys = ("thesis_error", "rmse", "thesis_error_reflective", "rmse_reflective", "flip_ldr", "flip_hdr",
                        "flip_ldr_reflective", "flip_hdr_reflective", "ssim", "ssim_reflective", "psnr",
                        "psnr_reflective")
    b = sub.add_parser("bench", help="sweep settings from a sweep file; write run time against error",
                       description="Runs the sweep of SWEEP_FILE (TOML or JSON, see ssrlab.bench.load_sweep), "
                                   "then writes rows.csv, rows.json, pareto.csv and plots into --out and prints "
                                   "the Pareto front. Each configuration's row is appended to --out's journal.jsonl "
                                   "as it finishes; --resume FOLDER runs only what is missing.")
    b.add_argument("sweep_file", metavar="SWEEP_FILE", nargs="?",
                   help="a sweep file, e.g. benchmarks/sweeps/layers.toml (optional with --resume)")
    b.add_argument("--out", help="output folder (default: results/<sweep file name>)")
    b.add_argument("--executor", choices=("local", "dask"), default="local",
                   help="local: this process, one configuration after another; dask: a local dask.distributed "
                        "cluster of worker processes, each with its own EGL context")
    b.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing dask.distributed cluster, e.g. tcp://head:8786 (docs/cluster.md)")
    b.add_argument("--connect-timeout", type=float, default=30.0, metavar="S",
                   help="seconds to wait for the --scheduler to answer (default: %(default)s)")
    b.add_argument("--reference-store", metavar="PATH",
                   help="folder of the reference store (default: $SSRLAB_CACHE/references on each worker); on a "
                        "cluster a path every worker sees, so that each reference is rendered once")
    b.add_argument("--resume", metavar="FOLDER",
                   help="finish the sweep whose journal is in FOLDER: run only the configurations without a row")
    b.add_argument("--force-mix", action="store_true",
                   help="with a journal of another sweep definition or code version: keep its rows and add this "
                        "run's (otherwise refused)")
    b.add_argument("--workers", type=int,
                   help="dask worker processes (default: as many as can be timed side by side, "
                        "ssrlab.bench.max_timing_workers: one on llvmpipe unless LP_NUM_THREADS is lowered)")
    b.add_argument("--timing-workers", action="store_true",
                   help="time with more --workers than the machine can run side by side (times then include "
                        "the other workers' load; compare them only within the sweep)")
    b.add_argument("--overwrite", action="store_true",
                   help="replace existing files even if ssrlab did not write them")
    b.add_argument("--time-key", default="time_frame_ms",
                   help="row column of the time axis, e.g. time_reflections_ms (default: %(default)s)")
    b.add_argument("--error-key", default="thesis_error", choices=bench_error_keys,
                   help="row column of the error axis (default: %(default)s); psnr and ssim are similarities, "
                        "higher is better, every other an error, lower is better")
    b.add_argument("--suite", choices=("standard",),
                   help="run the standard evaluation instead of a sweep: fixed scenes, budgets and references, "
                        "every built-in technique and each --entry scored with its time; writes --out/leaderboard.md "
                        "and the records (ssrlab.lab.standard)")
    b.add_argument("--quick", action="store_true",
                   help="--suite at a size for checking, not for quoting (its records say quick: true)")
    b.add_argument("--entry", action="append", default=[], metavar="MODULE:NAME",
                   help="a user technique for --suite: a user module spec whose UserPass NAME runs as a pass "
                        "(Settings(user_modules=..., user_passes=...)), e.g. "
                        "examples/bilateral_filter/technique.py:bilateral_filter (repeatable)")
    b.set_defaults(func=cmd_bench)

    argv = list(sys.argv[1:] if argv is None else argv)
    if "bench" in argv and argv[argv.index("bench") + 1:argv.index("bench") + 2] == ["compare"]:
        return cmd_bench_compare(argv[argv.index("bench") + 2:])
    if "bench" in argv and argv[argv.index("bench") + 1:argv.index("bench") + 2] == ["history"]:
        return cmd_bench_history(argv[argv.index("bench") + 2:])
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError, RuntimeError, ImportError) as e:
        print(f"ssrlab: {type(e).__name__}: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
