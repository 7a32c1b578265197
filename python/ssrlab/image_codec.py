"""Image files without OpenImageIO: PNG and JPEG through Pillow, EXR through the OpenEXR package.

An ssrlab extension built without OpenImageIO (a wheel for machines that have only their GL
drivers: CMake option SSRLAB_WITH_OIIO=OFF) hands every image file it reads or writes to
``codec`` (cpp/scene/image_io_python.cpp): glTF textures, environment maps, the PNG and EXR
files of ``ssrlab.io``. Importing ssrlab registers it when ``_core.image_io_backend()`` is
"python"; an OpenImageIO build never calls it.

    pip install 'ssrlab[images]'     # OpenEXR and Pillow (Pillow also comes with matplotlib)

8-bit files (PNG, JPEG) are written as OpenImageIO writes them: values clamped to [0, 1] and
rounded to the nearest of 256 levels (halves up); read back as value / 255. RGBA values are
written as given (PNG's alpha is unassociated), where OpenImageIO takes float RGBA as
associated alpha and divides the colour by it: ssrlab's own images are RGB. EXR keeps
float32, or half with half=True; its channels are read in OpenImageIO's order (R, G, B, A
first, then the others by name).
"""

from __future__ import annotations

import errno
import io as _stdio
import os
from pathlib import Path

import numpy as np

EXTRA_HINT = "pip install 'ssrlab[images]'"
EIGHT_BIT = (".png", ".jpg", ".jpeg")
_MODES = {1: "L", 2: "LA", 3: "RGB", 4: "RGBA"}
_COLOUR_ORDER = ("R", "G", "B", "A")


def _pil():
    try:
        from PIL import Image
    except ImportError:
        raise ImportError(f"PNG and JPEG files need Pillow in an ssrlab built without OpenImageIO: "
                          f"{EXTRA_HINT}") from None
    return Image


def _openexr():
    try:
        import OpenEXR
    except ImportError:
        raise ImportError(f"EXR files need the OpenEXR package in an ssrlab built without OpenImageIO: "
                          f"{EXTRA_HINT}") from None
    return OpenEXR


def _suffix(path) -> str:
    return Path(str(path)).suffix.lower()


def decode(source, hint: str = "") -> np.ndarray:
    """A file (path) or encoded bytes as (h, w, 4) uint8 RGBA."""
    Image = _pil()
    f = _stdio.BytesIO(source) if isinstance(source, (bytes, bytearray)) else str(source)
    with Image.open(f) as im:
        im.load()
        return np.ascontiguousarray(np.asarray(im.convert("RGBA"), dtype=np.uint8))


def encode_png(rgba: np.ndarray) -> bytes:
    buf = _stdio.BytesIO()
    _pil().fromarray(np.ascontiguousarray(rgba, dtype=np.uint8), "RGBA").save(buf, format="PNG")
    return buf.getvalue()


def _exr_order(names) -> list[str]:
    colour = [n for n in _COLOUR_ORDER if n in names]
    return colour + sorted(n for n in names if n not in colour)


def read(path) -> tuple[np.ndarray, list[str]]:
    """(h, w, c) float32 pixels and channel names."""
    if _suffix(path) == ".exr":
        OpenEXR = _openexr()
        with OpenEXR.File(str(path), separate_channels=True) as f:
            channels = f.channels()
            names = _exr_order(list(channels))
            planes = [np.asarray(channels[n].pixels, dtype=np.float32) for n in names]
        return np.ascontiguousarray(np.stack(planes, axis=-1)), names
    Image = _pil()
    with Image.open(str(path)) as im:
        im.load()
        if im.mode in ("I;16", "I;16B", "I;16L", "I"):
            a = np.asarray(im, dtype=np.float32) * np.float32(1.0 / 65535.0)
            return a[..., None], ["Y"]
        if im.mode == "F":
            return np.asarray(im, dtype=np.float32)[..., None], ["Y"]
        target = {"1": "L", "P": "RGBA" if "transparency" in im.info else "RGB"}.get(im.mode, im.mode)
        if target not in ("L", "LA", "RGB", "RGBA"):
            target = "RGB"
        a = np.asarray(im.convert(target), dtype=np.float32) * np.float32(1.0 / 255.0)  # as OpenImageIO scales
    a = a[..., None] if a.ndim == 2 else a
    names = {"L": ["Y"], "LA": ["Y", "A"], "RGB": ["R", "G", "B"], "RGBA": ["R", "G", "B", "A"]}[target]
    return np.ascontiguousarray(a), names


