"""Renderer.raster_floor, the device's floors under the deep G-buffer: every floor timed on every
repeat (finite, positive; no speed is asserted), and what it counts agrees with itself through
different paths of the device (shader atomics, occlusion queries, the targets read back) and with
the constructions' own counts of the same scene (a peeled layer's samples, the one-pass lists'
fragments), which are counted by other code."""

import math
import re
import subprocess
import sys

import pytest

import ssrlab
from conftest import REPO, benchmark_script

FLOORS = {"depth", "gbuffer", "id", "append", "append_list", "stores", "clear.depth", "clear.gbuffer",
          "clear.id_texture", "clear.id_compute", "clear.counters", "clear.heads", "clear.compute_colour"}
SIZE = dict(width=160, height=90)


@pytest.fixture(scope="module")
def hall():
    return ssrlab.scenes.load("hall")


@pytest.fixture(scope="module")
def hall_floor(renderer, hall):
    return renderer.raster_floor(hall, repeats=3, **SIZE)


def test_every_floor_is_timed_on_every_repeat(hall_floor):
    assert set(hall_floor.ms) == FLOORS
    for name, ms in hall_floor.ms.items():
        assert len(ms) == 3 and all(math.isfinite(t) and t > 0.0 for t in ms), (name, ms)
    assert hall_floor.median("depth") == sorted(hall_floor.ms["depth"])[1]
    with pytest.raises(KeyError, match="no floor 'peel'"):
        hall_floor.median("peel")


def test_counts_agree_across_the_devices_paths(hall_floor):
    c = hall_floor.counts
    # Every fragment: per-pixel atomic counters (summed on the CPU) = the occlusion query of the same
    # draw without depth test = what the timed append and linked-list draws stored.
    assert c["fragments"] > 0
    assert c["fragments_rasterised"] == c["fragments"]
    assert c["fragments_appended"] == c["fragments"]
    assert c["fragments_listed"] == c["fragments"]
    # The depth + id draw keeps the depth-only draw's samples and covers the same pixels (read back
    # from the depth target and from the id target), which are the pixels any fragment reached.
    assert c["samples_id"] == c["samples_depth"]
    assert c["pixels_id"] == c["pixels_depth"] == c["pixels_with_fragments"]
    assert c["pixels_depth"] <= c["samples_depth"] <= c["fragments"]
    assert c["max_fragments_per_pixel"] >= 2  # hall's walls and floor lie behind its front objects
    assert c["triangles"] == ssrlab.scenes.load("hall").triangle_count


@pytest.mark.parametrize("culling", [False, True])
def test_counts_equal_the_constructions_own(renderer, culling):
    # spheres_and_boxes: closed objects, so culling removes about half the fragments.
    scene = ssrlab.scenes.load("spheres_and_boxes")
    floor = renderer.raster_floor(scene, repeats=1, backface_culling=culling, **SIZE)
    base = ssrlab.Settings(**SIZE, method="off", shadow_map_size=0, backface_culling=culling)
    # Peeling counts its first depth pass's samples (an occlusion query of the scene drawn in its
    # order, as the floor's depth draw), the attribute pass the pixels holding a sample (in a shader),
    # the one-pass lists every fragment they appended (a global counter).
    peeled = renderer.render(scene, settings=base.replace(layers=1, deep_gbuffer="peel"))
    assert peeled.layer_samples[0] == floor.counts["samples_depth"]
    visibility = renderer.render(scene, settings=base.replace(layers=1, deep_gbuffer="visibility"))
    assert visibility.layer_samples[0] == floor.counts["pixels_depth"]
    lists = renderer.render(scene, settings=base.replace(layers=8, deep_gbuffer="visibility_lists"))
    assert lists.stats["deep_gbuffer_method"] == "visibility_lists"
    assert lists.stats["deep_gbuffer_fragments"] == floor.counts["fragments"]
    if culling:
        unculled = renderer.raster_floor(scene, repeats=1, **SIZE)
        assert floor.counts["fragments"] < unculled.counts["fragments"]
        assert floor.counts["pixels_depth"] == unculled.counts["pixels_depth"]  # the front faces cover it all


@pytest.mark.parametrize("repeats", [0, 1001, 2.0, True])
def test_bad_repeats_are_refused(renderer, hall, repeats):
    with pytest.raises(ValueError, match="raster_floor: repeats"):
        renderer.raster_floor(hall, repeats=repeats, **SIZE)


