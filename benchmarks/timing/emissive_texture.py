"""What an emissive texture costs a frame: ssrlab.crosscheck's emissive-texture scene (a black quad
emitting a checkerboard over a mirror floor) rendered with its emissive texture and with the
factor alone, interleaved round by round, `--repeats` timed rounds after the protocol's warm-up
rounds (ssrlab.lab.protocol). Records, and prints from them, the median and interquartile range of depth_peel (which writes gbuffer.emission only with the
texture), lighting (which reads it) and the frame's total, the paired ratio factor / texture and
the verdict of factor against texture (records.figure_verdict: 'undecided' where the noise cannot tell).

    python benchmarks/timing/emissive_texture.py                       # 640x360, 4 layers
    python benchmarks/timing/emissive_texture.py --deep-gbuffer lists
"""

from __future__ import annotations

import sys
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import ab_scenes, benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

import ssrlab  # noqa: E402
from ssrlab import crosscheck as cc  # noqa: E402

PARTS = ("depth_peel", "lighting", "total")


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.add_argument("--layers", type=int, default=4)
    ap.add_argument("--deep-gbuffer", default="peel", choices=("peel", "lists"))
    args = ap.parse_args()
    renderer = open_renderer(args)
    textured = cc.emissive_texture_crosscheck_scene()
    factor = cc.emissive_texture_crosscheck_scene()
    quad = factor.object_count - 1
    m = factor.material(quad)
    m.emissive_texture = -1
    factor.set_material(quad, m)
    settings = ssrlab.Settings(width=args.width, height=args.height, layers=args.layers,
                               deep_gbuffer=args.deep_gbuffer)
    bench = Bench("emissive_texture", args, renderer)
    ab_scenes(bench, renderer, {"texture": textured, "factor": factor}, settings, PARTS,
              f"{args.width}x{args.height}, {args.layers} layers, deep_gbuffer={args.deep_gbuffer}",
              dict(width=args.width, height=args.height, layers=args.layers, deep_gbuffer=args.deep_gbuffer))

if __name__ == "__main__":
    main()
