"""How long the live viewer's page takes: the hooks a page gets to record its pointer events and
its frames' arrival, decode and display, the matching of each frame shown with the frame the
server sent, and the floor of the page's own path with nothing to render.
benchmarks/timing/viewer_latency.py measures with them; tests/test_viewer_latency.py tests them.

The page's clock and the server's are the same machine's: the page records
performance.timeOrigin + performance.now() (ms), the server time.time() (s).
"""

from __future__ import annotations

import time

import numpy as np

from .server import frame_element, free_port, page_style, show_frame

PAGE_HOOKS = """
(() => {
  const now = () => performance.timeOrigin + performance.now();
  window.__events = []; window.__frames = [];
  window.addEventListener('pointermove', () => window.__events.push(now()), true);
  const blobs = new Map();
  const create = URL.createObjectURL;
  URL.createObjectURL = function (obj) {
    const url = create.call(URL, obj);
    if (obj && obj.type && obj.type.startsWith('image/')) {
      const rec = {received: now(), decoded: null, displayed: null};
      window.__frames.push(rec); blobs.set(url, rec);
    }
    return url;
  };
  // The page's frame element gets its blob by attribute (React) and a probe image by property:
  // a frame counts as decoded when the last of them has loaded.
  const watch = (img, v) => {
    const rec = blobs.get(v);
    if (rec) img.addEventListener('load', () => {
      rec.decoded = now(); rec.width = img.naturalWidth; rec.height = img.naturalHeight;
      requestAnimationFrame(() => requestAnimationFrame(() => { rec.displayed = now(); }));
    }, {once: true});
  };
  const desc = Object.getOwnPropertyDescriptor(HTMLImageElement.prototype, 'src');
  Object.defineProperty(HTMLImageElement.prototype, 'src', {
    get() { return desc.get.call(this); },
    set(v) { watch(this, v); desc.set.call(this, v); },
  });
  const setAttribute = Element.prototype.setAttribute;
  Element.prototype.setAttribute = function (name, v) {
    if (this instanceof HTMLImageElement && name === 'src') watch(this, v);
    return setAttribute.call(this, name, v);
  };
})();
"""
PANEL_PX = 324  # the docked panel's width (viser's "medium")


def percentile(values, q):
    return float(np.percentile(values, q)) if len(values) else float("nan")


def drag(page, args) -> tuple[float, float]:
    """Drags the camera across the canvas for args.seconds, a pointer move every 20 ms; returns
    when it started and ended (time.time())."""
    page.mouse.move(args.width * 0.3, args.height * 0.5)
    page.mouse.down()
    t0 = time.time()
    steps = 0
    while time.time() - t0 < args.seconds:
        steps += 1
        page.mouse.move(args.width * (0.3 + 0.4 * ((steps % 40) / 40.0)), args.height * 0.5)
        time.sleep(0.02)
    page.mouse.up()
    return t0, time.time()


def matched_parts(sent: list[dict], frames: list[dict], events: list[float]) -> dict[str, list[float]]:
    """Each frame the page showed, matched with the frame the server sent (the next one sent before
    it arrived with its size: the server's message buffer may replace a frame not yet sent by a
    newer one, so some frames sent never arrive) and with the last pointer event before its
    request: the parts of its way from that event to the screen, in ms."""
    pairs, i = [], 0
    for r in frames:
        if r.get("width") is None:
            continue
        j = i
        while j < len(sent) and not ((sent[j]["width"], sent[j]["height"]) == (r["width"], r["height"])
                                     and sent[j]["times"]["sent"] <= r["received"] / 1e3 + 0.002):
            j += 1
        if j < len(sent) and r["received"] / 1e3 - sent[j]["times"]["sent"] < 1.0:
            pairs.append((sent[j], r))
            i = j + 1
    rows = {k: [] for k in ("event_to_screen", "event_to_server", "queue", "render", "view", "encode_send",
                            "transport", "decode", "display", "viewer_own")}
    for s, r in pairs:
        t = s["times"]
        if r["displayed"] is None or r["decoded"] is None:
            continue  # superseded in the page before it was shown
        before = [e for e in events if e <= t["request"] * 1e3]
        if not before:
            continue
        ev = before[-1] / 1e3
        parts = {"event_to_server": t["request"] - ev, "queue": t["render_start"] - t["request"],
                 "render": t["render_end"] - t["render_start"], "view": t["view"] - t["render_end"],
                 "encode_send": t["sent"] - t["view"], "transport": r["received"] / 1e3 - t["sent"],
                 "decode": (r["decoded"] - r["received"]) / 1e3, "display": (r["displayed"] - r["decoded"]) / 1e3}
        total = r["displayed"] / 1e3 - ev
        rows["event_to_screen"].append(total * 1e3)
        for k, val in parts.items():
            rows[k].append(val * 1e3)
        rows["viewer_own"].append((total - parts["render"]) * 1e3)
    return rows


