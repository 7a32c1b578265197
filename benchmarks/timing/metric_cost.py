"""What image_metrics costs with and without FLIP and SSIM (docs/metrics.md).

    python benchmarks/timing/metric_cost.py [--repeats 7]

For each image size, a random linear-radiance pair (values up to 2, so that LDR and HDR FLIP
differ) and a random half of the pixels as the reflective mask; prints the median CPU wall time
of image_metrics(perceptual=False) and (perceptual=True), and of each FLIP map and the SSIM map
alone, the calls interleaved round by round after a warm-up round (the protocol's
Bench.calls); every figure is a record with its samples and the table is rendered from them.
One call at a time on one core; on a shared machine the figures include its load (the load
average at the start is printed and recorded in the records' params).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import benchmark_arguments, open_renderer  # noqa: E402
from ssrlab import metrics  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

SIZES = ((64, 48), (96, 54), (320, 180), (640, 360))


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=7)
    ap.add_argument("--sizes", nargs="+", default=[f"{w}x{h}" for w, h in SIZES], help="WIDTHxHEIGHT of the images")
    args = ap.parse_args()
    # The device fields of the records name the machine's renderer; the metrics run in numpy.
    bench = Bench("metric_cost", args, open_renderer(args), warmup=1)
    load = round(os.getloadavg()[0], 1)
    print(f"load average {load} on {os.cpu_count()} core(s); CPU wall ms of {args.repeats} rounds after a warm-up")
    rng = np.random.default_rng(0)
    for w, h in (tuple(int(v) for v in size.lower().split("x")) for size in args.sizes):
        ref = rng.uniform(0, 2, (h, w, 3)).astype(np.float32)
        img = np.clip(ref + rng.normal(0, 0.05, ref.shape), 0, None).astype(np.float32)
        mask = rng.random((h, w)) > 0.5
        ms = bench.calls({
            "basic": lambda: metrics.image_metrics(img, ref, mask, perceptual=False),
            "all": lambda: metrics.image_metrics(img, ref, mask, perceptual=True),
            "ldr_flip": lambda: metrics.flip_map(img, ref, "ldr"),
            "hdr_flip": lambda: metrics.flip_map(img, ref, "hdr"),
            "ssim": lambda: metrics.ssim_map(img, ref),
        })
        for name, v in ms.items():
            bench.record(dict(image=f"{w}x{h}", runs_on="cpu (numpy)", load_average=load, cores=os.cpu_count()),
                         name, "ms", v)
    bench.print_table(rows=("image",), digits=1)


if __name__ == "__main__":
    main()
