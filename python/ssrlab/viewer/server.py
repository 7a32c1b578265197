"""The live viewer: ssrlab's frames in a browser page (viser), the page's camera driving them.

One worker thread renders; the page's events (camera moves, controls) only record what is asked
and wake it, so a render never blocks the page. Each page keeps only its newest request: a camera
that moved three times while a frame rendered is rendered once, where it is now. While a camera
moves, the worker renders at a fraction of the page's pixels chosen from the measured time per
pixel (progressive resolution); once it rests, at the full resolution, then refines: frames of
new seeds are averaged into the shown colour, and the converged reference (when on) is traced
with more rays each round, its error figures shown beside the frame.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import socket
import threading
import time
import traceback
from collections import deque
from pathlib import Path

import numpy as np

from .. import _core
from ..renderer import Renderer
from ..settings import Settings
from . import camera as cam
from . import views
from .panel import SettingsPanel

# Seconds without a camera event after which a camera counts as resting (full resolution).
REST_S = 0.25
# Frame time the progressive resolution aims at while a camera moves (ms of render + view).
MOVING_TARGET_MS = 60.0
# Smallest share of the page's pixels a moving camera is rendered at.
MIN_SCALE = 0.2
# Rounds of the converged reference while a camera rests: rays per reflective pixel of each.
REFERENCE_ROUNDS = (4, 16, 64)
# Frames kept for the live numbers.
HISTORY = 120
# Seconds between two redraws of the live numbers (table and chart) while a camera moves: each
# redraw is a React render and a chart redraw in the page, on the same cores that decode the frame
# (benchmarks/timing/viewer_latency.py); a resting frame's numbers are drawn at once.
NUMBERS_S = 0.5
# How a page shows its frames. "background": as the 3D view's background texture, which holds in
# every layout of the page (panel docked, floating or collapsed, a narrow page) but costs a
# WebGL texture upload on the page's main thread per frame. "overlay": as an image element of the
# page's panel that CSS lifts over the canvas at its height and the frame's aspect, letting the
# pointer through to the camera's controls; the browser decodes and composites an <img> itself,
# which makes the page's own path shorter (benchmarks/timing/viewer_latency.py --floor, with either
# value of --frames), and leaves the 3D view's own canvas empty, which the page redraws each
# animation frame while the camera moves. The element lives in the docked panel, so with overlay
# the panel stays docked: its collapse button is hidden and its header and handle take no drag (a
# collapsed panel would unmount the element, a floating one lie under it); it can still be resized.
# A page too narrow to hold the docked panel beside the canvas needs the background. (A
# background texture kept beside the overlay would cost its sampling in every one of those redraws.)
FRAMES = ("background", "overlay")
FRAME_CSS = ("img[src^='blob:']{position:fixed!important;left:0;top:0;height:100vh!important;"
             "width:auto!important;max-width:none!important;pointer-events:none;user-select:none;z-index:0}"
             "[data-dock-region-collapse]{display:none!important}"
             "[data-dock-header],[data-dock-region-handle]{pointer-events:none!important}")
# The frame is over the page's 3D view: nothing of the page's own may shade or cover it (the panel's
# drop shadow, the toast a software WebGL raises, which also takes the pointer), so that the pixels
# shown are the pixels sent.
PAGE_CSS = ".mantine-Notifications-root{display:none!important}*{box-shadow:none!important}"
# Seconds between two looks at the watched shader files.
WATCH_S = 0.5


def free_port(host: str) -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


@dataclasses.dataclass
class Shown:
    """What a page shows: the image sent (uint8, (H, W, 3), as encoded), the frame it came from, its
    camera and settings, the view, how many frames of new seeds are averaged in it, and when each
    step happened (time.time() seconds: request, render_start, render_end, view, sent)."""

    image: np.ndarray
    frame: object
    camera: _core.Camera
    settings: Settings
    view: str
    accumulated: int
    scale: float
    times: dict
    serial: int
    frame_b: object = None  # the right of the divider, comparing A against B


@dataclasses.dataclass
class _Page:
    client: object
    camera: _core.Camera | None = None
    size: tuple[int, int] = (0, 0)  # canvas (width, height) in pixels
    dirty: bool = True
    requested_at: float = 0.0
    moved_at: float = 0.0
    shown: Shown | None = None
    accum: np.ndarray | None = None
    accum_count: int = 0
    reference_round: int = 0
    image: object = None  # the page's frame element (frame_element), with frames="overlay"


def page_style(frames: str) -> str:
    """The <style> element every page gets (PAGE_CSS, and FRAME_CSS with frames="overlay")."""
    return "<style>" + PAGE_CSS + (FRAME_CSS if frames == "overlay" else "") + "</style>"


def frame_element(client, lossless: bool, jpeg_quality: int = 90):
    """The image element of one page's panel that shows its frames (FRAME_CSS places it), hidden
    until the first frame."""
    return client.gui.add_image(np.zeros((8, 8, 3), np.uint8), label=None, format="png" if lossless else "jpeg",
                                jpeg_quality=None if lossless else int(jpeg_quality), visible=False, order=1e9)


def show_frame(element, image: np.ndarray) -> None:
    """Sends `image` (uint8, (H, W, 3)) to the page of `element` (frame_element)."""
    element.image = image
    if not element.visible:
        element.visible = True


class Viewer:
    """A live view of `scene` in the browser: the handle ssrlab.view returns.

    url: the page's address. settings, camera: readable and settable while the page is open
    (setting them re-renders every page); frame: the newest full-resolution Frame shown; shown:
    what each page shows (Shown); metrics: the error figures of the newest frame against its
    converged reference (with reference on); close() stops the server.
    """

    def __init__(self, scene, settings: Settings | None = None, renderer: Renderer | None = None, *,
                 host: str = "127.0.0.1", port: int | None = None, scene_source: str | None = None,
                 lossless: bool = False, jpeg_quality: int = 90, accumulate: int = 8, out: str | Path = "renders/view",
                 device: str = "auto", watch_shaders: bool = True, reference_rays=REFERENCE_ROUNDS,
                 frames: str = FRAMES[0], moving_fps: float | None = None, verbose: bool = False):
        try:
            import viser
        except ImportError as e:
            raise ImportError(f"ssrlab.view needs viser, the viewer's page: pip install 'ssrlab[viewer]' ({e})") from None

        if settings is None:
            settings = Settings()
        if not isinstance(settings, Settings):
            raise TypeError(f"ssrlab.view: settings must be an ssrlab.Settings, got {type(settings).__name__}")
        if isinstance(accumulate, bool) or not isinstance(accumulate, int) or not 1 <= accumulate <= 1024:
            raise ValueError(f"ssrlab.view: accumulate must be an int in [1, 1024], got {accumulate!r}")
        rounds = tuple(reference_rays)
        if not rounds or any(isinstance(r, bool) or not isinstance(r, int) or r < 1 for r in rounds):
            raise ValueError(f"ssrlab.view: reference_rays must be rays per pixel >= 1 of each round, got "
                             f"{reference_rays!r}")
        self.reference_rays = rounds
        if frames not in FRAMES:
            raise ValueError(f"ssrlab.view: frames must be one of {', '.join(FRAMES)}, got {frames!r}")
        if not (moving_fps is None or (isinstance(moving_fps, (int, float)) and not isinstance(moving_fps, bool)
                                       and math.isfinite(moving_fps) and moving_fps > 0)):
            raise ValueError(f"ssrlab.view: moving_fps must be None (no limit) or frames a second > 0, "
                             f"got {moving_fps!r}")
        if not 1 <= int(jpeg_quality) <= 100:
            raise ValueError(f"ssrlab.view: jpeg_quality must be in [1, 100], got {jpeg_quality!r}")
        if scene.camera is None:
            raise ValueError("ssrlab.view: the scene has no default camera; give it one (scene.camera = ssrlab.Camera(...))")
        self.renderer = renderer if renderer is not None else Renderer(device)
        # Pacing a moving camera below the frame rate the device gives leaves cores to a page on the
        # same machine, whose path to the screen then waits less for the renderer's threads; it
        # also waits, itself, for its turn (benchmarks/timing/viewer_latency.py --moving-fps).
        self.moving_fps = None if moving_fps is None else float(moving_fps)
        self._paced_at = 0.0  # when the last render of a moving camera started
        self._pace_wait = 0.0  # seconds the worker waits before the next render of a moving camera
        self.scene = scene
        self.scene_source = scene_source
        self.lossless = bool(lossless)
        self.jpeg_quality = int(jpeg_quality)
        self.frames = frames
        self.accumulate = int(accumulate)
        self.out = Path(out)
        self._cond = threading.Condition()
        self._render_lock = threading.Lock()
        self._closed = False
        self._pages: dict[int, _Page] = {}
        self._settings = settings
        self._settings_b: Settings | None = None
        self._error = ""
        self._view, self._layer, self._ray, self._exposure = "color", 0, 0, 1.0
        self._resolution = 1.0
        self._reference_on = False
        self._compare = False
        self._divider = 0.5
        self._ms_per_pixel: float | None = None
        self._history: deque = deque(maxlen=HISTORY)
        self._numbers_drawn = (0.0, 0)  # (when, serial of the frame drawn)
        self._numbers_frame = None  # the newest frame of the history, whose rays the numbers count
        self._serial = 0
        self._frame = None
        self._reference = None  # (key, ConvergedReference, rays)
        self.metrics: dict = {}
        self.metrics_b: dict | None = None
        self._recording: list | None = None
        self._playing = False
        self._time_base = (time.time(), float(getattr(scene, "time", 0.0)))
        self._watched: dict[str, float] = {}
        self._watch_shaders = bool(watch_shaders)
        self._watched_at = 0.0
        self._snapshot = ""

        host = str(host)
        port = free_port(host) if port is None else int(port)
        self.server = viser.ViserServer(host=host, port=port, label="ssrlab", verbose=verbose)
        self.host, self.port = self.server.get_host(), self.server.get_port()
        self.server.gui.configure_theme(control_width="medium", show_logo=False, show_share_button=False)
        self.server.gui.main_panel.dock_right()
        c0 = scene.camera
        self.server.initial_camera.position = tuple(c0.position)
        self.server.initial_camera.look_at = tuple(c0.target)
        self.server.initial_camera.up = tuple(c0.up)
        self.server.initial_camera.fov = math.radians(c0.fov_y)
        self._near, self._far = float(c0.near), float(c0.far)
        self._build_gui()
        self.server.on_client_connect(self._connect)
        self.server.on_client_disconnect(self._disconnect)
        self._watch(initial=True)
        self._worker = threading.Thread(target=self._run, name="ssrlab-viewer", daemon=True)
        self._worker.start()

    # -- the handle ------------------------------------------------------------------------------
    @property
    def url(self) -> str:
        host = "127.0.0.1" if self.host in ("0.0.0.0", "") else self.host
        return f"http://{host}:{self.port}/"

    @property
    def settings(self) -> Settings:
        """The settings the pages render with (width and height follow each page's canvas)."""
        return self._settings

    @settings.setter
    def settings(self, settings: Settings) -> None:
        if not isinstance(settings, Settings):
            raise TypeError(f"settings must be an ssrlab.Settings, got {type(settings).__name__}")
        settings.check_constraints()
        self._apply(settings)
        self._panel.show(settings)

    @property
    def camera(self) -> _core.Camera:
        """The camera of the page that rendered last (the scene's before any page opened)."""
        with self._cond:
            pages = [p for p in self._pages.values() if p.camera is not None]
        if not pages:
            return self.scene.camera
        return max(pages, key=lambda p: p.requested_at).camera

    @camera.setter
    def camera(self, camera: _core.Camera) -> None:
        if not isinstance(camera, _core.Camera):
            raise TypeError(f"camera must be an ssrlab.Camera, got {type(camera).__name__}")
        camera.validate()
        self.server.initial_camera.position = tuple(camera.position)
        self.server.initial_camera.look_at = tuple(camera.target)
        self.server.initial_camera.up = tuple(camera.up)
        self.server.initial_camera.fov = math.radians(camera.fov_y)
        self._near, self._far = float(camera.near), float(camera.far)
        for page in list(self._pages.values()):
            cam.to_page(page.client.camera, camera)

    @property
    def frame(self):
        """The newest full-resolution Frame a page shows (None before the first)."""
        return self._frame

    @property
    def shown(self) -> dict[int, Shown]:
        """What each open page shows, by viser client id."""
        with self._cond:
            return {cid: p.shown for cid, p in self._pages.items() if p.shown is not None}

    @property
    def error(self) -> str:
        """The message the page shows for the last refused setting, render or shader ('' when none)."""
        return self._error

    @property
    def history(self) -> list[dict]:
        """The live numbers of the last frames shown: size, GPU ms per pass, wall ms, viewer ms,
        rays traced (None for a frame whose numbers were not drawn: NUMBERS_S), and whether the
        camera was moving (a frame paced by moving_fps)."""
        return list(self._history)

    def wait(self, condition=None, timeout: float = 60.0) -> bool:
        """Waits until `condition(viewer)` holds (default: some page shows a frame); True if it did."""
        condition = condition or (lambda v: bool(v.shown))
        end = time.time() + timeout
        while time.time() < end:
            if condition(self):
                return True
            time.sleep(0.02)
        return bool(condition(self))

    def snippet(self) -> str:
        """Python that renders the frame shown (the newest page's) again with Renderer.render."""
        shown = self._newest()
        if shown is None:
            raise ValueError("no frame shown yet")
        return self._snippet_of(shown)

    def close(self) -> None:
        """Stops the server and the worker; the renderer and scene stay usable."""
        with self._cond:
            if self._closed:
                return
            self._closed = True
            self._cond.notify_all()
        self._worker.join(timeout=30)
        self.server.stop()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _repr_html_(self) -> str:
        return (f'<iframe src="{self.url}" width="100%" height="540" style="border:0" '
                f'title="ssrlab viewer"></iframe><div><a href="{self.url}" target="_blank">{self.url}</a></div>')

    def __repr__(self) -> str:
        return f"<ssrlab viewer {self.url} of scene {self.scene.name!r}>"

    # -- the page --------------------------------------------------------------------------------
    def _build_gui(self) -> None:
        gui = self.server.gui
        gui.add_html(page_style(self.frames))
        self._status = gui.add_markdown("starting")
        self._message = gui.add_markdown("")
        with gui.add_folder("view"):
            self._view_control = gui.add_dropdown("view", ("color",), initial_value="color",
                                                  hint="what the frame holds: colour, reflection, each G-buffer "
                                                       "channel of each layer, the rays, the error, any texture")
            self._layer_control = gui.add_slider("layer", min=0, max=max(self._settings.layers - 1, 1), step=1, initial_value=0,
                                                 hint="G-buffer layer of the layered views")
            self._ray_control = gui.add_slider("ray", min=0, max=max(self._settings.rays_per_pixel - 1, 1), step=1, initial_value=0,
                                               hint="ray of the pixel, for the ray views")
            self._exposure_control = gui.add_number("exposure", initial_value=1.0, min=0.0, step=0.1,
                                                    hint="scale of linear radiance before the sRGB encoding")
            self._resolution_control = gui.add_slider("resolution", min=0.1, max=1.0, step=0.05, initial_value=1.0,
                                                      hint="share of the page's pixels rendered at rest "
                                                           "(a moving camera may get fewer)")
            self._reference_control = gui.add_checkbox(
                "reference", initial_value=False, hint="trace the converged reference while the camera rests and show the "
                                         "frame's error against it (thesis error, PSNR, FLIP)")
            to_scene = gui.add_button("scene camera", hint="every page back to the scene's own camera")
            self._caption = gui.add_markdown("")
        to_scene.on_click(lambda _e: setattr(self, "camera", self.scene.camera))
        for c in (self._view_control, self._layer_control, self._ray_control, self._exposure_control,
                  self._resolution_control, self._reference_control):
            c.on_update(self._on_view)
        with gui.add_folder("numbers") as self._numbers_folder:
            self._numbers = gui.add_markdown("")
            self._chart = gui.add_uplot(data=(np.zeros(1), np.zeros(1)),
                                        series=({"label": "frame"}, {"label": "GPU total", "stroke": "black"}),
                                        title="milliseconds over the last frames", aspect=1.5)
            self._chart_order = self._chart.order
            self._chart_series = ("GPU total",)
            self._metrics_md = gui.add_markdown("")
        with gui.add_folder("pixel inspector", expand_by_default=False):
            self._inspector = gui.add_markdown("click the image to read every channel of every layer there")
        with gui.add_folder("A against B", expand_by_default=False):
            self._compare_control = gui.add_checkbox("compare", initial_value=False,
                                                     hint="the left of the divider renders the settings above (A), "
                                                          "the right these (B)")
            self._b_control = gui.add_text("B: changes", initial_value="method=\"linear\"",
                                           hint="fields B changes from A, FIELD=VALUE separated by commas "
                                                "(values as JSON)")
            self._divider_control = gui.add_slider("divider", min=0.0, max=1.0, step=0.01, initial_value=0.5)
            self._compare_md = gui.add_markdown("")
        for c in (self._compare_control, self._b_control, self._divider_control):
            c.on_update(self._on_compare)
        animated = bool(getattr(self.scene, "animations", [])) or bool(
            getattr(self.scene, "_animation_state", None) and self.scene._animation_state().motions)
        with gui.add_folder("time", expand_by_default=False):
            self._play_control = gui.add_checkbox("play", initial_value=False, hint="play the scene's animations and motions",
                                                  disabled=not animated)
            self._time_control = gui.add_slider("time", min=0.0, max=_duration(self.scene), step=0.01,
                                                initial_value=float(getattr(self.scene, "time", 0.0)),
                                                disabled=not animated)
        self._play_control.on_update(self._on_time)
        self._time_control.on_update(self._on_time)
        with gui.add_folder("keep", expand_by_default=False):
            copy = gui.add_button("copy as Python", hint="the scene, settings and camera as a script that renders "
                                                        "this frame again, bit for bit on the same device")
            save = gui.add_button("save frame", hint="Frame.save into a new folder under the viewer's out folder")
            self._record_control = gui.add_checkbox("record camera path", initial_value=False,
                                                    hint="keeps every resting camera; unticked, writes them as a "
                                                         "CameraPath file (ssrlab.CameraPath.load)")
            self._keep_md = gui.add_markdown("")
        copy.on_click(lambda _e: self._on_copy())
        save.on_click(lambda _e: self._on_save())
        self._record_control.on_update(lambda _e: self._on_record())
        self._panel = SettingsPanel(gui, self._settings, self.renderer.user_passes, self._on_settings)
        self.server.scene.on_click()(self._on_click)

    def _connect(self, client) -> None:
        page = _Page(client=client, image=frame_element(client, self.lossless, self.jpeg_quality)
                     if self.frames == "overlay" else None)
        with self._cond:
            self._pages[client.client_id] = page
            initial = _core.Camera(position=tuple(self.server.initial_camera.position),
                                   target=tuple(self.server.initial_camera.look_at),
                                   up=tuple(self.server.initial_camera.up),
                                   fov_y=math.degrees(self.server.initial_camera.fov), near=self._near, far=self._far)
        cam.to_page(client.camera, initial)

        async def moved(camera_handle) -> None:
            # A coroutine runs in the server's event loop as the message arrives, where a plain
            # function would wait for a thread of the server's pool first; it only records the
            # request and wakes the worker.
            self._on_camera(client.client_id, camera_handle)

        client.camera.on_update(moved)

    def _disconnect(self, client) -> None:
        with self._cond:
            self._pages.pop(client.client_id, None)

    def _on_camera(self, cid: int, handle) -> None:
        try:
            camera = cam.from_page(handle.position, handle.wxyz, handle.fov, handle.look_at, self._near, self._far)
            size = (int(handle.image_width), int(handle.image_height))
        except (ValueError, AssertionError):
            return  # a degenerate camera (no size yet): nothing to render
        now = time.time()
        with self._cond:
            page = self._pages.get(cid)
            if page is None:
                return
            if page.camera is not None and _same_camera(page.camera, camera) and page.size == size:
                return
            first = page.camera is None
            page.camera, page.size = camera, size
            page.dirty, page.requested_at = True, now
            page.moved_at = 0.0 if first else now
            self._cond.notify_all()
        if self._recording is not None:
            self._recording.append(camera)

    def _on_view(self, _event) -> None:
        with self._cond:
            self._view = str(self._view_control.value)
            self._layer = int(self._layer_control.value)
            self._ray = int(self._ray_control.value)
            self._exposure = float(self._exposure_control.value)
            resolution = float(self._resolution_control.value)
            changed_size = resolution != self._resolution
            self._resolution = resolution
            self._reference_on = bool(self._reference_control.value)
            for page in self._pages.values():
                page.dirty = True
                if changed_size:
                    page.accum, page.accum_count = None, 0
            self._cond.notify_all()

    def _on_compare(self, _event) -> None:
        try:
            b = self._settings.replace(**parse_changes(str(self._b_control.value))) if self._compare_control.value \
                else None
        except ValueError as e:
            self._show_error(f"B: {e}")
            return
        with self._cond:
            self._compare = b is not None
            self._settings_b = b
            self._divider = float(self._divider_control.value)
            self._error = ""
            self._message.content = ""
            self._mark_all()

    def _on_time(self, _event) -> None:
        with self._cond:
            self._playing = bool(self._play_control.value)
            self._time_base = (time.time(), float(self._time_control.value))
            self._mark_all(reset=True)

    def _on_settings(self, values: dict) -> None:
        try:
            settings = self._settings.replace(**values)
        except (ValueError, TypeError) as e:
            self._show_error(str(e))
            return
        self._apply(settings)

    def _apply(self, settings: Settings) -> None:
        with self._cond:
            self._settings = settings
            if self._settings_b is not None:
                try:
                    self._settings_b = settings.replace(**parse_changes(str(self._b_control.value)))
                except ValueError:
                    pass
            self._error = ""
            self._message.content = ""
            self._layer_control.max = max(settings.layers - 1, 1)
            self._ray_control.max = max(settings.rays_per_pixel - 1, 1)
            self._mark_all(reset=True)

    def _mark_all(self, reset: bool = False) -> None:
        for page in self._pages.values():
            page.dirty = True
            if reset:
                page.accum, page.accum_count, page.reference_round = None, 0, 0
        self._cond.notify_all()

    def _show_error(self, message: str) -> None:
        self._error = message
        self._message.content = f"**refused:** {message}"

    def _on_click(self, event) -> None:
        with self._cond:
            page = self._pages.get(event.client_id)
            shown = page.shown if page else None
        if shown is None:
            return
        x, y = event.screen_pos  # 0..1 over the canvas, (0, 0) its top-left corner
        s = shown.settings
        row, col = min(int(y * s.height), s.height - 1), min(int(x * s.width), s.width - 1)
        try:
            with self._render_lock:
                values = views.inspect(shown.frame, row, col)
        except (ValueError, RuntimeError) as e:
            self._inspector.content = f"cannot read pixel ({row}, {col}): {e}"
            return
        self.inspected = values
        self._inspector.content = views.inspect_markdown(values)

    def _on_copy(self) -> None:
        shown = self._newest()
        if shown is None:
            return
        self._snapshot = self._snippet_of(shown)
        self._keep_md.content = "```python\n" + self._snapshot + "```"

    def _on_save(self) -> None:
        shown = self._newest()
        if shown is None:
            return
        folder = _new_folder(self.out, "frame")
        try:
            with self._render_lock:
                shown.frame.save(folder)
            (folder / "render.py").write_text(self._snippet_of(shown))
            self._keep_md.content = f"saved {folder}"
        except (OSError, ValueError) as e:
            self._keep_md.content = f"could not save: {e}"

    def _on_record(self) -> None:
        from ..sequence import CameraPath

        if self._record_control.value:
            self._recording = [self.camera]
            self._keep_md.content = "recording the camera"
            return
        cams, self._recording = self._recording or [], None
        if len(cams) < 2:
            self._keep_md.content = "no camera path: the camera did not move while recording"
            return
        c = cams[0]
        path = CameraPath([x.position for x in cams], [x.target for x in cams], len(cams), up=c.up,
                          fov_y=c.fov_y, near=c.near, far=c.far)
        self.out.mkdir(parents=True, exist_ok=True)
        target = _new_folder(self.out, "camera_path").with_suffix(".json")
        try:
            path.save(target)
            self._keep_md.content = f"wrote {target} ({len(cams)} cameras)"
        except (OSError, ValueError) as e:
            self._keep_md.content = f"could not write the camera path: {e}"

    def _newest(self) -> Shown | None:
        with self._cond:
            shown = [p.shown for p in self._pages.values() if p.shown is not None]
        return max(shown, key=lambda s: s.serial) if shown else None

    def _snippet_of(self, shown: Shown) -> str:
        source = self.scene_source or f"...  # the scene given to ssrlab.view ({self.scene.name!r})"
        t = float(self.scene.time) if (self._playing or getattr(self.scene, "time", 0.0)) else None
        registered = ""
        if self.renderer.user_passes and not shown.settings.user_modules:
            registered = "# register the user passes " + ", ".join(self.renderer.user_passes) + \
                " here: renderer.register_pass(...)"
        return cam.snippet(source, shown.camera, shown.settings, self.renderer.info["device"], t, registered)

    # -- the worker ------------------------------------------------------------------------------
    def _run(self) -> None:
        while True:
            with self._cond:
                if self._closed:
                    return
                job = self._next_job()
                if job is None:
                    self._cond.wait(timeout=min(0.05, self._pace_wait) if self._pace_wait > 0 else 0.05)
                    job = self._next_job() if not self._closed else None
            if job is None:
                with self._render_lock:
                    self._draw_numbers()
                self._watch()
                continue
            try:
                self._do(*job)
            except Exception as e:  # the server and its state outlive any render
                self._show_error(f"{type(e).__name__}: {e}")
                if os.environ.get("SSRLAB_VIEWER_TRACEBACK"):
                    traceback.print_exc()
                with self._cond:
                    page = self._pages.get(job[0])
                    if page is not None:
                        page.dirty = False

    def _next_job(self):
        """(client id, kind) of the most pressing work: a page's new request (oldest first), a
        resting page shown at a reduced resolution, accumulation, a reference round."""
        now = time.time()
        if self._playing:
            self._mark_all(reset=True)
        dirty = [p for p in self._pages.values() if p.dirty and p.camera is not None and p.size[0] > 0]
        self._pace_wait = 0.0
        if dirty:
            page = min(dirty, key=lambda p: p.requested_at)
            if self.moving_fps is not None and now - page.moved_at < REST_S:
                self._pace_wait = self._paced_at + 1.0 / self.moving_fps - now
                if self._pace_wait > 0:
                    return None  # paced (moving_fps): the request waits, and meanwhile takes newer cameras
            return page.client.client_id, "request"
        for page in self._pages.values():
            if page.shown is None or page.camera is None or now - page.moved_at < REST_S:
                continue
            if page.shown.scale < self._resolution:
                return page.client.client_id, "rest"
            if self._playing:
                continue
            if not self._compare and page.accum_count < self.accumulate and _stochastic(self._settings):
                return page.client.client_id, "accumulate"
            if self._reference_on and page.reference_round < len(self.reference_rays):
                return page.client.client_id, "reference"
        return None

    def _size(self, page: _Page, moving: bool) -> tuple[int, int, float]:
        w, h = page.size
        scale = self._resolution
        if moving and self._ms_per_pixel is not None:
            fit = math.sqrt(MOVING_TARGET_MS / max(self._ms_per_pixel * w * h, 1e-9))
            scale = min(scale, max(MIN_SCALE, round(fit * 20) / 20))
        return max(int(round(w * scale)), 8), max(int(round(h * scale)), 8), scale

    def _do(self, cid: int, kind: str) -> None:
        with self._cond:
            page = self._pages.get(cid)
            if page is None:
                return
            page.dirty = False
            camera, requested = page.camera, page.requested_at
            moving = time.time() - page.moved_at < REST_S
            if moving and kind == "request":
                self._paced_at = time.time()
            settings, b = self._settings, self._settings_b if self._compare else None
            view, layer, ray, exposure = self._view, self._layer, self._ray, self._exposure
        if self._playing:
            t = self._time_base[1] + (time.time() - self._time_base[0])
            t = t % max(self._time_control.max, 1e-6) if self._time_control.max > 0 else t
            self.scene.set_time(t)
        if kind == "reference":
            self._reference_round(page, view, layer, ray, exposure)
            return
        w, h, scale = self._size(page, moving and kind == "request")
        s = settings.replace(width=w, height=h)
        seed_offset = page.accum_count if kind == "accumulate" else 0
        if seed_offset:
            s = s.replace(seed=(settings.seed + seed_offset) % 2**31)
        times = {"request": requested, "render_start": time.time()}
        with self._render_lock:
            try:
                frame = self.renderer.render(self.scene, camera, s)
                frame_b = self.renderer.render(self.scene, camera, b.replace(width=w, height=h)) if b else None
            except (ValueError, _core.ShaderError, _core.GLError, _core.SceneError) as e:
                self._show_error(f"{type(e).__name__}: {e}")
                return
            times["render_end"] = time.time()
            ms = frame.wall_ms
            self._ms_per_pixel = ms / (w * h) if self._ms_per_pixel is None else \
                0.7 * self._ms_per_pixel + 0.3 * ms / (w * h)
            if kind == "accumulate" and page.accum_count >= 1 and page.shown is not None and \
                    (page.shown.settings.height, page.shown.settings.width) == (h, w):
                if page.accum is None:  # the sum starts at the first frame averaged in, not before
                    page.accum = np.array(page.shown.frame.color, np.float64)
                page.accum += frame.color
                page.accum_count += 1
                colour = page.accum / page.accum_count
                shown_frame, s = page.shown.frame, page.shown.settings
            else:
                # A new view: its float colour stays on the device unless frames are averaged in
                # (views.picture encodes it there).
                page.accum, page.accum_count = None, 1
                page.reference_round = 0
                colour, shown_frame = None, frame
            if view not in views.names(shown_frame):
                view = "color"
            reference = self._reference[1] if self._reference and self._reference[0] == id(shown_frame) else None
            try:
                image, caption = views.picture(shown_frame, view, layer=layer, ray=ray, reference=reference,
                                               exposure=exposure, color=colour)
            except ValueError as e:
                image, caption = views.picture(shown_frame, "color", exposure=exposure, color=colour)
                caption = f"{e}; showing the colour"
            if frame_b is not None:
                image_b, _ = views.picture(frame_b, view if view in views.names(frame_b) else "color", layer=layer,
                                           ray=ray, exposure=exposure)
                image = _split(image, image_b, self._divider)
                self._compare_md.content = self._compare_text(frame, frame_b)
            names = views.names(shown_frame)
        times["view"] = time.time()
        if not self._send(page, image):
            return
        times["sent"] = time.time()
        with self._cond:
            self._serial += 1
            page.shown = Shown(image=image, frame=shown_frame, camera=camera, settings=s, view=view,
                               accumulated=page.accum_count, scale=scale, times=times, serial=self._serial,
                               frame_b=frame_b if frame_b is not None else
                               (page.shown.frame_b if kind == "accumulate" and page.shown else None))
            if scale >= self._resolution:
                self._frame = shown_frame
        if tuple(self._view_control.options) != tuple(names):
            self._view_control.options = tuple(names)
        if self._caption.content != caption:
            self._caption.content = caption
        with self._render_lock:
            self._numbers_for(frame, times, scale, page.accum_count, cid, moving=moving and kind == "request")

    def _send(self, page: _Page, image: np.ndarray) -> bool:
        if self._closed or page.client.client_id not in self.server.get_clients():
            with self._cond:  # the page closed while its frame rendered
                self._pages.pop(page.client.client_id, None)
            return False
        try:
            if page.image is not None:
                show_frame(page.image, image)
            elif self.lossless:
                page.client.scene.set_background_image(image, format="png")
            else:
                page.client.scene.set_background_image(image, format="jpeg", jpeg_quality=self.jpeg_quality)
            page.client.flush()  # now, not at the end of the server's next send window
            return True
        except Exception:  # the page closed while its frame rendered
            with self._cond:
                self._pages.pop(page.client.client_id, None)
            return False

    def _reference_round(self, page: _Page, view, layer, ray, exposure) -> None:
        from ..truth.metrics import image_metrics

        shown = page.shown
        rays = self.reference_rays[page.reference_round]

        def go_on(done: int, total: int) -> bool:  # a page's new request stops the round between its sample rounds
            return not self._closed and not any(p.dirty for p in self._pages.values())

        with self._render_lock:
            if shown.frame.released:
                return
            try:
                ref = shown.frame.reference("converged", rays=rays, progress=go_on)
            except RuntimeError:
                return  # stopped for a newer request: that request renders first, the round comes again later
            colour = page.accum / page.accum_count if page.accum is not None else shown.frame.color
            metrics = image_metrics(shown.frame.color if page.accum_count <= 1 else colour, ref.color, ref.reflective)
            metrics_b = None
            if shown.frame_b is not None and not shown.frame_b.released:
                metrics_b = image_metrics(shown.frame_b.color, ref.color, ref.reflective)
            self._reference = (id(shown.frame), ref, rays)
        page.reference_round += 1
        self.metrics = {"rays": rays, **metrics}
        self.metrics_b = None if metrics_b is None else {"rays": rays, **metrics_b}
        self._metrics_md.content = _metrics_markdown(rays, metrics, page.accum_count)
        if metrics_b is not None:
            self._compare_md.content = self._compare_text(shown.frame, shown.frame_b, metrics, metrics_b)
        if view == "error":
            with self._cond:
                page.dirty = True
                page.moved_at = 0.0
                self._cond.notify_all()

    @staticmethod
    def _compare_text(a, b, metrics_a=None, metrics_b=None) -> str:
        def line(name, f, m):
            err = (f", thesis error {m['thesis_error']:.6g}, PSNR {m['psnr']:.4g} dB" if m else "")
            return f"{name}: {f.timings.get('total', 0.0):.2f} ms GPU, {f.wall_ms:.1f} ms wall{err}"

        return line("A (left)", a, metrics_a) + "  \n" + line("B (right)", b, metrics_b)

    def _numbers_for(self, frame, times: dict, scale: float, accumulated: int, cid: int = -1,
                     moving: bool = False) -> None:
        timings = frame.timings
        viewer_ms = (times["sent"] - times["render_end"]) * 1e3
        entry = {"width": frame.settings.width, "height": frame.settings.height, "scale": scale,
                 "gpu_ms": float(timings.get("total", 0.0)), "wall_ms": float(frame.wall_ms),
                 "render_ms": (times["render_end"] - times["render_start"]) * 1e3, "viewer_ms": viewer_ms,
                 "passes": {k: float(v) for k, v in timings.items() if "." not in k and k != "total"},
                 "shown_at": times["sent"], "times": dict(times), "page": cid, "serial": self._serial,
                 "rays": None, "accumulated": accumulated, "moving": moving}
        self._history.append(entry)
        self._numbers_frame = frame
        moving = any(time.time() - p.moved_at < REST_S for p in list(self._pages.values()))
        self._draw_numbers(at_once=not moving)

    def _draw_numbers(self, at_once: bool = True) -> None:
        """The live numbers of the newest frame: at once, or when NUMBERS_S has passed since the last
        redraw (and the newest frame is not drawn yet)."""
        if not self._history:
            return
        entry = self._history[-1]
        now = time.time()
        when, serial = self._numbers_drawn
        if entry["serial"] == serial or (not at_once and now - when < NUMBERS_S):
            return
        self._numbers_drawn = (now, entry["serial"])
        if entry["rays"] is None:  # counted for the frames whose numbers are drawn only: it reads the rays back
            f = self._numbers_frame
            traced = f is not None and not f.released and "rays.hit" in f.texture_names
            entry["rays"] = int(f.stats.get("rays_traced") or 0) if traced else 0
        recent = [e for e in self._history if e["shown_at"] > entry["shown_at"] - 2.0]
        fps = (len(recent) - 1) / (recent[-1]["shown_at"] - recent[0]["shown_at"]) if len(recent) > 1 and \
            recent[-1]["shown_at"] > recent[0]["shown_at"] else 0.0
        top = sorted(entry["passes"].items(), key=lambda kv: -kv[1])
        lines = [f"{entry['width']}x{entry['height']} ({entry['scale']:.0%} of the page), {fps:.1f} frames/s, "
                 f"{entry['rays']} rays traced, {entry['accumulated']} frame(s) averaged  ",
                 f"GPU {entry['gpu_ms']:.2f} ms, wall {entry['wall_ms']:.1f} ms, viewer {entry['viewer_ms']:.1f} ms",
                 "", "| pass | GPU ms |", "|---|---|"] + [f"| {k} | {v:.3f} |" for k, v in top]
        self._numbers.content = "\n".join(lines)
        status = f"**{self.scene.name}** on {self.renderer.info['renderer']}"
        if self._status.content != status:
            self._status.content = status
        passes = tuple(entry["passes"])
        series = ("GPU total",) + passes + ("viewer",)
        history = list(self._history)
        columns = [np.array([e["gpu_ms"] for e in history])]
        columns += [np.array([e["passes"].get(name, np.nan) for e in history]) for name in passes]
        columns += [np.array([e["viewer_ms"] for e in history])]
        data = (np.arange(len(history), dtype=np.float64), *columns)
        if series != self._chart_series:
            self._chart.remove()
            with self._numbers_folder:
                self._chart = self.server.gui.add_uplot(
                    data=data, series=({"label": "frame"},) + tuple(
                        {"label": name, "stroke": _CHART_COLOURS[i % len(_CHART_COLOURS)]}
                        for i, name in enumerate(series)),
                    title="milliseconds over the last frames", aspect=1.5, order=self._chart_order)
            self._chart_series = series
        else:
            self._chart.data = data

    # -- shaders that change on disk --------------------------------------------------------------
    def _watched_files(self) -> list[Path]:
        from ..user_pass import declared

        files = {Path(p.shader) for p in list(self.renderer.user_passes.values()) + list(declared().values())}
        root = Path(self.renderer._shader_dir).resolve()
        if (root.parent / "CMakeLists.txt").exists():  # a source checkout: ssrlab's own shaders too
            files |= {p for p in root.rglob("*") if p.suffix in (".glsl", ".comp", ".vert", ".frag")}
        return sorted(files)

    def _watch(self, initial: bool = False) -> None:
        if not self._watch_shaders or (not initial and time.time() - self._watched_at < WATCH_S):
            return
        self._watched_at = time.time()
        stamps = {}
        for f in self._watched_files():
            try:
                stamps[str(f)] = f.stat().st_mtime_ns
            except OSError:
                continue
        if initial or not self._watched:
            self._watched = stamps
            return
        changed = sorted(k for k, v in stamps.items() if self._watched.get(k) != v)
        if not changed:
            return
        self._watched = stamps
        self._reload(changed)

    def _reload(self, changed: list[str]) -> None:
        """A new renderer, whose shader library reads every file again, with the same user passes;
        kept only if the current settings render with it (the last good frame stays otherwise)."""
        old = self.renderer
        with self._render_lock:
            try:
                new = Renderer(old.device, shader_dir=old._shader_dir, input_fetch=old._input_fetch,
                               max_triangles=old.max_triangles or 0)
                new.triangle_rates = old.triangle_rates
                new.readback_path, new.clear_path, new.visibility_tiles = \
                    old.readback_path, old.clear_path, old.visibility_tiles
                for p in old.user_passes.values():
                    new.register_pass(p)
                page = self._newest()
                s = (page.settings if page else self._settings.replace(width=64, height=36))
                new.render(self.scene, page.camera if page else None, s)
            except (_core.ShaderError, ValueError, _core.GLError) as e:
                self._show_error(f"{type(e).__name__} after {', '.join(Path(c).name for c in changed)} changed: {e}")
                return
        self.renderer = new
        with self._cond:
            self._error = ""
            self._message.content = f"reloaded {', '.join(Path(c).name for c in changed)}"
            self._mark_all(reset=True)


_CHART_COLOURS = ("black", "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
                  "#7f7f7f", "#bcbd22", "#17becf")


def _same_camera(a: _core.Camera, b: _core.Camera) -> bool:
    return (tuple(a.position) == tuple(b.position) and tuple(a.target) == tuple(b.target)
            and tuple(a.up) == tuple(b.up) and a.fov_y == b.fov_y)


def _stochastic(s: Settings) -> bool:
    """Whether frames of other seeds differ: rays drawn at random, or noise in the sampling."""
    return s.method != "off" and (s.rays_per_pixel > 1 or s.glossy == "stochastic")


def _duration(scene) -> float:
    longest = 0.0
    for a in getattr(scene, "animations", []) or []:
        longest = max(longest, float(getattr(a, "duration", 0.0)))
    return longest if longest > 0 else 10.0


def moving_fps_arg(text: str):
    """A command line's --moving-fps ('off' or frames a second) as Viewer's moving_fps."""
    if text == "off":
        return None
    try:
        fps = float(text)
    except ValueError:
        fps = math.nan
    if not (math.isfinite(fps) and fps > 0):
        raise argparse.ArgumentTypeError(f"must be off or frames a second > 0, got {text!r}")
    return fps


def parse_changes(text: str) -> dict:
    """'a=1, b="x"' as {'a': 1, 'b': 'x'}: --set's FIELD=VALUE items (ssrlab.lab.protocol.parse_set),
    separated by commas."""
    from ..lab.protocol import parse_set

    return parse_set([t for t in text.split(",") if t.strip()])


def _split(a: np.ndarray, b: np.ndarray, divider: float) -> np.ndarray:
    """A left of the divider, B right of it (pictures as the page gets them, uint8), a one-pixel
    white line between."""
    w = a.shape[1]
    x = min(max(int(round(divider * w)), 0), w)
    out = np.array(a, copy=True)
    out[:, x:] = b[:, x:]
    if 0 < x < w:
        out[:, x - 1] = 255
    return out


def _metrics_markdown(rays: int, m: dict, accumulated: int) -> str:
    keys = [k for k in ("thesis_error", "psnr", "rmse", "flip_ldr", "thesis_error_reflective", "psnr_reflective",
                        "flip_ldr_reflective") if m.get(k) is not None]
    lines = [f"error against the converged reference ({rays} rays per reflective pixel"
             f"{f'; the frame averaged over {accumulated} seeds' if accumulated > 1 else ''}):", "",
             "| metric | value |", "|---|---|"]
    lines += [f"| {k} | {m[k]:.9g} |" for k in keys]
    return "\n".join(lines)


def _new_folder(out: Path, stem: str) -> Path:
    """out/<stem>_<n> for the first n not taken: nothing a user wrote is overwritten."""
    out.mkdir(parents=True, exist_ok=True)
    n = 0
    while (out / f"{stem}_{n:03d}").exists() or (out / f"{stem}_{n:03d}.json").exists():
        n += 1
    return out / f"{stem}_{n:03d}"
