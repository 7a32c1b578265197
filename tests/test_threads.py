"""A render lets other Python threads run (it releases the GIL), and two threads rendering with one
Renderer at once get the images each would get alone (the GL context's lock serialises them)."""

from __future__ import annotations

import threading
import time

import numpy as np

import ssrlab


def test_other_threads_run_while_a_frame_renders():
    r = ssrlab.Renderer("cpu")
    scene = ssrlab.scenes.hall()
    s = ssrlab.Settings(width=320, height=180, method="hiz")
    r.render(scene, settings=s)  # compiled before the measured render
    ticks, done = [0], threading.Event()

    def count():
        while not done.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    time.sleep(0.05)
    before = ticks[0]
    frame = r.render(scene, settings=s)
    during = ticks[0] - before
    done.set()
    t.join()
    # A render holding the GIL would let the counter tick only at the interpreter's switch interval
    # before it began; released, it ticks about once a millisecond of the render's wall time.
    assert during >= max(3, int(frame.wall_ms / 10)), (during, frame.wall_ms)


def test_two_threads_rendering_with_one_renderer_get_their_own_images():
    r = ssrlab.Renderer("cpu")
    scene = ssrlab.scenes.box_stack()
    a, b = ssrlab.Settings(width=96, height=64, method="linear"), ssrlab.Settings(width=96, height=64, method="hiz")
    alone = {k: r.render(scene, settings=s).color.copy() for k, s in (("a", a), ("b", b))}
    got, errors = {"a": [], "b": []}, []

    def work(key, s):
        try:
            for _ in range(4):
                got[key].append(r.render(scene, settings=s).color.copy())
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    threads = [threading.Thread(target=work, args=kv) for kv in (("a", a), ("b", b))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    for key in ("a", "b"):
        assert len(got[key]) == 4
        for image in got[key]:
            assert np.array_equal(image, alone[key])
