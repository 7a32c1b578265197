"""The live viewer in a real headless browser (Debian's Chromium through Playwright): what the page
shows is what Renderer.render gives for the camera and settings the server reports, pixel for pixel
(frames sent as PNG), and the page survives what a user does to it."""

from __future__ import annotations

import contextlib
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import ssrlab
from ssrlab import display
from ssrlab.viewer import FRAMES, views

from viewer_page import browser, drag, open_page, require_browser, wait_settled, wait_shown

REPO = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.usefixtures("_browser_available")


@pytest.fixture(scope="module")
def _browser_available():
    require_browser()


@pytest.fixture(scope="module")
def chromium():
    with browser() as b:
        yield b


@pytest.fixture(scope="module")
def renderer():
    return ssrlab.Renderer("cpu")


def expected_pixels(renderer, shown, scene):
    """The page's image of a colour view, from a render of its camera and settings."""
    frame = renderer.render(scene, shown.camera, shown.settings)
    return views.to_bytes(display.srgb(frame.color)), frame


def rests(shown):
    return shown.scale >= 1.0


def hall_hiz(renderer, **kw):
    """The viewer most tests open: hall, Hi-Z, frames sent as PNG, no averaging of seeds."""
    return ssrlab.view("hall", ssrlab.Settings(method="hiz"), renderer, lossless=True, accumulate=1, **kw)


@contextlib.contextmanager
def resting_page(chromium, viewer):
    """A page on `viewer` once it shows its first full-resolution frame; the viewer closes after."""
    try:
        page = open_page(chromium, viewer.url)
        shown, pixels = wait_shown(page, viewer, condition=rests)
        yield page, shown
    finally:
        viewer.close()