def probe(path) -> tuple[int, int, int]:
    """(width, height, channels) from the file's header."""
    if _suffix(path) == ".exr":
        OpenEXR = _openexr()
        with OpenEXR.File(str(path), header_only=True) as f:
            lo, hi = f.header()["dataWindow"]
            channels = f.header().get("channels", [])
        return int(hi[0] - lo[0] + 1), int(hi[1] - lo[1] + 1), max(1, len(channels))
    PIL = _pil()
    try:
        im = PIL.open(str(path))
    except PIL.UnidentifiedImageError:
        raise ValueError(f"{path}: not an image file Pillow can read (PNG, JPEG, ...; EXR by extension)") from None
    with im:
        return im.size[0], im.size[1], len(im.getbands())


def write(path, pixels: np.ndarray, names=(), half: bool = False) -> None:
    """Writes (h, w, c) float pixels; the extension picks the format (see the module documentation)."""
    a = np.asarray(pixels, dtype=np.float32)
    a = a[..., None] if a.ndim == 2 else a
    c = a.shape[2]
    suffix = _suffix(path)
    if suffix in EIGHT_BIT:
        if c not in _MODES or (suffix != ".png" and c in (2, 4)):
            raise ValueError(f"{path}: {c} channel(s) cannot be written as {suffix[1:].upper()}")
        # OpenImageIO's float -> uint8: round half up, in float32
        q = np.floor(np.clip(np.nan_to_num(a), 0.0, 1.0) * np.float32(255.0) + np.float32(0.5)).astype(np.uint8)
        img = _pil().fromarray(q[..., 0] if c == 1 else q, _MODES[c])
        if suffix == ".png":
            img.save(str(path), format="PNG")
        else:
            img.save(str(path), format="JPEG", quality=95)
        return
    if suffix == ".exr":
        OpenEXR = _openexr()
        names = list(names) or (list(_COLOUR_ORDER[:c]) if c in (3, 4) else
                                ["Y"] if c == 1 else [f"channel{i}" for i in range(c)])
        if len(names) != c or len(set(names)) != c:
            raise ValueError(f"{path}: {len(names)} distinct channel names needed for {c} channels, got {names}")
        dtype = np.float16 if half else np.float32
        channels = {n: np.ascontiguousarray(a[..., i].astype(dtype)) for i, n in enumerate(names)}
        header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
        parent = Path(str(path)).parent
        if not parent.is_dir():  # OpenEXR reports this as a RuntimeError without the cause
            raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), str(parent))
        with OpenEXR.File(header, channels) as f:
            try:
                f.write(str(path))
            except RuntimeError as e:  # OpenEXR's failures (a full disk...) as the OSError they are
                # OpenEXR's message keeps the system's text only: its errno where the text names one
                code = next((n for n, text in ((errno.ENOSPC, "No space left on device"),
                                               (errno.EFBIG, "File too large"),
                                               (errno.EDQUOT, "Disk quota exceeded"),
                                               (errno.EACCES, "Permission denied")) if text in str(e)), errno.EIO)
                raise OSError(code, f"OpenEXR could not write the file: {e}", str(path)) from e
        return
    raise ValueError(f"{path}: without OpenImageIO ssrlab writes PNG, JPEG and EXR files, not {suffix or 'this'}")


def codec(op: str, *args):
    """The single entry point the extension calls (cpp/scene/image_io_python.cpp)."""
    if op == "decode":
        return decode(*args)
    if op == "encode_png":
        return encode_png(*args)
    if op == "read":
        return read(*args)
    if op == "probe":
        return probe(*args)
    if op == "write":
        return write(*args)
    raise ValueError(f"image codec: unknown operation {op!r}")


def register() -> bool:
    """Hands image files to this module where the extension has no OpenImageIO; True if it did."""
    from . import _core

    backend = getattr(_core, "image_io_backend", None)
    if backend is None or backend() != "python":
        return False
    _core._set_image_codec(codec)
    return True


__all__ = ["codec", "decode", "encode_png", "read", "probe", "write", "register"]
