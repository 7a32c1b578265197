"""A/B of a whole frame between two builds, interleaved in one run.

    python benchmarks/tools/ab_frame.py --baseline-python /work/venvs/loader/bin/python
                                  [--current-python PY] [--scenes hall spheres_and_boxes]
                                  [--width 640 --height 360] [--frames 7] [--warmup 2]
                                  [--set key=value ...]

Two Python interpreters, each with its own installed ssrlab (e.g. a venv built from the commit
before a change, and this one), run as persistent subprocesses that each hold one Renderer. Both
render the thesis configuration (4 layers, 4 GGX rays, half resolution, stride 4, 250 steps;
`--set` adds or replaces settings, given to both sides under the same names) alternately: warm-up
renders first, then `--frames` interleaved frames each, so both sides see the same load on a
shared machine. Per side: the median GPU total (frame.timings["total"]) and the wall time of
render() + reading frame.color, each with its min-max; the speed-up (baseline / current median);
and the thesis error between the two sides' images (sent back through .npy files in a temporary
folder). A verdict needs the min-max ranges apart: where they overlap it prints "undecided".

Timings on llvmpipe are CPU time on shared cores: only the ratio measured in one run means much.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

THESIS = dict(layers=4, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250)


# --- worker side: runs under either interpreter, imports only that interpreter's ssrlab ----------------

def worker() -> int:
    import numpy as np
    import ssrlab

    renderer = ssrlab.Renderer("auto")
    scene = settings = None
    out = sys.stdout
    sys.stdout = sys.stderr  # anything the library prints must not corrupt the protocol
    out.write(json.dumps({"ok": True, "device": renderer.info["renderer"], "version": getattr(ssrlab, "__version__", "?"),
                          "module": ssrlab.__file__}) + "\n")
    out.flush()
    for line in sys.stdin:
        msg = json.loads(line)
        try:
            if msg["cmd"] == "setup":
                scene = getattr(ssrlab.scenes, msg["scene"])()
                settings = ssrlab.Settings(**msg["settings"])
                reply = {"ok": True}
            elif msg["cmd"] == "render":
                t0 = time.perf_counter()
                frame = renderer.render(scene, settings=settings)
                color = frame.color
                wall = (time.perf_counter() - t0) * 1e3
                if msg.get("image"):
                    np.save(msg["image"], np.asarray(color, dtype=np.float32))
                reply = {"ok": True, "gpu": float(frame.timings["total"]), "wall": wall,
                         "passes": {k: float(v) for k, v in frame.timings.items() if "." not in k}}
                del frame
            elif msg["cmd"] == "quit":
                break
            else:
                reply = {"ok": False, "error": f"unknown command {msg['cmd']!r}"}
        except Exception as e:  # reported to the driver, which stops with the message
            reply = {"ok": False, "error": f"{type(e).__name__}: {e}"}
        out.write(json.dumps(reply) + "\n")
        out.flush()
    return 0


# --- driver side -------------------------------------------------------------------------------------------

class Side:
    def __init__(self, name: str, python: str):
        self.name = name
        self.proc = subprocess.Popen([python, str(Path(__file__).resolve()), "--worker"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True, bufsize=1)
        self.hello = self._read()

    def _read(self):
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"{self.name} worker exited (status {self.proc.poll()}); see its stderr above")
        reply = json.loads(line)
        if not reply.get("ok"):
            raise RuntimeError(f"{self.name} worker: {reply.get('error')}")
        return reply

    def ask(self, **msg):
        self.proc.stdin.write(json.dumps(msg) + "\n")
        self.proc.stdin.flush()
        return self._read()

    def close(self):
        try:
            self.proc.stdin.write(json.dumps({"cmd": "quit"}) + "\n")
            self.proc.stdin.flush()
        except OSError:
            pass
        self.proc.wait(timeout=60)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--baseline-python", required=True, help="interpreter whose ssrlab is the baseline")
    ap.add_argument("--current-python", default=sys.executable, help="interpreter whose ssrlab is measured")
    ap.add_argument("--scenes", nargs="+", default=["hall", "spheres_and_boxes"])
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--frames", type=int, default=7, help="interleaved timed frames per side and scene")
    ap.add_argument("--warmup", type=int, default=2, help="untimed frames per side and scene first")
    ap.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE", help="settings beside the thesis's")
    ap.add_argument("--passes", action="store_true", help="also print per-pass medians")
    args = ap.parse_args(argv)
    # The driver's statistics; the workers import only their own interpreter's ssrlab (the baseline's
    # may predate ssrlab.lab).
    from ssrlab.lab.timing import median_range, verdict

    if args.frames < 1 or args.warmup < 0:
        ap.error("--frames must be >= 1 and --warmup >= 0")
    settings = dict(THESIS, width=args.width, height=args.height)
    from ssrlab.lab.protocol import parse_set

    try:
        settings.update(parse_set(args.set))
    except ValueError as e:
        ap.error(str(e))

    import numpy as np

    sides = {"baseline": Side("baseline", args.baseline_python), "current": Side("current", args.current_python)}
    try:
        for name, side in sides.items():
            print(f"{name}: {side.hello['module']} on {side.hello['device']}")
        print(f"settings: {', '.join(f'{k}={v}' for k, v in settings.items())}; {args.warmup} warm-up + "
              f"{args.frames} interleaved frames per side; medians (min-max)")
        status = 0
        with tempfile.TemporaryDirectory(prefix="ab_frame_") as tmp:
            for scene in args.scenes:
                for side in sides.values():
                    side.ask(cmd="setup", scene=scene, settings=settings)
                for _ in range(args.warmup):
                    for side in sides.values():
                        side.ask(cmd="render")
                res = {n: [] for n in sides}
                for i in range(args.frames):
                    # Alternate which side goes first, so neither always follows the other.
                    order = list(sides.items()) if i % 2 == 0 else list(reversed(sides.items()))
                    last = i == args.frames - 1
                    for n, side in order:
                        res[n].append(side.ask(cmd="render", image=str(Path(tmp) / f"{n}.npy") if last else None))
                img = {n: np.load(Path(tmp) / f"{n}.npy") for n in sides}
                print(f"\n{scene} {args.width}x{args.height}")
                print("| side | GPU total ms | wall ms (render + color) |\n|---|---|---|")
                stats = {}
                for n in sides:
                    g = median_range([r["gpu"] for r in res[n]])
                    w = median_range([r["wall"] for r in res[n]])
                    stats[n] = (g, w)
                    print(f"| {n} | {g[0]:.1f} ({g[1]:.1f}-{g[2]:.1f}) | {w[0]:.1f} ({w[1]:.1f}-{w[2]:.1f}) |")
                if args.passes:
                    names = sorted(set(res["baseline"][0]["passes"]) | set(res["current"][0]["passes"]))
                    print("| pass | baseline ms | current ms |\n|---|---|---|")
                    for p in names:
                        cells = []
                        for n in sides:
                            v = [r["passes"][p] for r in res[n] if p in r["passes"]]
                            cells.append(f"{statistics.median(v):.2f}" if v else "-")
                        print(f"| {p} | {cells[0]} | {cells[1]} |")
                (bg, bw), (cg, cw) = stats["baseline"], stats["current"]
                print(f"speed-up (baseline / current median): GPU {bg[0] / cg[0]:.2f}x ({verdict(bg, cg)}), "
                      f"wall {bw[0] / cw[0]:.2f}x ({verdict(bw, cw)})")
                a, b = img["current"].astype(np.float64), img["baseline"].astype(np.float64)
                if a.shape != b.shape:
                    print(f"images differ in shape: {a.shape} vs {b.shape}")
                    status = 1
                    continue
                per_pixel = np.abs(a - b).sum(axis=-1)
                err = float(per_pixel.mean())
                print(f"thesis error between the images {err:.2e} (largest per-pixel {float(per_pixel.max()):.2e}, "
                      f"pixels above 1e-3: {int((per_pixel > 1e-3).sum())} of {per_pixel.size}); "
                      f"{'within' if err <= 1e-3 else 'ABOVE'} 1e-3")
                if not np.isfinite(err):
                    status = 1
        return status
    finally:
        for side in sides.values():
            side.close()


if __name__ == "__main__":
    if "--worker" in sys.argv[1:]:
        sys.exit(worker())
    sys.exit(main())
