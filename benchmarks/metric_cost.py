"""What image_metrics costs with and without FLIP and SSIM (docs/metrics.md).

    python benchmarks/metric_cost.py [--repeats 7]

For each image size, a random linear-radiance pair (values up to 2, so that LDR and HDR FLIP
differ) and a random half of the pixels as the reflective mask; prints the median CPU wall time
of image_metrics(perceptual=False) and (perceptual=True), and of each FLIP map and the SSIM map
alone. One call at a time on one core; on a shared machine the figures include its load.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from ssrlab import metrics

SIZES = ((64, 48), (96, 54), (320, 180), (640, 360))


def median_ms(f, repeats: int) -> float:
    f()  # first call: imports, allocations
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return float(np.median(times)) * 1e3


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--repeats", type=int, default=7)
    args = p.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} core(s); median of {args.repeats}")
    print(f"{'image':>9} {'basic ms':>9} {'all ms':>9} {'LDR-FLIP':>9} {'HDR-FLIP':>9} {'SSIM':>7}")
    rng = np.random.default_rng(0)
    for w, h in SIZES:
        ref = rng.uniform(0, 2, (h, w, 3)).astype(np.float32)
        img = np.clip(ref + rng.normal(0, 0.05, ref.shape), 0, None).astype(np.float32)
        mask = rng.random((h, w)) > 0.5
        basic = median_ms(lambda: metrics.image_metrics(img, ref, mask, perceptual=False), args.repeats)
        full = median_ms(lambda: metrics.image_metrics(img, ref, mask, perceptual=True), args.repeats)
        ldr = median_ms(lambda: metrics.flip_map(img, ref, "ldr"), args.repeats)
        hdr = median_ms(lambda: metrics.flip_map(img, ref, "hdr"), args.repeats)
        ssim = median_ms(lambda: metrics.ssim_map(img, ref), args.repeats)
        print(f"{w:>4}x{h:<4} {basic:9.1f} {full:9.1f} {ldr:9.1f} {hdr:9.1f} {ssim:7.1f}")


if __name__ == "__main__":
    main()