def test_bad_settings_are_refused(renderer, hall):
    with pytest.raises(TypeError, match="settings must be an ssrlab.Settings"):
        renderer.raster_floor(hall, settings={"width": 64})
    with pytest.raises(ValueError, match="width"):
        renderer.raster_floor(hall, width=0, height=64, repeats=1)


def run_benchmark(name: str, *args: str) -> str:
    """A benchmark script's standard output, run as the script it is, on the device at hand."""
    r = subprocess.run([sys.executable, str(benchmark_script(name)), *args], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    return r.stdout


def table_rows(text: str, first: str) -> list[list[str]]:
    """The cells of every row of the Markdown tables in `text` whose header starts with `first`."""
    rows, inside = [], False
    for line in text.splitlines():
        if not line.startswith("|"):
            inside = False
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[0] == first:
            inside = True
        elif inside and not set(cells[0]) <= {"-"}:
            rows.append(cells)
    return rows


def test_raster_floor_script_prints_every_floor_and_each_constructions_layer():
    text = run_benchmark("raster_floor", "--width", "64", "--height", "36", "--repeats", "3")
    # The floors' table, rendered from the records: median [25th-75th percentile] ms of each floor.
    timed = {row[0]: row[1] for row in table_rows(text, "floor") if re.fullmatch(r"[0-9.]+ \[[0-9.]+-[0-9.]+\]", row[1])}
    assert set(timed) == FLOORS
    built = {row[0]: float(row[1]) for row in table_rows(text, "construction")}
    assert set(built) == {"peel", "lists", "visibility", "visibility_lists"} and all(v > 0 for v in built.values())


def test_deep_gbuffer_script_sets_each_construction_beside_its_floor_and_judges_the_goals():
    text = run_benchmark("deep_gbuffer", "--width", "64", "--height", "36", "--repeats", "3", "--layers", "1", "8",
                         "--scenes", "hall")
    # A row names what was built after an arrow where it differs ('visibility_lists' at one layer:
    # 'visibility'); its cells come from the records: ms as median [25th-75th percentile].
    rows = table_rows(text, "method")
    assert {(r[0].split("->")[0], r[1]) for r in rows} == {(m, l) for m in ("peel", "lists", "visibility",
                                                                             "visibility_lists") for l in ("1", "8")}
    for r in rows:
        ms, floor_ms, x_floor = float(r[3].split()[0]), float(r[5]), float(r[6])
        assert ms > 0 and floor_ms > 0 and x_floor > 0, r
    # hall's goals, against each construction's own floor: 8 layers, and one visibility layer, each
    # with a verdict (the size is not the goals', so the script says the verdicts are this run's) and
    # the ratio to one peeled layer beside it, not judged.
    assert "this run: " in text
    verdicts = re.findall(r"^    (peel|lists|visibility|visibility_lists)(?:->\w+)? +[0-9.]+x \[[0-9.]+-[0-9.]+\]: (.+)"
                          r"   \(x (?:one peeled layer|peeling's layer) [0-9.]+x \[[0-9.]+-[0-9.]+\]\)$", text, re.M)
    assert len(verdicts) == 4 + 2
    assert all(v in ("met", "not met") or v.startswith("undecided") for _, v in verdicts), verdicts


def test_layers_vs_rays_script_judges_the_fastest_construction():
    text = run_benchmark("layers_vs_rays", "--width", "64", "--height", "36", "--repeats", "3", "--reference-rays",
                         "4", "--scenes", "box_stack", "--deep-gbuffer", "visibility", "--device", "auto")
    rows = table_rows(text, "series")
    assert ["layers (visibility)", "2 layers", "visibility"] in [r[:3] for r in rows]
    fastest = [r[1] for r in rows if r[0] == "layers (fastest)" and r[2] in ("peel", "visibility")]
    assert fastest == ["2 layers", "3 layers", "4 layers"] * (2 if "by cpu time" in text else 1)
    assert "layers by the fastest construction: " in text and "layers by peeling: " in text


def test_construction_switch_times_each_construction_alone_and_after_others():
    text = run_benchmark("construction_switch", "--width", "48", "--height", "32", "--repeats", "1")
    rows = table_rows(text, "scene")
    assert len(rows) == 12 and {r[0] for r in rows} == {"hall"}, text
    assert {r[1].split()[0] for r in rows} == {"peel", "visibility"} and {r[2] for r in rows} == {"released", "kept"}
    # Each construction's first part (named under the table) within its whole construction's time.
    assert "first_part: peel: depth_peel.setup, visibility: visibility_buffer" in text
    assert all(0 < float(r[4]) <= float(r[3]) for r in rows), rows
