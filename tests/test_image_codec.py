"""Image files without OpenImageIO (ssrlab.image_codec): what Pillow and OpenEXR write reads back
as OpenImageIO reads it, and the other way round, so that an extension built without
OpenImageIO (the wheel) writes the same PNG and EXR files."""

import numpy as np
import pytest

from ssrlab import _core, image_codec

pytest.importorskip("PIL")
OpenEXR = pytest.importorskip("OpenEXR")
OIIO = _core.image_io_backend() == "OpenImageIO"
RNG = np.random.default_rng(7)


def test_the_extension_names_its_backend_and_a_python_build_uses_the_codec():
    assert _core.image_io_backend() in ("OpenImageIO", "python")
    assert image_codec.register() == (not OIIO)


@pytest.mark.parametrize("half", [False, True])
def test_exr_round_trips_and_matches_openimageio(tmp_path, half):
    pixels = RNG.uniform(-2, 40, (9, 13, 4)).astype(np.float32)
    names = ["R", "G", "B", "depth"]
    image_codec.write(tmp_path / "py.exr", pixels, names, half)
    back, back_names = image_codec.read(tmp_path / "py.exr")
    expect = pixels.astype(np.float16).astype(np.float32) if half else pixels
    assert back_names == names and np.array_equal(back, expect)
    assert image_codec.probe(tmp_path / "py.exr") == (13, 9, 4)
    if OIIO:
        theirs, their_names = _core.read_image(str(tmp_path / "py.exr"))
        assert their_names == names and np.array_equal(theirs, expect)
        _core.write_image(str(tmp_path / "oiio.exr"), pixels, names, half)
        ours, our_names = image_codec.read(tmp_path / "oiio.exr")
        assert our_names == names and np.array_equal(ours, expect)


@pytest.mark.parametrize("channels", [1, 3, 4])
def test_png_quantises_as_openimageio_does(tmp_path, channels):
    pixels = RNG.uniform(-0.2, 1.2, (7, 5, channels)).astype(np.float32)
    pixels[0, 0] = 0.5 / 255  # exactly between two levels: rounding matters
    image_codec.write(tmp_path / "py.png", pixels)
    ours, names = image_codec.read(tmp_path / "py.png")
    assert ours.shape == (7, 5, channels)
    assert np.abs(ours - np.clip(pixels, 0, 1)).max() <= 0.5 / 255 + 1e-6
    # OpenImageIO takes float RGBA as associated alpha and divides colour by alpha into the PNG
    # (whose alpha is unassociated); the codec writes the values as given. Opaque images agree.
    if OIIO and channels != 4:
        _core.write_image(str(tmp_path / "oiio.png"), pixels)
        theirs, their_names = _core.read_image(str(tmp_path / "oiio.png"))
        assert np.array_equal(image_codec.read(tmp_path / "oiio.png")[0], theirs)
        assert np.array_equal(ours, theirs), "the same 8-bit values as OpenImageIO writes"
        if channels != 1:
            assert names == their_names


def test_decode_and_encode_png_round_trip():
    rgba = RNG.integers(0, 256, (6, 4, 4), dtype=np.uint8)
    data = image_codec.encode_png(rgba)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert np.array_equal(image_codec.decode(data, "image/png"), rgba)


def test_bad_files_and_missing_packages_are_named(tmp_path, monkeypatch):
    with pytest.raises(ValueError, match=r"out\.tif.*PNG, JPEG and EXR"):
        image_codec.write(tmp_path / "out.tif", np.zeros((2, 2, 3), np.float32))
    with pytest.raises(FileNotFoundError):  # an OSError, which the extension makes an OutputError
        image_codec.write(tmp_path / "no" / "folder" / "out.exr", np.zeros((2, 2, 3), np.float32))
    with pytest.raises(OSError):
        image_codec.write(tmp_path / "no" / "folder" / "out.png", np.zeros((2, 2, 3), np.float32))
    with pytest.raises(ValueError, match="distinct channel names"):
        image_codec.write(tmp_path / "out.exr", np.zeros((2, 2, 2), np.float32), ["R", "R"])
    import builtins

    real = builtins.__import__

    def no_openexr(name, *a, **k):
        if name == "OpenEXR":
            raise ImportError("No module named 'OpenEXR'")
        return real(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", no_openexr)
    with pytest.raises(ImportError, match=r"ssrlab\[images\]"):
        image_codec.write(tmp_path / "out.exr", np.zeros((2, 2, 3), np.float32))