def print_parts(rows: dict[str, list[float]], skip=()) -> None:
    print(f"{'part':<16} {'median ms':>10} {'p90 ms':>10}")
    for k, vals in rows.items():
        if k not in skip:
            print(f"{k:<16} {percentile(vals, 50):>10.1f} {percentile(vals, 90):>10.1f}")


def page_floor(args) -> float:
    """The viewer's own path with nothing to render: the same drag, each camera the page sends
    answered at once by a ready picture of the canvas's size (a new one each time) through the
    same path as the viewer's frames (encode and send, transport, decode, display). What it takes
    is the floor under viewer_own on this machine, with this browser and page, whatever the
    renderer does; returns its median (ms)."""
    import viser
    from playwright.sync_api import sync_playwright

    port = free_port("127.0.0.1")
    server = viser.ViserServer(host="127.0.0.1", port=port, verbose=False)
    server.gui.configure_theme(control_width="medium", show_logo=False, show_share_button=False)
    server.gui.main_panel.dock_right()
    server.gui.add_html(page_style(args.frames))
    rng = np.random.default_rng(0)
    # A smooth picture (a JPEG of noise would be far larger than a rendered frame's)
    y, x = np.mgrid[0:args.height, 0:args.width]
    image = np.stack([x / args.width, y / args.height, 0.5 + 0.1 * rng.random((args.height, args.width))], -1)
    image = (image * 255).astype(np.uint8)
    sent: list[dict] = []
    elements: dict = {}

    async def answer(camera) -> None:  # in the server's event loop, as the viewer's camera callback
        request = time.time()
        client = camera.client
        h, w = int(camera.image_height), int(camera.image_width)
        if h < 8 or w < 8:
            return
        picture = image if image.shape[:2] == (h, w) else np.ascontiguousarray(
            image[np.arange(h) * image.shape[0] // h][:, np.arange(w) * image.shape[1] // w])
        picture[:8, :8] = 8 * (len(sent) % 32)  # a new picture each time, as the viewer sends
        view = time.time()
        if args.frames == "overlay":
            show_frame(elements[client.client_id], picture)
        else:
            client.scene.set_background_image(picture, format="png" if args.lossless else "jpeg",
                                              jpeg_quality=None if args.lossless else 90)
        client.flush()
        sent.append({"width": w, "height": h, "times": {"request": request, "render_start": request,
                                                         "render_end": request, "view": view, "sent": time.time()}})

    def connected(client) -> None:
        if args.frames == "overlay":
            elements[client.client_id] = frame_element(client, args.lossless)
        client.camera.on_update(answer)

    server.on_client_connect(connected)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": args.width + PANEL_PX, "height": args.height},
                                device_scale_factor=1)
        page.add_init_script(PAGE_HOOKS)
        page.goto(f"http://127.0.0.1:{port}/")
        deadline = time.time() + 60
        while not sent and time.time() < deadline:
            time.sleep(0.1)
        time.sleep(2.0)
        start = len(sent)
        drag(page, args)
        time.sleep(1.0)
        events = page.evaluate("window.__events")
        frames = page.evaluate("window.__frames")
        browser.close()
    server.stop()
    rows = matched_parts(sent[start:], frames, events)
    print(f"the floor: the viewer's own path with nothing to render, {args.width}x{args.height}, "
          f"{'PNG' if args.lossless else 'JPEG'}, frames as {args.frames}, {len(rows['viewer_own'])} frames matched:")
    print_parts(rows, skip=("queue", "render", "view"))
    if len(rows["viewer_own"]) < 10:
        print("the floor: undecided (fewer than 10 frames matched; drag longer: --seconds)")
        return float("nan")
    return percentile(rows["viewer_own"], 50)
