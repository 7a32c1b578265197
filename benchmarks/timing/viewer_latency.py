"""The live viewer's latency in a real browser: from a drag event in the page to its frame on
screen, split into the event's way to the server, the wait for the render before it (queue), render,
view (the picture of the chosen view), encode and send, transport, decode in the page and display; and the frames shown per second while the camera moves.

Debian's Chromium, headless, drives the page (Playwright); the page's clock and the server's are
the same machine's. The page records each pointer event, each frame's arrival (the blob its image
element is given), its decode (the image's load event) and its display (the second animation frame
after the decode: the frame in which the new image was drawn). The viewer's own
cost is everything but the render.

    python benchmarks/timing/viewer_latency.py [--scene hall] [--width 640 --height 360] [--seconds 4] [--device cpu]
        [--frames background|overlay] [--moving-fps off|FPS] [--floor]

--floor also runs the same drag against a server that answers each camera at once with a ready
picture (nothing to render or view): the viewer's own cost can go no lower on this machine with
this browser and page, and the verdict says how much of the goal that floor leaves.

Goals on a 2-core llvmpipe machine (hall): at least 10 frames shown per second while the camera
moves (progressive resolution), and the viewer's own cost at most 50 ms median at 640x360. On a GPU:
1920x1080 at 60 frames shown per second or more, the viewer's own cost at most 8 ms.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import ssrlab
from ssrlab.viewer.latency import PAGE_HOOKS, PANEL_PX, drag, matched_parts, page_floor, percentile, print_parts
from ssrlab.viewer.server import FRAMES, moving_fps_arg

def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", default="hall")
    ap.add_argument("--width", type=int, default=640, help="the page's canvas width in pixels")
    ap.add_argument("--height", type=int, default=360, help="the page's canvas height in pixels")
    ap.add_argument("--seconds", type=float, default=4.0, help="how long the camera is dragged")
    ap.add_argument("--device", default="auto")
    ap.add_argument("--lossless", action="store_true", help="PNG frames instead of JPEG")
    ap.add_argument("--frames", choices=FRAMES, default=FRAMES[0], help="how the page shows frames (ssrlab.view)")
    ap.add_argument("--moving-fps", default="off", metavar="FPS", type=moving_fps_arg,
                    help="frames a second a moving camera renders at most (ssrlab.view's moving_fps): off or a number")
    ap.add_argument("--set", action="append", metavar="FIELD=VALUE", default=[])
    ap.add_argument("--floor", action="store_true",
                    help="also measure the viewer's own path with nothing to render (the floor under viewer_own)")
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    from ssrlab.lab.protocol import parse_set

    settings = ssrlab.Settings().replace(**parse_set(args.set))
    v = ssrlab.view(args.scene, settings, device=args.device, lossless=args.lossless, accumulate=1, frames=args.frames,
                    moving_fps=args.moving_fps)
    info = v.renderer.info
    print(f"device: {info['renderer']} ({info['device']}), OpenGL {info['gl_version']}; scene {args.scene}, "
          f"canvas {args.width}x{args.height}, {'PNG' if args.lossless else 'JPEG'} frames as {args.frames}, "
          f"moving camera paced at {'no limit' if v.moving_fps is None else f'{v.moving_fps:g} frames/s'}, "
          f"settings {settings!r}")
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=["--no-sandbox"])
            page = browser.new_page(viewport={"width": args.width + PANEL_PX, "height": args.height},
                                    device_scale_factor=1)
            page.add_init_script(PAGE_HOOKS)
            opened = time.time()
            page.goto(v.url)
            if not v.wait(lambda x: any(e["scale"] >= 1 for e in x.history), timeout=120):
                raise SystemExit(f"viewer_latency: no full-resolution frame within 120 s ({v.error or 'no error'})")
            first = min(e["shown_at"] for e in v.history) - opened
            time.sleep(1.0)  # the first frames compile the chain; the drag starts after them
            start_hist = len(v.history)
            t0, t1 = drag(page, args)
            time.sleep(2.0)  # the last frames arrive and the resting frame renders
            events = page.evaluate("window.__events")
            frames = page.evaluate("window.__frames")
            browser.close()
    finally:
        v.close()
    sent = [e for e in v.history[start_hist:]]

    rows = matched_parts(sent, frames, events)
    shown_moving = [r for r in frames if r["displayed"] is not None and t0 * 1e3 <= r["displayed"] <= t1 * 1e3]
    fps = len(shown_moving) / (t1 - t0)
    sizes = sorted({(e["width"], e["height"]) for e in sent})
    # The canvas the page reported (its panel may take more than PANEL_PX: the goal is judged at
    # the canvas the frames were rendered for, said beside the verdict).
    canvas = max(((e["width"], e["height"]) for e in v.history if e["scale"] >= 1), default=(0, 0))
    print(f"first frame {first:.2f} s after the page opened; {len(rows['render'])} frames matched over a "
          f"{t1 - t0:.1f} s drag; sizes rendered {sizes}")
    print_parts(rows)
    print(f"frames shown per second while dragging: {fps:.1f}")
    gpu = info["device"] != "cpu"
    fps_goal, own_goal = (60.0, 8.0) if gpu else (10.0, 50.0)
    floor = page_floor(args) if args.floor else None
    if len(rows["viewer_own"]) < 10:
        print(f"verdict: undecided (only {len(rows['viewer_own'])} frames matched; drag longer: --seconds)")
        return 0
    own = percentile(rows["viewer_own"], 50)
    print(f"goal: >= {fps_goal:.0f} frames shown/s while moving: {'met' if fps >= fps_goal else 'not met'} "
          f"({fps:.1f})")
    print(f"goal: viewer's own cost <= {own_goal:.0f} ms median at {args.width}x{args.height}: "
          f"{'met' if own <= own_goal else 'not met'} ({own:.1f} ms; the page's canvas was "
          f"{canvas[0]}x{canvas[1]})")
    if floor is not None and not np.isnan(floor):
        # What the page's own path takes with nothing rendering beside it: the part of the goal a
        # renderer (its queue, its view and its share of the machine's cores) may take.
        print(f"the floor, with nothing to render, is {floor:.1f} ms median: "
              + (f"{own_goal - floor:.1f} ms of the goal are left to the renderer's presence" if floor < own_goal
                 else f"at or above the goal ({own_goal:.0f} ms): with this page on this machine the goal "
                      f"cannot be met, whatever the renderer does"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
