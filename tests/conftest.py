"""Shared fixtures. Every test renders on llvmpipe-sized images and passes without a GPU; on
a machine with one, device="auto" renders there instead, and the tests of device="cpu" itself
(marked needs_cpu_device) skip where there is no software rasteriser."""

from __future__ import annotations

import functools
import json
import os
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

import ssrlab

REPO = Path(__file__).resolve().parents[1]


def benchmark_script(name: str) -> Path:
    """A benchmark's script by its name (its records' benchmark name), in whichever genre folder of
    benchmarks/ holds it (benchmarks/README.md)."""
    found = sorted((REPO / "benchmarks").glob(f"*/{name}.py"))
    assert len(found) == 1, f"benchmarks/*/{name}.py: {found}"
    return found[0]
# The sample models are part of the repository and of the package (python/ssrlab/sample_models):
# this checkout's copy, then the one the installed package found for itself (ssrlab.models, which
# the scene builders use, needs no $SSRLAB_MODELS).
MODELS = list(dict.fromkeys([REPO / "python" / "ssrlab" / "sample_models",
                             getattr(ssrlab.models, "PACKAGED", REPO / "python" / "ssrlab" / "sample_models")]))
# FLIP costs tens to hundreds of milliseconds for each of the suite's small images (docs/metrics.md),
# more than most of its renders: sweeps here leave FLIP and SSIM out unless a test asks (perceptual=True, or
# SSRLAB_PERCEPTUAL=1 as the thesis_layers notebook's test does).
os.environ.setdefault("SSRLAB_PERCEPTUAL", "0")

# SSRLAB_TEST_GPU_PATHS=1: every Renderer the tests open takes the paths a GPU takes by default
# (clears by compute, no visibility tiles, texelFetch input, staged readback) on whatever device
# it opens, so that a machine without a GPU runs the GPU's code paths too. The tests of the defaults
# themselves skip then (GPU_PATHS).
GPU_PATHS = os.environ.get("SSRLAB_TEST_GPU_PATHS", "") == "1"
if GPU_PATHS:
    _renderer_init = ssrlab.Renderer.__init__

    @functools.wraps(_renderer_init)
    def _gpu_paths_init(self, device="auto", *, shader_dir=None, input_fetch="auto"):
        _renderer_init(self, device, shader_dir=shader_dir,
                       input_fetch="texelFetch" if input_fetch == "auto" else input_fetch)
        self.clear_path = "compute"
        self.visibility_tiles = "off"
        self.readback_path = "staged"

    ssrlab.Renderer.__init__ = _gpu_paths_init
gpu_paths_skip = pytest.mark.skipif(GPU_PATHS, reason="SSRLAB_TEST_GPU_PATHS=1 replaces the defaults under test")

# Every subprocess a test starts ends: subprocess.run without a timeout gets this one, so that a
# CLI that hangs fails its test instead of the whole suite.
SUBPROCESS_TIMEOUT_S = 600
_subprocess_run = subprocess.run


def _run_with_timeout(*args, **kwargs):
    kwargs.setdefault("timeout", SUBPROCESS_TIMEOUT_S)
    return _subprocess_run(*args, **kwargs)


subprocess.run = _run_with_timeout


@pytest.fixture(scope="session")
def renderer():
    return ssrlab.Renderer("auto")


# -- the CPU device -------------------------------------------------------------------------------
# A few tests are about device="cpu" itself (Mesa's llvmpipe): that it opens, that $SSRLAB_DEVICE
# pins it. A machine with a GPU need not have Mesa's software rasteriser (an NVIDIA image ships
# NVIDIA's libEGL only), and there those tests skip, saying why. Every other test renders on the
# device at hand (device="auto").

