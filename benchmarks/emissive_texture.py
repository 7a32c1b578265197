"""What an emissive texture costs a frame: ssrlab.crosscheck's emissive-texture scene (a black quad
emitting a checkerboard over a mirror floor) rendered with its emissive texture and with the
factor alone, interleaved, `--repeats` timed frames each (first use excluded). Prints the median,
min-max and interquartile range of depth_peel (which writes gbuffer.emission only with the
texture), lighting (which reads it) and the frame's total, the paired ratio texture / factor and
a verdict that says 'undecided' where the two ranges overlap.

    python benchmarks/emissive_texture.py                       # 640x360, 4 layers
    python benchmarks/emissive_texture.py --deep-gbuffer lists
"""

from __future__ import annotations

from common import ab_scenes, benchmark_arguments, open_renderer

import ssrlab
from ssrlab import crosscheck as cc

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
    ab_scenes(renderer, {"texture": textured, "factor": factor}, settings, PARTS, args.repeats,
              f"{args.width}x{args.height}, {args.layers} layers, deep_gbuffer={args.deep_gbuffer}")

if __name__ == "__main__":
    main()
