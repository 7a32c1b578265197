"""Writing results: PNG (sRGB, 8-bit), EXR (float, via OpenImageIO) and JSON.

Output folders keep a manifest (``.ssrlab-manifest.json``) of the files ssrlab wrote there
and their SHA-256. A later run replaces those files freely, but never a file that ssrlab
did not write, or one changed since it did, unless asked to (``overwrite=True``): nothing a
user wrote is lost without asking.
"""

from __future__ import annotations

import errno
import functools
import hashlib
import json
import os
import tempfile
from pathlib import Path
from typing import Callable

import numpy as np

from . import _core

MANIFEST = ".ssrlab-manifest.json"
OutputError = _core.OutputError


def output_error(exc: BaseException, target: Path) -> OSError:
    """An OutputError (an OSError) naming `target`, the file the user asked for, with the cause of
    `exc`, which may name a temporary file: errno and strerror are kept where the cause has them."""
    code = getattr(exc, "errno", None) or errno.EIO
    cause = getattr(exc, "strerror", None) or str(exc) or type(exc).__name__
    return OutputError(code, f"cannot write {target.name}: {cause}", str(target))


def atomic_write(target: Path, writer: Callable[[Path], None]) -> None:
    """Calls writer(temp_path) on a temporary file beside `target`, then renames it into place: a
    failure (a full disk, a writer that raises) leaves `target` as it was and no partial file, and
    raises an OutputError naming `target`."""
    target = Path(target)
    suffix = "".join(target.suffixes) or ".tmp"
    try:
        fd, tmp = tempfile.mkstemp(prefix=".ssrlab-", suffix=suffix, dir=target.parent)
    except OSError as exc:
        raise output_error(exc, target) from exc
    os.close(fd)
    try:
        writer(Path(tmp))
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600 files; give the usual mode
        os.replace(tmp, target)
    except OSError as exc:
        raise output_error(exc, target) from exc
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def linear_to_srgb(linear: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """sRGB transfer function (IEC 61966-2-1) of exposure * linear, clamped to [0, 1]."""
    x = np.clip(np.asarray(linear, dtype=np.float32) * exposure, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055).astype(np.float32)


def to_bytes(rgb: np.ndarray) -> np.ndarray:
    """Display floats in [0, 1] as (H, W, 3) uint8, rounded to the nearest code."""
    return np.ascontiguousarray(np.clip(np.rint(np.asarray(rgb, np.float32) * 255.0), 0, 255).astype(np.uint8))


@functools.cache
def srgb8_thresholds() -> np.ndarray:
    """For each 8-bit code k = 1..255, the smallest float32 linear value in [0, 1] that
    linear_to_srgb (at exposure 1) and to_bytes take to k or more: float32 (255,), increasing.
    Since that code never falls as the value rises, a value's code is how many thresholds lie at
    or below it: how Frame.srgb8 encodes on the device (passes/display_bytes.comp) with the codes
    of this one transfer function."""
    def code(bits: np.ndarray) -> np.ndarray:
        return to_bytes(linear_to_srgb(bits.view(np.float32)[:, None]))[:, 0].astype(np.int32)

    k = np.arange(1, 256, dtype=np.int32)
    # Bisection over the bit patterns of the float32 values in [0, 1], which order as the values:
    # code(lo) < k <= code(hi) throughout.
    lo = np.zeros(255, np.int32)
    hi = np.full(255, np.float32(1.0).view(np.int32), np.int32)
    while np.any(hi - lo > 1):
        mid = lo + (hi - lo) // 2
        up = code(mid) >= k
        hi, lo = np.where(up, mid, hi), np.where(up, lo, mid)
    out = hi.view(np.float32)
    out.flags.writeable = False
    return out


def image_backend() -> str:
    """Who reads and writes image files: "OpenImageIO" (an extension built with it) or "python"
    (ssrlab.image_codec through the OpenEXR and Pillow packages: the wheel)."""
    return str(_core.image_io_backend())


def write_image(path, pixels: np.ndarray, channel_names=(), half: bool = False) -> None:
    """Writes float pixels (h, w[, c]) with OpenImageIO; the extension picks the format."""
    _core.write_image(str(path), np.ascontiguousarray(pixels, dtype=np.float32), list(channel_names), half)


def read_image(path) -> tuple[np.ndarray, list[str]]:
    """Reads an image as float32 (h, w, c) and its channel names."""
    return _core.read_image(str(path))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


class OutputFolder:
    """Writes files into a folder without clobbering what ssrlab did not write."""

    def __init__(self, folder, *, overwrite: bool = False):
        self.folder = Path(folder)
        self.overwrite = overwrite
        self._manifest_path = self.folder / MANIFEST
        self._manifest: dict[str, str] = {}
        if self._manifest_path.is_file():
            try:
                self._manifest = json.loads(self._manifest_path.read_text()).get("files", {})
            except (OSError, ValueError):
                self._manifest = {}

    def check(self, names: list[str]) -> None:
        """Raises FileExistsError, before anything is written, if a target may not be replaced."""
        if self.folder.exists() and not self.folder.is_dir():
            raise NotADirectoryError(f"output path {self.folder} exists and is not a folder")
        if self.overwrite:
            return
        for name in names:
            path = self.folder / name
            if path.exists() and self._manifest.get(name) != _sha256(path):
                why = "was changed since ssrlab wrote it" if name in self._manifest else "was not written by ssrlab"
                raise FileExistsError(f"{path} exists and {why}; pass overwrite=True (--overwrite) to replace it")

    def write(self, name: str, writer: Callable[[Path], None]) -> Path:
        """Calls writer(temp_path) then moves the result into place atomically (atomic_write); the
        manifest is replaced the same way."""
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise output_error(exc, self.folder) from exc
        target = self.folder / name
        atomic_write(target, writer)
        self._manifest[name] = _sha256(target)
        text = json.dumps({"files": self._manifest}, indent=1, sort_keys=True)
        atomic_write(self._manifest_path, lambda p: p.write_text(text))
        return target


GBUFFER_CHANNELS = [
    "depth", "window_depth", "N.X", "N.Y", "N.Z", "albedo.R", "albedo.G", "albedo.B", "roughness", "metallic",
    "reflectivity", "coverage", "lit.R", "lit.G", "lit.B",
]


def gbuffer_layer_image(frame, layer: int) -> np.ndarray:
    """The channels of GBUFFER_CHANNELS for one layer, as (h, w, 15) float32."""
    g = frame.gbuffer
    parts = [g.depth[layer][..., None], g.window_depth[layer][..., None], g.normal[layer], g.albedo[layer],
             g.roughness[layer][..., None], g.metallic[layer][..., None], g.reflectivity[layer][..., None],
             g.coverage[layer][..., None].astype(np.float32), g.lit[layer]]
    return np.concatenate(parts, axis=-1).astype(np.float32)


def write_frame(frame, folder, *, overwrite: bool = False, exposure: float = 1.0, extra: dict | None = None,
                progress=None) -> list[Path]:
    """Writes a frame's outputs into `folder`:

    color.png             the final image, sRGB 8-bit (exposure * linear, clamped)
    color.exr             the final image, linear float
    gbuffer_layer<i>.exr  every G-buffer layer, channels GBUFFER_CHANNELS
    timings.json          GPU milliseconds per pass, wall time, settings, camera, `extra`
    """
    out = OutputFolder(folder, overwrite=overwrite)
    layers = frame.settings.layers
    names = ["color.png", "color.exr", *[f"gbuffer_layer{i}.exr" for i in range(layers)], "timings.json"]
    out.check(names)
    written = []
    color = frame.color
    written.append(out.write("color.png", lambda p: write_image(p, linear_to_srgb(color, exposure))))
    written.append(out.write("color.exr", lambda p: write_image(p, color, ["R", "G", "B"])))
    if progress:
        progress.update(1)
    for i in range(layers):
        img = gbuffer_layer_image(frame, i)
        written.append(out.write(f"gbuffer_layer{i}.exr", lambda p, img=img: write_image(p, img, GBUFFER_CHANNELS)))
    if progress:
        progress.update(1)
    cam = frame.camera
    record = {
        "timings_ms": frame.timings,
        "wall_ms": frame.wall_ms,
        "passes": frame.passes,
        "settings": frame.settings.to_dict(),
        "camera": {"position": list(cam.position), "target": list(cam.target), "up": list(cam.up),
                   "fov_y": cam.fov_y, "near": cam.near, "far": cam.far},
        **(extra or {}),
    }
    written.append(out.write("timings.json", lambda p: p.write_text(json.dumps(record, indent=2, sort_keys=True))))
    return written
