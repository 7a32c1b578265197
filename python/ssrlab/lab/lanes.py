"""How a SIMD vector's lanes use the walk steps it pays for, from per-ray step counts.

A vector runs until the longest walk among its lanes ends: where neighbouring rays walk very
different lengths, most lanes idle. The trace shaders lay their rays out over classify's list order
(32x32 regions, 4x4 blocks) with two rays per lane of an 8-lane vector; lane_use gives the share
of the paid steps that do work for the two layouts the trace could use (benchmarks/tools/ab_pass.py
--lane-use).
"""

from __future__ import annotations

import numpy as np


def list_order_steps(steps: np.ndarray) -> np.ndarray:
    """Steps of the traced pixels in classify's list order: 32x32 regions in rows, in each the 8x8
    invocations in rows, each its 4x4 block of pixels in rows."""
    h, w = steps.shape
    order = []
    for ry in range(0, h, 32):
        for rx in range(0, w, 32):
            region = steps[ry:ry + 32, rx:rx + 32]
            rh, rw = region.shape
            padded = np.zeros((32, 32))
            padded[:rh, :rw] = region
            blocks = padded.reshape(8, 4, 8, 4).transpose(0, 2, 1, 3).reshape(-1)
            order.append(blocks[blocks > 0])
    return np.concatenate(order)


def lane_use(steps: np.ndarray) -> dict[str, float]:
    """Used / paid steps for a vector on entries i and i + 32 of a 64-entry group, and on 16
    consecutive entries (two rays per lane, eight lanes)."""
    v = list_order_steps(steps)
    g = v[: len(v) // 64 * 64].reshape(-1, 64)
    useful = g.sum()
    # A vector pays 2 steps (its two rays) per iteration, as long as the longest of its 16 rays.
    far = sum(np.maximum(g[:, 8 * k:8 * k + 8], g[:, 32 + 8 * k:40 + 8 * k]).max(axis=1).sum() for k in range(4))
    near = sum(g[:, 16 * k:16 * k + 16].max(axis=1).sum() for k in range(4))
    return {"entries i, i+32": useful / (16 * far), "16 consecutive entries": useful / (16 * near)}


__all__ = ["list_order_steps", "lane_use"]