def wait_rounds(viewer, figures: str, timeout: float = 240.0) -> None:
    """Waits until the viewer's `figures` (metrics, metrics_b) come from its last reference round."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        m = getattr(viewer, figures)
        if m and m["rays"] >= viewer.reference_rays[-1]:
            return
        time.sleep(0.1)
    raise AssertionError(f"the viewer's {figures} did not reach its last reference round in {timeout} s")


@pytest.fixture
def hall_view(renderer):
    v = hall_hiz(renderer)
    yield v
    v.close()


@pytest.mark.parametrize("frames", FRAMES)
def test_first_frame_is_the_render_of_the_reported_camera_and_a_drag_moves_it(chromium, renderer, frames):
    hall_view = hall_hiz(renderer, frames=frames)
    try:
        page = _first_frame_and_a_drag(chromium, hall_view, renderer)
        if frames == "overlay":
            _the_panel_stays_docked(page, hall_view)
    finally:
        hall_view.close()


def _the_panel_stays_docked(page, viewer):
    """With frames="overlay" the frame is an element of the docked panel: the page offers no way to
    collapse or float the panel, so nothing the user does there takes the frame away."""
    assert page.locator("[data-dock-region-collapse]").count() == 0 or \
        not page.locator("[data-dock-region-collapse]").first.is_visible()
    for handle in ("[data-dock-header]", "[data-dock-region-handle]"):
        box = page.locator(handle).first.bounding_box()
        page.mouse.move(box["x"] + 60, box["y"] + 5)
        page.mouse.down()
        page.mouse.move(box["x"] - 200, box["y"] + 120, steps=8)
        page.mouse.up()
    assert page.locator("[data-dock-region=right]").count() == 1
    wait_shown(page, viewer, timeout=20)  # the page still shows the frame the viewer sent last


def _first_frame_and_a_drag(chromium, hall_view, renderer):
    page = open_page(chromium, hall_view.url)
    start = time.time()
    shown, pixels = wait_shown(page, hall_view, condition=lambda s: rests(s) and s.camera.fov_y == 60.0)
    assert time.time() - start < 60
    assert (shown.settings.width, shown.settings.height) == (320, 180)  # the page's canvas
    assert np.allclose(shown.camera.position, hall_view.scene.camera.position, atol=1e-4)
    expected, _ = expected_pixels(renderer, shown, hall_view.scene)
    assert np.array_equal(pixels, expected)

    drag(page, 40, 10)
    moved, pixels2 = wait_shown(page, hall_view, condition=lambda s: rests(s) and s.serial > shown.serial
                                and not np.allclose(s.camera.position, shown.camera.position))
    assert not np.array_equal(pixels2, pixels)
    expected2, _ = expected_pixels(renderer, moved, hall_view.scene)
    assert np.array_equal(pixels2, expected2)
    assert hall_view.camera.position == moved.camera.position  # the handle reports the page's camera
    return page


def test_settings_from_the_page_and_a_refused_value_keeps_the_frame(chromium, hall_view, renderer):
    page = open_page(chromium, hall_view.url)
    first, _ = wait_shown(page, hall_view, condition=rests)
    page.get_by_text("settings: deep G-buffer").click()
    layers = page.get_by_label("layers", exact=True)
    layers.fill("2")
    layers.press("Enter")
    two, pixels = wait_shown(page, hall_view, condition=lambda s: rests(s) and s.settings.layers == 2)
    assert hall_view.settings.layers == 2
    expected, _ = expected_pixels(renderer, two, hall_view.scene)
    assert np.array_equal(pixels, expected)

    layers.fill("0")
    layers.press("Enter")
    deadline = time.time() + 20
    while "Settings.layers" not in hall_view.error and time.time() < deadline:
        time.sleep(0.05)
    assert "Settings.layers must be in [1," in hall_view.error
    message = page.locator("p", has_text="refused:").first
    message.wait_for(timeout=20000)
    assert "Settings.layers must be in [1," in message.inner_text()
    time.sleep(0.5)
    same, pixels_after = wait_shown(page, hall_view)
    assert same.serial == two.serial and np.array_equal(pixels_after, pixels)  # the last good frame stays
    assert hall_view.settings.layers == 2


def test_settings_set_from_python_change_every_page(chromium, hall_view, renderer):
    a, b = open_page(chromium, hall_view.url), open_page(chromium, hall_view.url)
    wait_shown(a, hall_view, condition=rests)
    deadline = time.time() + 60
    while len(hall_view.shown) < 2 and time.time() < deadline:
        time.sleep(0.05)
    assert len(hall_view.shown) == 2, "both pages get frames"
    hall_view.settings = hall_view.settings.replace(method="linear")
    with pytest.raises(ValueError, match="Settings.max_steps"):
        hall_view.settings = hall_view.settings.replace(max_steps=-3)
    for cid in list(hall_view.shown):
        page = a if cid == min(hall_view.shown) else b
        shown, pixels = wait_shown(page, hall_view, cid,
                                   condition=lambda s: rests(s) and s.settings.method == "linear")
        expected, _ = expected_pixels(renderer, shown, hall_view.scene)
        assert np.array_equal(pixels, expected)


def test_closing_a_page_mid_render_leaves_the_server_serving(chromium, hall_view):
    page = open_page(chromium, hall_view.url)
    wait_shown(page, hall_view, condition=rests)
    drag(page, 30, 0)
    page.close()  # while the dragged camera's frame renders
    time.sleep(1.0)
    again = open_page(chromium, hall_view.url)
    shown, _ = wait_shown(again, hall_view, condition=rests)
    assert hall_view._worker.is_alive() and hall_view.error == ""


def test_every_view_of_the_frame_and_the_inspector(chromium, renderer):
    v = ssrlab.view("box_stack", ssrlab.Settings(layers=2, rays_per_pixel=2, method="linear"), renderer,
                    lossless=True, accumulate=1)
    try:
        page = open_page(chromium, v.url)
        shown, _ = wait_shown(page, v, condition=rests)
        frame = shown.frame
        names = views.names(frame)
        for want in ("gbuffer.depth", "gbuffer.normal", "gbuffer.albedo", "gbuffer.roughness", "gbuffer.metallic",
                     "gbuffer.coverage", "gbuffer.lit", "rays.hit_layer", "rays.hits", "rays.steps", "rays.source"):
            assert want in names
        for name in names:
            if name == "error":
                continue
            rgb, caption = views.render(frame, name, layer=1, ray=1)
            assert rgb.shape == (frame.settings.height, frame.settings.width, 3) and np.isfinite(rgb).all(), name
            assert caption
        # the steps view from the page: its pixels are the heat map of the ray's depth fetches
        page.get_by_label("view", exact=True).click()
        page.get_by_role("option", name="rays.steps", exact=True).click()
        steps, pixels = wait_shown(page, v, condition=lambda s: s.view == "rays.steps" and rests(s))
        rgb, _ = views.render(steps.frame, "rays.steps")
        assert np.array_equal(pixels, views.to_bytes(rgb))
        # the inspector: a click reads every layer of that pixel
        page.mouse.click(100, 120)
        deadline = time.time() + 20
        while getattr(v, "inspected", None) is None and time.time() < deadline:
            time.sleep(0.05)
        values = v.inspected
        row, col = values["pixel"]
        assert (row, col) == (120 * steps.settings.height // 180, 100 * steps.settings.width // 320)
        g = steps.frame.gbuffer
        for k in range(2):
            assert values["layers"][k]["depth"] == pytest.approx(float(g.depth[k, row, col]))
            assert values["layers"][k]["object_id"] == int(g.object_id[k, row, col])
        assert len(values["rays"]) == 2
        page.get_by_text("pixel inspector", exact=True).click()
        page.get_by_text(f"row {row}, column {col}").wait_for(timeout=20000)
    finally:
        v.close()


def test_error_figures_are_image_metrics_of_the_frame_and_reference(chromium, renderer):
    v = hall_hiz(renderer, reference_rays=(2, 8))
    with resting_page(chromium, v) as (page, shown):
        page.get_by_label("reference", exact=True).check()

        wait_rounds(v, "metrics")
        got = dict(v.metrics)
        ref = shown.frame.reference("converged", rays=got["rays"])
        want = ssrlab.metrics.image_metrics(shown.frame.color, ref.color, ref.reflective)
        for k in ("thesis_error", "psnr", "rmse", "psnr_reflective"):
            assert got[k] == pytest.approx(want[k], rel=1e-6), k
        page.get_by_text("numbers", exact=True).click()
        text = page.get_by_text("error against the converged reference", exact=False).first
        text.wait_for(timeout=20000)
        deadline = time.time() + 20
        while time.time() < deadline:  # the page's table follows the server's within its update
            cells = page.locator("table", has_text="thesis_error").first.inner_text().split()
            shown = {k: float(cells[i + 1]) for i, k in enumerate(cells[:-1]) if k in want}
            if shown.get("psnr") == pytest.approx(want["psnr"], rel=1e-6):
                break
            time.sleep(0.1)
        for k in ("thesis_error", "psnr", "rmse", "psnr_reflective"):
            assert shown[k] == pytest.approx(want[k], rel=1e-6), k


def test_copy_as_python_renders_the_same_pixels_in_a_fresh_process(chromium, hall_view, tmp_path):
    page = open_page(chromium, hall_view.url)
    wait_shown(page, hall_view, condition=rests)
    drag(page, -30, 5)
    page.get_by_text("keep", exact=True).click()
    shown, pixels = wait_settled(page, hall_view, condition=lambda s: rests(s) and
                                 not np.allclose(s.camera.position, hall_view.scene.camera.position))
    page.get_by_role("button", name="copy as Python").click()
    deadline = time.time() + 20
    while not hall_view._snapshot and time.time() < deadline:
        time.sleep(0.05)
    script = hall_view._snapshot
    assert max(s.serial for s in hall_view.shown.values()) == shown.serial  # the snippet is of the frame compared
    assert "ssrlab.Camera(" in script and "renderer.render(scene, camera, settings)" in script
    out = tmp_path / "color.npy"
    program = script + f"\nimport numpy\nnumpy.save({str(out)!r}, frame.color)\n"
    subprocess.run([sys.executable, "-c", program], check=True, cwd=tmp_path, env={**__import__("os").environ,
                                                                                   "SSRLAB_DEVICE": "cpu"})
    assert np.array_equal(views.to_bytes(display.srgb(np.load(out))), pixels)


def test_a_user_pass_shader_edited_on_disk_changes_the_next_frame_and_an_error_keeps_it(chromium, tmp_path):
    folder = tmp_path / "technique"
    shutil.copytree(REPO / "examples" / "bilateral_filter", folder)
    shader = folder / "filter.comp"
    p = ssrlab.UserPass("tinted", shader, stage="reflection_filter",
                        reads=("reflection", "linear_depth", "gbuffer.normal"),
                        params=(ssrlab.Param("radius", "int", 3, 0, 8), ssrlab.Param("sigma_depth", "float", 0.02),
                                ssrlab.Param("normal_power", "float", 32.0), ssrlab.Param("min_roughness", "float", 0.05)))
    r = ssrlab.Renderer("cpu")
    r.register_pass(p)
    v = ssrlab.view("hall", ssrlab.Settings(user_passes=("tinted",)), r, lossless=True, accumulate=1)
    try:
        page = open_page(chromium, v.url)
        before, pixels = wait_shown(page, v, condition=rests)
        text = shader.read_text()
        marker = "vec4 centre = texelFetch(u_reflection, p, 0);"
        assert marker in text
        time.sleep(0.05)  # a new modification time
        shader.write_text(text.replace(marker, marker + " centre.rgb = vec3(1.0, 0.0, 1.0);"))
        after, pixels2 = wait_shown(page, v, timeout=120,
                                    condition=lambda s: rests(s) and s.serial > before.serial and "reloaded" in
                                    v._message.content)
        assert not np.array_equal(pixels, pixels2)
        assert v.renderer is not r  # a fresh shader library read the edited file
        expected, _ = expected_pixels(v.renderer, after, v.scene)
        assert np.array_equal(pixels2, expected)

        lines = shader.read_text().splitlines()
        lines.insert(29, "    this is not GLSL;")
        shader.write_text("\n".join(lines) + "\n")
        deadline = time.time() + 120
        while "ShaderError" not in v.error and time.time() < deadline:
            time.sleep(0.1)
        assert "ShaderError" in v.error and "filter.comp:30" in v.error, v.error
        page.get_by_text("filter.comp:30", exact=False).first.wait_for(timeout=20000)
        same, pixels3 = wait_shown(page, v)
        assert same.serial == after.serial and np.array_equal(pixels3, pixels2)  # the last good frame stays
    finally:
        v.close()


def test_camera_path_recorded_and_loaded(chromium, hall_view, tmp_path):
    hall_view.out = tmp_path
    page = open_page(chromium, hall_view.url)
    wait_shown(page, hall_view, condition=rests)
    page.get_by_text("keep", exact=True).click()
    page.get_by_label("record camera path", exact=True).check()
    drag(page, 20, 0)
    wait_shown(page, hall_view, condition=lambda s: rests(s) and
               not np.allclose(s.camera.position, hall_view.scene.camera.position))
    page.get_by_label("record camera path", exact=True).uncheck()
    deadline = time.time() + 20
    while not list(tmp_path.glob("camera_path_*.json")) and time.time() < deadline:
        time.sleep(0.05)
    path = ssrlab.CameraPath.load(next(tmp_path.glob("camera_path_*.json")))
    assert len(path) >= 2
    frames = list(hall_view.renderer.render_sequence(hall_view.scene, path[:2], ssrlab.Settings(width=32, height=18)))
    assert len(frames) == 2


def test_viewer_refuses_bad_arguments():
    with pytest.raises(ValueError, match="accumulate"):
        ssrlab.view("hall", accumulate=0)
    with pytest.raises(TypeError, match="settings"):
        ssrlab.view("hall", settings={"layers": 2})
    with pytest.raises(ValueError, match="unknown scene"):
        ssrlab.view("no_such_scene")
    with pytest.raises(ValueError, match="frames must be one of background, overlay"):
        ssrlab.view("hall", frames="texture")
    for bad in (0, -2.0, float("nan"), "fast", True):
        with pytest.raises(ValueError, match="moving_fps must be None"):
            ssrlab.view("hall", moving_fps=bad)


def test_a_moving_camera_is_paced_at_moving_fps(chromium, renderer):
    viewer = hall_hiz(renderer, moving_fps=4.0)
    try:
        assert viewer.moving_fps == 4.0
        page = open_page(chromium, viewer.url)
        wait_shown(page, viewer)
        page.mouse.move(60, 45)
        page.mouse.down()
        end = time.time() + 2.0
        x = 60
        while time.time() < end:  # a camera that moves all along, a pointer event every 30 ms
            x = 60 + (x - 59) % 120
            page.mouse.move(x, 45)
            time.sleep(0.03)
        page.mouse.up()
        time.sleep(0.5)
        starts = [e["times"]["render_start"] for e in viewer.history if e["moving"]]
        assert len(starts) >= 4
        assert min(np.diff(starts)) >= 1.0 / 4.0 - 0.01  # never two moving frames closer than 1 / moving_fps
        assert len(starts) <= 2.0 * 4.0 + 2
    finally:
        viewer.close()


def test_view_command_serves_the_page(chromium, tmp_path):
    proc = subprocess.Popen([sys.executable, "-m", "ssrlab", "view", "hall", "--device", "cpu", "--lossless",
                             "--set", "method=\"linear\"", "--out", str(tmp_path)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        seen = []
        for line in proc.stdout:  # after viser's own banner
            seen.append(line)
            if line.startswith("ssrlab view: "):
                break
        assert line.startswith("ssrlab view: http://127.0.0.1:"), "".join(seen)
        url = line.split()[2]
        page = open_page(chromium, url)
        page.get_by_text("hall", exact=True).wait_for(timeout=60000)  # the status names the scene once a frame shows
    finally:
        proc.terminate()
        proc.wait(timeout=30)


def test_in_a_notebook_the_page_shows_inline_and_the_next_cell_changes_it(chromium, tmp_path):
    import nbformat
    from nbclient import NotebookClient

    cells = [
        "import ssrlab\nh = ssrlab.view('hall', ssrlab.Settings(method='hiz'), lossless=True, accumulate=1, "
        "device='cpu')\nh",
        "h.settings = h.settings.replace(method='linear')",
        "print(h.snippet())",
        "h.close()",
    ]
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    client = NotebookClient(nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}})
    with client.setup_kernel():
        client.execute_cell(nb.cells[0], 0)
        html = [o["data"]["text/html"] for o in nb.cells[0].outputs if "text/html" in o.get("data", {})]
        html = next((h for h in html if "<iframe" in h), "")
        assert "<iframe" in html, nb.cells[0].outputs
        url = html.split('src="')[1].split('"')[0]
        page = open_page(chromium, url)
        # The inline page: its frame shows once the kernel's viewer rendered the page's camera.
        before = page.screenshot()
        deadline = time.time() + 60
        while time.time() < deadline and page.locator("p", has_text="frames/s").count() == 0:
            time.sleep(0.1)
        first = _settled_canvas(page)
        client.execute_cell(nb.cells[1], 1)
        changed = _settled_canvas(page, differs_from=first)
        assert not np.array_equal(changed, first), "setting handle.settings changed what the page shows"
        client.execute_cell(nb.cells[2], 2)
        script = "".join(o.get("text", "") for o in nb.cells[2].outputs)
        assert "'method': 'hiz'" not in script and "ssrlab.Settings(" in script  # linear: the default
        out = tmp_path / "color.npy"
        subprocess.run([sys.executable, "-c", script + f"\nimport numpy\nnumpy.save({str(out)!r}, frame.color)\n"],
                       check=True, cwd=tmp_path)
        assert np.array_equal(views.to_bytes(display.srgb(np.load(out))), changed)
        client.execute_cell(nb.cells[3], 3)
        assert before is not None


def _settled_canvas(page, differs_from=None, timeout: float = 90.0) -> np.ndarray:
    """The canvas once two screenshots 0.5 s apart agree (and differ from `differs_from`)."""
    from viewer_page import canvas_pixels

    end = time.time() + timeout
    last = canvas_pixels(page, (180, 320, 3))
    while time.time() < end:
        time.sleep(0.5)
        now = canvas_pixels(page, (180, 320, 3))
        if np.array_equal(now, last) and (differs_from is None or not np.array_equal(now, differs_from)):
            return now
        last = now
    raise AssertionError("the page's canvas did not settle")


def test_the_readme_screenshot(chromium, renderer, tmp_path):
    """The page as the README shows it; SSRLAB_UPDATE_IMAGES=1 writes it to docs/images/viewer.png."""
    import os

    v = ssrlab.view("hall", ssrlab.Settings(method="hiz", layers=2), renderer, lossless=True, accumulate=1)
    try:
        page = chromium.new_page(viewport={"width": 640 + 324, "height": 360}, device_scale_factor=1)
        page.goto(v.url)
        wait_shown(page, v, condition=lambda s: rests(s) and s.settings.width == 640)
        page.get_by_text("numbers", exact=True).click()
        page.locator("p", has_text="frames/s").first.wait_for(timeout=20000)
        target = REPO / "docs" / "images" / "viewer.png" if os.environ.get("SSRLAB_UPDATE_IMAGES") == "1" \
            else tmp_path / "viewer.png"
        page.screenshot(path=str(target))
        assert target.stat().st_size > 10_000
    finally:
        v.close()


def test_a_against_b_each_with_its_time_and_error_against_one_reference(chromium, renderer):
    v = hall_hiz(renderer, reference_rays=(2, 8))
    with resting_page(chromium, v) as (page, _):
        page.get_by_text("A against B", exact=True).click()
        page.get_by_label("compare", exact=True).check()
        shown, pixels = wait_shown(page, v, condition=lambda s: rests(s) and s.frame_b is not None)
        a = views.to_bytes(display.srgb(shown.frame.color))
        b = views.to_bytes(display.srgb(shown.frame_b.color))
        assert shown.frame_b.settings.method == "linear" and shown.frame.settings.method == "hiz"
        x = 160  # the divider at half the width: A left of it, the line, B right of it
        assert np.array_equal(pixels[:, : x - 1], a[:, : x - 1]) and np.array_equal(pixels[:, x:], b[:, x:])
        page.get_by_label("reference", exact=True).check()
        wait_rounds(v, "metrics_b")
        got_a, got_b = dict(v.metrics), dict(v.metrics_b)
        ref = shown.frame.reference("converged", rays=got_b["rays"])
        for got, frame in ((got_a, shown.frame), (got_b, shown.frame_b)):
            want = ssrlab.metrics.image_metrics(frame.color, ref.color, ref.reflective)
            assert got["psnr"] == pytest.approx(want["psnr"], rel=1e-6)
        page.locator("p", has_text="B (right)").first.wait_for(timeout=20000)


def test_without_viser_the_viewer_says_what_to_install(monkeypatch):
    import builtins

    real = builtins.__import__

    def no_viser(name, *args, **kwargs):
        if name == "viser" or name.startswith("viser."):
            raise ImportError("No module named 'viser'")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_viser)
    with pytest.raises(ImportError, match=r"pip install 'ssrlab\[viewer\]'"):
        ssrlab.view("hall")
