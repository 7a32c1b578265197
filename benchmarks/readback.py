"""The CPU side of reading a frame back (issue 13, frame overheads): both readback paths, one run.

    python benchmarks/readback.py [--sizes 640x360 1920x1080] [--repeats 15] [--device auto|gpu|cpu]

A texture reaches numpy by one of two paths (Renderer::read_texture): a float texture (the final
colour and the rays RGBA32F, lit and the normals RGBA16F, depths R32F) is downloaded as stored
(RGBA16F as halves, widened with F16C where the CPU has it), its rows put top first by the driver
(GL_MESA_pack_invert, Mesa; `Renderer.info["readback_rows"]`) or swapped on the CPU; a normalised,
sRGB or depth texture (the G-buffer's albedo and material, the depth buffer) is first decoded to float RGBA by the readback copy pass
(shaders/passes/readback.comp) into a buffer, which is then downloaded. Every texture took the
second path before. For one frame of `hall` per size, the script times the native
read of each texture below (the Python-side cache is bypassed: every read goes to the GPU), medians
and IQR of --repeats after 2 warm-up reads, and prints MB/s of the float32 array delivered. Where two
textures of one size take different paths, the ratio of their per-byte times compares the paths on
the same run: the verdict says "faster" only where the IQRs do not overlap.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import benchmark_arguments, open_renderer  # noqa: E402

# name: readback path (float formats downloaded directly, the others through the copy pass)
TEXTURES = {"color": "direct", "lit": "direct", "gbuffer.albedo": "copy pass", "gbuffer.material": "copy pass"}


def time_reads(frame, name: str, repeats: int) -> tuple[np.ndarray, int]:
    for _ in range(2):
        data = frame.read(name, cache=False)
    ms = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        data = frame.read(name, cache=False)
        ms.append((time.perf_counter() - t0) * 1e3)
    return np.asarray(ms), data.nbytes


def main(argv=None) -> int:
    ap = benchmark_arguments(__doc__, repeats=15)
    ap.add_argument("--sizes", nargs="+", default=["640x360", "1920x1080"], help="WIDTHxHEIGHT")
    args = ap.parse_args(argv)
    import ssrlab

    renderer = open_renderer(args)
    scene = ssrlab.scenes.hall()
    print(f"medians (IQR) of {args.repeats} native reads after 2 warm-ups; the float32 RGBA array delivered")
    print("| size | texture | path | MB | ms (IQR) | MB/s |")
    print("|---|---|---|---|---|---|")
    for size in args.sizes:
        w, h = (int(v) for v in size.lower().split("x"))
        frame = renderer.render(scene, settings=ssrlab.Settings(width=w, height=h, method="hiz", sampling="mirror"))
        per_byte = {}
        for name, path in TEXTURES.items():
            ms, nbytes = time_reads(frame, name, args.repeats)
            q1, med, q3 = np.percentile(ms, [25, 50, 75])
            per_byte.setdefault(path, []).append((q1 / nbytes, med / nbytes, q3 / nbytes))
            print(f"| {w}x{h} | {name} | {path} | {nbytes / 1e6:.1f} | {med:.3f} ({q1:.3f}-{q3:.3f}) | "
                  f"{nbytes / 1e6 / (med * 1e-3):.0f} |")
        direct = min(per_byte["direct"], key=lambda t: t[1])
        copy = min(per_byte["copy pass"], key=lambda t: t[1])
        verdict = "faster" if direct[2] < copy[0] else "slower" if direct[0] > copy[2] else "no verdict (IQRs overlap)"
        print(f"{w}x{h}: time per byte, direct / copy pass (the best texture of each): {direct[1] / copy[1]:.2f}: "
              f"direct download {verdict}")
        frame.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
