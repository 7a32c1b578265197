"""What benchmarks/timing/viewer_latency.py measures with (ssrlab.viewer.latency): how a frame the
page showed is matched with the frame the server sent and split into parts, and the floor (the
page's own path with nothing to render) at a smoke size in the real browser."""

from __future__ import annotations

import argparse
import math

import pytest

from viewer_page import require_browser


@pytest.fixture(scope="module")
def latency():
    from ssrlab.viewer import latency

    return latency


def sent_frame(w, h, request, start, end, view, sent):
    return {"width": w, "height": h, "times": {"request": request, "render_start": start, "render_end": end,
                                                "view": view, "sent": sent}}


def test_parts_of_a_matched_frame_add_up_to_its_way_to_the_screen(latency):
    # Seconds on the server, ms in the page (performance.timeOrigin + now()), as the hooks record.
    sent = [sent_frame(64, 36, 10.000, 10.004, 10.050, 10.056, 10.058),
            sent_frame(96, 54, 10.100, 10.100, 10.140, 10.146, 10.149),  # replaced before it was sent
            sent_frame(128, 72, 10.150, 10.160, 10.200, 10.205, 10.207)]
    frames = [{"received": 10062.0, "decoded": 10068.0, "displayed": 10090.0, "width": 64, "height": 36},
              {"received": 10215.0, "decoded": 10220.0, "displayed": 10245.0, "width": 128, "height": 72},
              {"received": 10300.0, "decoded": None, "displayed": None}]  # a probe image: no size
    events = [9980.0, 9990.0, 10130.0, 10145.0]
    rows = latency.matched_parts(sent, frames, events)
    assert len(rows["viewer_own"]) == 2
    first = {k: v[0] for k, v in rows.items()}
    assert first["event_to_server"] == pytest.approx(10.0)  # the last event before the request
    assert first["queue"] == pytest.approx(4.0) and first["render"] == pytest.approx(46.0)
    assert first["transport"] == pytest.approx(4.0) and first["display"] == pytest.approx(22.0)
    for i in range(2):
        parts = sum(rows[k][i] for k in ("event_to_server", "queue", "render", "view", "encode_send", "transport",
                                         "decode", "display"))
        assert parts == pytest.approx(rows["event_to_screen"][i])
        assert rows["viewer_own"][i] == pytest.approx(rows["event_to_screen"][i] - rows["render"][i])
    # The second frame the page got is the third sent (the next one of its size sent before it arrived).
    assert rows["render"][1] == pytest.approx(40.0) and rows["event_to_server"][1] == pytest.approx(5.0)


@pytest.mark.parametrize("frames", ("overlay",))
def test_the_floor_at_a_smoke_size(latency, frames, capsys):
    require_browser()
    args = argparse.Namespace(width=160, height=90, seconds=1.0, frames=frames, lossless=False)
    floor = latency.page_floor(args)
    out = capsys.readouterr().out
    assert "the floor: the viewer's own path with nothing to render, 160x90" in out
    if math.isnan(floor):  # a machine too loaded to answer ten cameras in a second says so
        assert "undecided" in out
    else:
        assert 0.0 < floor < 5000.0
        assert "viewer_own" in out and "event_to_server" in out
