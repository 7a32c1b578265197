"""Rich display in Jupyter: every ssrlab object a notebook shows has a picture or a table."""

import importlib.util
import struct
import zlib

import numpy as np
import pytest

import ssrlab
from conftest import small

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(data: bytes) -> tuple[int, int]:
    """(width, height) of a PNG, checking its signature and every chunk's CRC (independently of
    the encoder under test)."""
    assert data[:8] == PNG_SIGNATURE, "not a PNG"
    pos, size, chunks = 8, None, []
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert zlib.crc32(kind + body) & 0xFFFFFFFF == crc, f"bad CRC in chunk {kind}"
        if kind == b"IHDR":
            size = struct.unpack(">II", body[:8])
        chunks.append(kind)
        pos += 12 + length
    assert chunks[0] == b"IHDR" and chunks[-1] == b"IEND" and b"IDAT" in chunks
    return size


def decode(data: bytes) -> np.ndarray:
    from matplotlib.image import imread
    import io

    return imread(io.BytesIO(data), format="png")


@pytest.fixture(scope="module")
def frame(renderer):
    return renderer.render(ssrlab.scenes.box_stack(), settings=small(width=64, height=48, layers=2,
                                                                      rays_per_pixel=2))


def test_frame_png_is_the_final_image(frame):
    data = frame._repr_png_()
    w, h = png_size(data)
    assert w % 64 == 0 and h % 48 == 0 and w // 64 == h // 48 >= 1, "an integer enlargement of the frame"
    img = decode(data)[..., :3]
    k = w // 64
    expected = ssrlab.display.srgb(frame.color)
    # Same pixels as the sRGB-encoded final image (8-bit rounding apart).
    assert np.abs(img[::k, ::k] - expected).max() <= 1.0 / 255 + 1e-6


def test_frame_html_has_the_image_and_every_pass_time(frame):
    html = frame._repr_html_()
    assert "data:image/png;base64," in html
    for name in frame.passes:
        assert name in html
    assert f"{frame.timings['total']:.4g}" in html


def test_frame_repr_names_size_layers_passes_and_time(frame):
    text = repr(frame)
    assert "64x48" in text and "2 layer(s)" in text and "trace_linear" in text and "ms" in text
    assert "at 0x" not in text


def test_gbuffer_grid_has_a_row_per_layer(frame):
    w, h = png_size(frame.gbuffer._repr_png_())
    assert w > h > 0
    one = ssrlab.display.grid([[np.zeros((48, 64, 3))] * 3])
    two = decode(frame.gbuffer._repr_png_())
    assert two.shape[0] == 2 * one.shape[0] + ssrlab.display.GAP and two.shape[1] == one.shape[1]
    html = frame.gbuffer._repr_html_()
    assert html.count("data:image/png") == 3 * 2 and "layer 1: depth" in html


def test_rays_display(frame):
    png_size(frame.rays._repr_png_())
    html = frame.rays._repr_html_()
    assert "hit share" in html and html.count("data:image/png") == 3
    assert "2 ray(s) per pixel" in repr(frame.rays)


def test_reference_displays(frame):
    conv = frame.reference("converged", rays=4)
    w, h = png_size(conv._repr_png_())
    assert w > 2 * h, "truth, frame and error side by side"
    html = conv._repr_html_()
    # truth, frame, error and, with flip-evaluator installed, the FLIP error map
    flip = importlib.util.find_spec("flip_evaluator") is not None
    assert "PSNR" in html and html.count("data:image/png") == 3 + flip
    assert ("LDR-FLIP error map" in html) == flip
    per_ray = frame.reference("per_ray")
    html = per_ray._repr_html_()
    assert "rays traced" in html and "coverage" in html
    assert "PerRayReference" in repr(per_ray)


def test_reference_image_repr(renderer, tmp_path):
    ref = ssrlab.reference.reference_image(renderer, ssrlab.scenes.mirror_test(), settings=small(width=32, height=24),
                                           rays=2, folder=tmp_path)
    assert png_size(ref._repr_png_())[0] >= 32
    assert repr(ref).startswith("<ReferenceImage converged 32x24")


def test_settings_html_lists_only_the_changed_fields():
    s = ssrlab.Settings(layers=4, method="hiz")
    html = s._repr_html_()
    assert "layers" in html and "hiz" in html and "2 field(s) differ" in html
    assert "thickness_scale" not in html
    assert "every field at its default" in ssrlab.Settings()._repr_html_()
    assert repr(s) == "Settings(layers=4, method='hiz')" and eval(repr(s), {"Settings": ssrlab.Settings}) == s


def test_a_notebook_cell_ending_in_a_frame_displays_an_image(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    monkeypatch.setenv("SSRLAB_CACHE", str(tmp_path / "cache"))
    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_code_cell("import ssrlab\nrenderer = ssrlab.Renderer()\n"
                                  "frame = renderer.render(ssrlab.scenes.mirror_test(), width=64, height=48,\n"
                                  "                        shadow_map_size=256)\nframe"),
        nbformat.v4.new_code_cell("frame.gbuffer"),
        nbformat.v4.new_code_cell("frame.settings"),
    ]
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    results = [[o for o in c.outputs if o.output_type == "execute_result"] for c in nb.cells]
    assert all(len(r) == 1 for r in results), [c.outputs for c in nb.cells]
    shown = results[0][0]["data"]
    assert "image/png" in shown and "text/html" in shown, sorted(shown)
    import base64

    assert png_size(base64.b64decode(shown["image/png"])) == (192, 144)
    assert "64x48" in shown["text/plain"]
    assert "image/png" in results[1][0]["data"]
    assert "differ from the defaults" in results[2][0]["data"]["text/html"]
