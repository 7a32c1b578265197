"""The CPU side of reading a frame back: the two readback paths, A/B in one run.

    python benchmarks/readback.py [--sizes 640x360 1920x1080] [--repeats 15] [--device auto|gpu|cpu]

A texture reaches numpy by one of two paths (Renderer.readback_path):
  download  a float texture (the final colour and the rays RGBA32F, lit and the normals RGBA16F,
            depths R32F) downloaded as stored by glGetTextureSubImage (RGBA16F as halves, widened
            with F16C), its rows put top first by the driver (GL_MESA_pack_invert, Mesa) or swapped
            on the CPU; a normalised, sRGB or depth texture decoded to float RGBA by the readback
            copy pass (shaders/passes/readback.comp) into a buffer, then downloaded;
  staged    every texture through the copy pass, the buffer copied by the GPU into pinned client
            memory (a persistently mapped buffer), then into the array by several threads.
For one frame of `hall` per size, the script times the native read of each texture below (the
Python-side cache is bypassed: every read goes to the device), the two paths interleaved read by
read, medians and IQR of --repeats after 2 warm-up reads. The verdict says "faster" or "slower"
only where the IQRs do not overlap. Each path's reads are a record (ssrlab.lab.records) of their
samples; the table is rendered from them.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

# name: readback path (float formats downloaded directly, the others through the copy pass)
TEXTURES = {"color": "direct", "lit": "direct", "gbuffer.albedo": "copy pass", "gbuffer.material": "copy pass"}
PATHS = ("download", "staged")


def time_reads(renderer, frame, name: str, repeats: int) -> dict[str, np.ndarray]:
    """ms per native read of `name` by each readback path, the paths interleaved read by read."""
    ms = {path: [] for path in PATHS}
    for i in range(repeats + 2):
        for path in PATHS:
            renderer.readback_path = path
            t0 = time.perf_counter()
            data = frame.read(name, cache=False)
            if i >= 2:  # 2 warm-up reads per path
                ms[path].append((time.perf_counter() - t0) * 1e3)
    renderer.readback_path = "auto"
    return {p: np.asarray(v) for p, v in ms.items()}, data.nbytes


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=15)
    ap.add_argument("--sizes", nargs="+", default=["640x360", "1920x1080"], help="WIDTHxHEIGHT")
    args = ap.parse_args(argv)
    import ssrlab
    from ssrlab.lab import records, timing

    renderer = open_renderer(args)
    bench = Bench("readback", args, renderer)
    scene = ssrlab.scenes.hall()
    print(f"medians (IQR) of {args.repeats} native reads per path after 2 warm-ups, the paths interleaved; "
          f"the float32 RGBA array delivered; 'auto' is {renderer.info['readback_path']} on this device")
    rows = []
    for size in args.sizes:
        w, h = (int(v) for v in size.lower().split("x"))
        frame = renderer.render(scene, settings=ssrlab.Settings(width=w, height=h, method="hiz", sampling="mirror"))
        for name, path in TEXTURES.items():
            ms, nbytes = time_reads(renderer, frame, name, args.repeats)
            params = dict(size=f"{w}x{h}", texture=name, download_path=path, bytes=nbytes)
            recs = {p: bench.record({**params, "path": p}, "read", "ms", ms[p]) for p in PATHS}
            q = {p: records.summary(r["samples"]) for p, r in recs.items()}
            d, st = q["download"], q["staged"]
            # (median, q1, q3): the interquartile ranges apart, or no verdict
            apart = timing.verdict((d["median"], d["p25"], d["p75"]), (st["median"], st["p25"], st["p75"]))
            verdict = f"staged {apart}" if apart != "undecided" else "no verdict (IQRs overlap)"
            rows.append([f"{w}x{h}", name, path, f"{nbytes / 1e6:.1f}"]
                        + [f"{x['median']:.3f} ({x['p25']:.3f}-{x['p75']:.3f})" for x in (d, st)]
                        + [f"{st['median'] / d['median']:.2f}", verdict])
        frame.release()
    print(records.markdown(["size", "texture", "download path", "MB", "download ms (IQR)", "staged ms (IQR)",
                            "staged / download", "verdict"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
