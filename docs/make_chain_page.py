"""Writes docs/architecture/chain.md: the chain of passes of a few representative settings, as
ssrlab.chain.derive orders them from the passes' own declarations (what each reads and writes).

    python docs/make_chain_page.py          # rewrite the page
    python docs/make_chain_page.py --check  # exit 1 if the page differs from what the code says

tests/test_docs.py runs the check, so the page cannot drift from the code. The chains are those of
`ssrlab.scenes.stand_in()`, the scene Renderer.chain uses without one (a sun that casts a shadow and a
mirror floor: every pass that depends on a scene fact runs, the shadow map's included), on the CPU
device (the passes read their float inputs by imageLoad). No GL context is made.
"""

from __future__ import annotations

import sys
from pathlib import Path

PAGE = Path(__file__).resolve().parent / "architecture" / "chain.md"

CONFIGURATIONS = [
    ("The thesis's frame: linear tracing, stochastic GGX rays, the resolve", dict(rays_per_pixel=4)),
    ("Hi-Z tracing (seed 002)", dict(method="hiz")),
    ("Hi-Z cone tracing for glossy reflections (seed 002, 4.4)", dict(method="hiz", glossy="cone")),
    ("Skipping what the scene does not need", dict(skip=True, variance_rays=True, adaptive_rays=True,
                                                   rays_per_pixel=4)),
    ("The hybrid: screen space, then the BVH", dict(fallback="bvh")),
    ("Ray-traced reflections (seed 003)", dict(method="bvh")),
    ("A sequence with the SVGF denoiser and TAA", dict(denoise="svgf", taa="clamped")),
]


def page() -> str:
    import ssrlab

    lines = ["# The chain, from the code", "",
             "Made by `python docs/make_chain_page.py` from `ssrlab.chain.derive(settings)` (what "
             "`Renderer.chain(settings)` lists, without a GL context), which asks each pass whether it runs and "
             "what it reads and writes, and orders the passes by those declarations "
             "([declarations and the chain's order](order.md)); GPU buffers in italics: the work lists a pass "
             "hands to a later one. `tests/test_docs.py` fails when this page and the code disagree. Scene: "
             "`ssrlab.scenes.stand_in()` (what `Renderer.chain(settings)` uses without a scene); float inputs "
             "read by imageLoad (the CPU device's path: on a GPU the resolve reads its neighbours' rays from "
             "shared memory and `resolve_fetch` does not run).", ""]
    for title, kw in CONFIGURATIONS:
        settings = ssrlab.Settings(width=64, height=48, **kw)
        chain = ssrlab.chain.derive(settings, ssrlab.scenes.stand_in(), device="cpu")
        changed = ", ".join(f"{k}={v!r}" for k, v in kw.items())
        lines += [f"## {title}", "", f"`Settings({changed})`", "", chain.markdown(), "",
                  "Its textures: their formats and declared channels (what Frame's views show), who creates each, rewrites it in place and reads it.", "", chain.resources(), ""]
    return "\n".join(lines)


def main() -> int:
    text = page()
    if "--check" in sys.argv[1:]:
        if not PAGE.is_file() or PAGE.read_text() != text:
            print(f"{PAGE} differs from what the code says: run python docs/make_chain_page.py")
            return 1
        return 0
    PAGE.parent.mkdir(parents=True, exist_ok=True)
    PAGE.write_text(text)
    print(f"wrote {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