def cpu_device_absence(open_cpu=None) -> str | None:
    """None where device="cpu" opens Mesa's software rasteriser; else why not, in words. Decided
    the way the tests would use it: by opening ssrlab.Renderer("cpu") (`open_cpu`, for a test of this
    helper), whose DeviceError names what EGL offered instead."""
    try:
        r = (open_cpu or (lambda: ssrlab.Renderer("cpu")))()
    except ssrlab.DeviceError as e:
        return f"no CPU device (Mesa's llvmpipe) here: {e}"
    if r.info["device"] != "cpu":
        return f"device='cpu' opened {r.info['renderer']!r}, which is not a software rasteriser"
    return None


@functools.lru_cache(maxsize=None)
def cpu_device_absence_here() -> str | None:
    """cpu_device_absence() of this machine, decided once per test process."""
    return cpu_device_absence()


def pytest_configure(config):
    config.addinivalue_line("markers", "needs_cpu_device: the test opens device='cpu' (Mesa's llvmpipe) and "
                                       "skips, naming why, where this machine has none")


def pytest_runtest_setup(item):
    if item.get_closest_marker("needs_cpu_device") is not None:
        why = cpu_device_absence_here()
        if why is not None:
            pytest.skip(why)


@pytest.fixture(autouse=True)
def no_gl_errors(request):
    """After every test that rendered, GL must not have reported an error."""
    yield
    if "renderer" in request.fixturenames:
        request.getfixturevalue("renderer")._native.check_gl()


def model_path(rel: str) -> Path:
    """The sample model `rel` (e.g. "Suzanne/Suzanne.gltf"). They come with the checkout, so a
    missing one is a broken checkout or package: a failure, never a skip."""
    for base in MODELS:
        if (base / rel).is_file():
            return base / rel
    pytest.fail(f"sample model {rel} not found under {', '.join(map(str, MODELS))}: the checkout or the "
                f"installed package lacks its sample_models")


def suzanne_copy(tmp_path: Path) -> Path:
    """A copy of the Suzanne sample model in tmp_path/model (to edit)."""
    import shutil

    src = model_path("Suzanne/Suzanne.gltf").parent
    dst = tmp_path / "model"
    shutil.copytree(src, dst)
    return dst / "Suzanne.gltf"


def gltf_json(path: Path) -> dict:
    """The JSON chunk of a .gltf or .glb file (read independently of the loader under test)."""
    data = path.read_bytes()
    if data[:4] == b"glTF":
        length = struct.unpack("<I", data[12:16])[0]
        return json.loads(data[20:20 + length])
    return json.loads(data)


def bits(a: np.ndarray) -> np.ndarray:
    """The texels as their bit patterns (equal floats, NaNs and signed zeros compare exactly)."""
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


@functools.lru_cache(maxsize=None)
def image_load_refusal() -> str | None:
    """Why this machine's default device refuses Renderer(input_fetch="imageLoad") (NVIDIA's GL
    offers a compute shader 8 image units; the passes read 10 that way), or None where it runs."""
    try:
        ssrlab.Renderer("auto", input_fetch="imageLoad")
    except ValueError as e:
        return str(e)
    return None


def small(**kw) -> ssrlab.Settings:
    """Settings for a small test image. The deep G-buffer is peeled unless a test names another
    construction: 'auto' chooses by measurement, and on a GPU, where the visibility constructions
    are the faster, a small image's timings can choose either, per renderer; their attributes differ
    from peeling's in the last bits (docs/deep_gbuffer.md), so tests that compare two renderers'
    images, or one against fixed expectations, name theirs (test_visibility_buffer.py and
    test_deep_gbuffer.py test the others and 'auto' itself)."""
    kw.setdefault("deep_gbuffer", "peel")
    kw.setdefault("width", 96)
    kw.setdefault("height", 64)
    kw.setdefault("shadow_map_size", 512)
    return ssrlab.Settings(**kw)


def assert_finite(a: np.ndarray, what: str = "array") -> None:
    bad = ~np.isfinite(a)
    assert not bad.any(), f"{what}: {int(bad.sum())} NaN/Inf values"
