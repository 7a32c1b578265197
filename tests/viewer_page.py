"""A real browser on the live viewer's page: Debian's Chromium, headless, driven by Playwright."""

from __future__ import annotations

import contextlib
import io
import shutil
import time

import numpy as np
import pytest

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
# The panel docks at the right with this width (viser's "medium" control width), so a page this much
# wider than a frame shows the frame 1:1 in its canvas.
PANEL_PX = 324


def require_browser():
    pytest.importorskip("viser")
    pytest.importorskip("playwright.sync_api")
    if not shutil.which("chromium") and not __import__("os").path.exists(CHROMIUM):
        pytest.skip("no Chromium (Debian's package 'chromium'; ./run.sh test installs it)")


@contextlib.contextmanager
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        try:
            yield b
        finally:
            b.close()


def open_page(b, url: str, width: int = 320, height: int = 180):
    """A page whose canvas is width x height CSS pixels at device scale 1."""
    page = b.new_page(viewport={"width": width + PANEL_PX, "height": height}, device_scale_factor=1)
    page.goto(url)
    return page


def canvas_pixels(page, shape) -> np.ndarray:
    """The canvas as the page shows it, (H, W, 3) uint8, cut to `shape`."""
    from PIL import Image

    png = page.screenshot()
    a = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
    return a[: shape[0], : shape[1]]


def wait_shown(page, viewer, cid=None, timeout: float = 60.0, condition=None):
    """Waits until the page shows what the viewer sent last to it (and `condition(shown)` holds)."""
    end = time.time() + timeout
    last = None
    while time.time() < end:
        shown = viewer.shown
        s = shown.get(cid) if cid is not None else (max(shown.values(), key=lambda x: x.serial) if shown else None)
        if s is not None and (condition is None or condition(s)):
            pixels = canvas_pixels(page, s.image.shape)
            if pixels.shape == s.image.shape and np.array_equal(pixels, s.image):
                return s, pixels
            last = s
        time.sleep(0.1)
    raise AssertionError(f"the page did not show the viewer's frame within {timeout} s (last sent: "
                         f"{None if last is None else (last.serial, last.settings.width, last.settings.height)}; "
                         f"viewer error: {viewer.error!r})")


def wait_settled(page, viewer, condition=None, quiet: float = 1.0, timeout: float = 60.0):
    """wait_shown, once no newer frame has come for `quiet` seconds: the page's camera controls
    ease on after a drag, and each step they send renders a frame of its own."""
    end = time.time() + timeout
    while time.time() < end:
        shown, pixels = wait_shown(page, viewer, condition=condition, timeout=max(end - time.time(), 1.0))
        time.sleep(quiet)
        if max(s.serial for s in viewer.shown.values()) == shown.serial:
            return shown, pixels
    raise AssertionError(f"the viewer's frames did not settle within {timeout} s")


def drag(page, dx: int, dy: int, x: int = 60, y: int = 45, steps: int = 5) -> None:
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + dx, y + dy, steps=steps)
    page.mouse.up()
