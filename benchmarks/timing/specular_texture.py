"""What KHR_materials_specular's textures cost a frame: a mirror floor, a sphere and a black
dielectric wall whose specularTexture and specularColorTexture are checkerboards, rendered with the
textures (FrameFacts.specular_texture: gbuffer.specular written by depth_peel, read by lighting and
the PBR composite) and the same scene without them (the factors only, no extra layer),
interleaved round by round, `--repeats` timed rounds after the protocol's warm-up rounds
(ssrlab.lab.protocol). Records, and prints from them, the median and interquartile range of depth_peel,
lighting, composite and the frame's total, the paired ratio factor / texture and the verdict of
factor against texture (records.figure_verdict: 'undecided' where the noise cannot tell).

    python benchmarks/timing/specular_texture.py                       # 640x360, 4 layers, PBR composite
    python benchmarks/timing/specular_texture.py --deep-gbuffer lists
    python benchmarks/timing/specular_texture.py --base-texture   # both walls textured already

Without textures the wall's material is an untextured kind, whose shading pass samples nothing
(GpuScene::material_features); with --base-texture both scenes give it a base colour texture, so
that the comparison is of the specular textures and gbuffer.specular alone.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import ab_scenes, benchmark_arguments, open_renderer  # noqa: E402
from ssrlab.lab.protocol import Bench  # noqa: E402

import ssrlab  # noqa: E402

PARTS = ("depth_peel", "lighting", "composite", "total")


def checker(cells: int, even, odd, texels: int = 256) -> np.ndarray:
    i, j = np.meshgrid(np.arange(texels) * cells // texels, np.arange(texels) * cells // texels, indexing="ij")
    return np.where(((i + j) % 2 == 0)[..., None], np.asarray(even, np.uint8), np.asarray(odd, np.uint8))


def scene(textured: bool, base_texture: bool) -> ssrlab.Scene:
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), (12, 12), material=ssrlab.Material(base_color=(0.9, 0.9, 0.9), roughness=0.05,
                                                               metallic=1.0, reflectivity=1.0), name="floor")
    wall = ssrlab.Material(base_color=(0.02, 0.02, 0.02), roughness=0.4, reflectivity=0.0, name="wall")
    wall.specular_color = (2.0, 1.0, 0.5)
    if base_texture:
        wall.base_color_texture = s.add_image(checker(2, (255, 255, 255), (200, 200, 200)), name="base")
    if textured:
        wall.specular_texture = s.add_image(checker(8, (0, 0, 0, 255), (0, 0, 0, 64)), name="specular")
        wall.specular_color_texture = s.add_image(checker(4, (255, 128, 64), (64, 255, 128)), name="specular_color")
    s.add_plane((0, 1.5, -2.0), (8, 3), normal=(0, 0, 1), material=wall, name="wall")
    s.add_sphere((0.8, 0.6, -0.5), 0.6, material=wall, name="sphere")
    s.add_light(ssrlab.directional_light((0.2, -0.4, -1.0), intensity=4.0))
    s.ambient = (0.02, 0.02, 0.02)
    s.environment = ssrlab.Environment.constant((0.1, 0.12, 0.15))
    s.camera = ssrlab.Camera(position=(0.0, 1.0, 3.0), target=(0.0, 0.5, -2.0), fov_y=50.0, near=0.1, far=30.0)
    return s


def main() -> None:
    ap = benchmark_arguments(__doc__, repeats=9)
    ap.add_argument("--layers", type=int, default=4)
    ap.add_argument("--deep-gbuffer", default="peel", choices=("peel", "lists"))
    ap.add_argument("--composite", default="pbr", choices=("pbr", "linear"))
    ap.add_argument("--base-texture", action="store_true", help="give the wall a base colour texture in both scenes")
    args = ap.parse_args()
    renderer = open_renderer(args)
    textured, factor = scene(True, args.base_texture), scene(False, args.base_texture)
    settings = ssrlab.Settings(width=args.width, height=args.height, layers=args.layers,
                               deep_gbuffer=args.deep_gbuffer, composite=args.composite)
    bench = Bench("specular_texture", args, renderer)
    ab_scenes(bench, renderer, {"texture": textured, "factor": factor}, settings, PARTS,
              f"{args.width}x{args.height}, {args.layers} layers, deep_gbuffer={args.deep_gbuffer}, "
              f"composite={args.composite}, base texture {args.base_texture}",
              dict(width=args.width, height=args.height, layers=args.layers, deep_gbuffer=args.deep_gbuffer,
                   composite=args.composite, base_texture=args.base_texture))

if __name__ == "__main__":
    main()
