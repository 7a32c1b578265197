"""How closely the converged reference's C++ tracer (tracer="cpu") reproduces the GLSL tracer
(tracer="glsl"), per case of tests/test_reference_cpu.py: PSNR of the final colour and of the
reflection, the largest pixel difference and the share of pixels more than 1e-3 apart. The
figures behind the test's stated bound (docs/reference_tracers.md).

    python benchmarks/accuracy/reference_cpu_agreement.py [--device auto|cpu|gpu]
"""

from __future__ import annotations

import sys
import argparse
import tempfile
from pathlib import Path

import numpy as np

import ssrlab

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository's root: benchmarks.common from any cwd
from benchmarks.common import open_renderer  # noqa: E402


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    peak = max(float(np.abs(b).max()), 1e-6)
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(peak * peak / mse)


def compare(r, label, scene, width, height, **kw):
    frame = r.render(scene, settings=ssrlab.Settings(width=width, height=height, method="off", shadow_map_size=512))
    glsl = frame.reference("converged", tracer="glsl", **kw)
    want = {"color": glsl.color.copy(), "reflection": glsl.reflection.copy()}
    cpu = frame.reference("converged", tracer="cpu", **kw)
    cols = []
    for key, b in want.items():
        a = getattr(cpu, key)
        d = np.abs(a - b).max(axis=-1)
        cols.append(f"{key} {psnr(a, b):6.1f} dB, max {d.max():.1e}, >1e-3 {(d > 1e-3).mean():.2%}")
    opts = " ".join(f"{k}={v}" for k, v in kw.items())
    print(f"{label:<42} {opts:<40} " + " | ".join(cols), flush=True)


def model_scene(rel: str, roughness: float):
    try:
        path = ssrlab.models.find(rel)
    except FileNotFoundError as e:
        print(e)
        return None
    scene = ssrlab.scenes.load(str(path))
    lo, hi = (np.asarray(b, dtype=float) for b in scene.bounds)
    size = float(np.max(hi - lo)) * 3
    scene.add_plane(((lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2), (size, size), name="floor",
                    material=ssrlab.Material(base_color=(0.6, 0.6, 0.6), roughness=roughness, reflectivity=0.8))
    return scene


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--device", default="auto", choices=("auto", "gpu", "cpu"))
    r = open_renderer(ap.parse_args())
    for name in ssrlab.scenes.SCENES:
        for sampling, rays in (("mirror", 1), ("vndf", 3)):
            compare(r, name, ssrlab.scenes.load(name), 80, 48, rays=rays, sampling=sampling)
    for rel in ("Suzanne/Suzanne.gltf", "2CylinderEngine/2CylinderEngine.glb"):
        for roughness in (0.0, 0.35):
            scene = model_scene(rel, roughness)
            if scene is None:
                break
            compare(r, f"{rel.split('/')[0]} on a {roughness} floor", scene, 64, 48, rays=3)
    scene = ssrlab.scenes.load("spheres_and_boxes")
    compare(r, "spheres_and_boxes", scene, 64, 40, rays=11, sampling="ggx", viewer="camera", seed=3)
    with tempfile.TemporaryDirectory() as d:
        y, x = np.mgrid[0:16, 0:32].astype(np.float32)
        env = np.stack([x / 31.0, y / 15.0, 0.5 + 0.5 * np.sin(x / 3.0)], -1).astype(np.float32) * 2.0
        ssrlab.io.write_image(Path(d) / "env.exr", env, ["R", "G", "B"])
        scene.environment = ssrlab.Environment.map(str(Path(d) / "env.exr"))
        compare(r, "spheres_and_boxes, environment map", scene, 64, 40, rays=3)


if __name__ == "__main__":
    main()
