"""The run-time-against-error benchmark: grids, sweeps, Pareto fronts, result files, sweep
files, the command line and dask workers. Small images, the thesis's ground truth as the
reference; nothing here depends on timing values."""

import concurrent.futures
import json
import math
import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import ssrlab
from ssrlab import bench, metrics
from ssrlab.reference import THESIS_GROUND_TRUTH
from conftest import REPO

# Peeled (conftest.small's reason): a row's timing columns are those of the construction it ran,
# which 'auto' could choose differently in the test's own renderer on a GPU.
SMALL = {"width": 64, "height": 48, "shadow_map_size": 256, "deep_gbuffer": "peel"}
# The thesis's ground-truth settings as one grid point: scored against the thesis reference
# of the same view, it is the reference itself.
LAYERS = [1, 2, 4, 8, THESIS_GROUND_TRUTH["layers"]]
RAYS = [1, THESIS_GROUND_TRUTH["rays_per_pixel"]]
LOW_VIEW = {"name": "low", "position": [1.0, 0.8, 5.0], "target": [0.0, 0.5, -5.0]}

# Columns every row has, whatever the configuration (gpu_<pass>_ms ones depend on the passes).
ROW_KEYS = {
    "index", "scene", "scene_spec", "view", "reference", "reference_rays", "reference_rays_per_pixel", "repeats",
    "warmup", "time_frame_ms", "time_reflections_ms", "wall_ms", *metrics.METRIC_KEYS, "reflective_pixels",
    "mean_fetches", "gpu_total_ms", "gpu_deep_gbuffer_ms", "gpu_lighting_ms", "gpu_composite_ms", "device",
    "gl_renderer", "gl_version", "worker", "timestamp", "ssrlab_version", "git_revision",
    *(bench.SETTINGS_PREFIX + f for f in bench.SETTINGS_FIELDS),
}


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """A reference cache of this module's own (never the user's ~/.cache)."""
    return tmp_path_factory.mktemp("references")


@pytest.fixture(scope="module")
def layer_rows(cache):
    """box_stack, two views, layers x rays per pixel (the thesis's settings among them)."""
    return bench.sweep({"layers": LAYERS, "rays_per_pixel": RAYS}, ["box_stack"], views=["default", LOW_VIEW],
                       base={**SMALL, "stride": 1.0}, repeats=1, warmup=1, reference="thesis", progress=False,
                       cache_folder=cache)


# -- grids --------------------------------------------------------------------------------------
def test_expand_grid_is_the_cartesian_product_in_stable_order():
    points = bench.expand_grid({"layers": [1, 2], "method": ["linear", "hiz"], "stride": [4.0]})
    assert points == [
        {"layers": 1, "method": "linear", "stride": 4.0}, {"layers": 1, "method": "hiz", "stride": 4.0},
        {"layers": 2, "method": "linear", "stride": 4.0}, {"layers": 2, "method": "hiz", "stride": 4.0},
    ]
    assert bench.expand_grid({}) == [{}]
    assert bench.expand_grid({"layers": (v for v in (3, 5))}) == [{"layers": 3}, {"layers": 5}]


@pytest.mark.parametrize("grid, match", [
    ({"layerz": [1, 2]}, r"grid key 'layerz' is not a Settings field \(did you mean 'layers'\?\)"),
    ({"layers": 4}, r"grid\['layers'\] must be a non-empty list"),
    ({"method": "hiz"}, r"grid\['method'\] must be a non-empty list"),
    ({"layers": []}, r"grid\['layers'\] must be a non-empty list"),
    ({"layers": [1, 99]}, r"grid\['layers'\]: Settings.layers must be in"),
    ({"method": ["linear", "cone"]}, r"grid\['method'\]: Settings.method must be one of"),
    ([("layers", [1])], "grid must be a dict"),
])
def test_expand_grid_rejects_bad_grids(grid, match):
    with pytest.raises(ValueError, match=match):
        bench.expand_grid(grid)


# -- Pareto front -------------------------------------------------------------------------------------
def test_pareto_front_of_hand_made_rows():
    rows = [
        {"id": "a", "time_frame_ms": 1.0, "thesis_error": 5.0},
        {"id": "b", "time_frame_ms": 2.0, "thesis_error": 3.0},
        {"id": "c", "time_frame_ms": 2.0, "thesis_error": 4.0},   # as fast as b, worse
        {"id": "d", "time_frame_ms": 3.0, "thesis_error": 3.0},   # slower than b, no better
        {"id": "e", "time_frame_ms": 4.0, "thesis_error": 1.0},
        {"id": "f", "time_frame_ms": 0.5, "thesis_error": 9.0},
        {"id": "g", "time_frame_ms": None, "thesis_error": 0.1},  # no time: left out
        {"id": "h", "time_frame_ms": 0.1, "thesis_error": math.nan},
        {"id": "i", "time_frame_ms": 4.0, "thesis_error": 1.0},   # a duplicate of e: the first is kept
    ]
    assert [r["id"] for r in bench.pareto_front(rows)] == ["f", "a", "b", "e"]
    # Other columns: time_reflections_ms makes c the fastest.
    for r, t in zip(rows, [5, 6, 0.5, 7, 8, 9, None, 1, 8]):
        r["time_reflections_ms"] = t
    assert [r["id"] for r in bench.pareto_front(rows, time_key="time_reflections_ms")] == ["c", "b", "e"]
    with pytest.raises(ValueError, match="error_key='psnr'"):
        bench.pareto_front(rows, error_key="psnr")


# -- sweeps ---------------------------------------------------------------------------------------------
def test_sweep_rows_have_every_documented_key_and_finite_numbers(layer_rows, renderer):
    assert len(layer_rows) == 2 * len(LAYERS) * len(RAYS)
    points = bench.expand_grid({"layers": LAYERS, "rays_per_pixel": RAYS})
    for i, row in enumerate(layer_rows):
        missing = ROW_KEYS - set(row)
        assert not missing, f"row {i} lacks {sorted(missing)}"
        assert row["index"] == i and row["view"] == ("default" if i < len(points) else "low")
        point = points[i % len(points)]
        assert (row["s_layers"], row["s_rays_per_pixel"]) == (point["layers"], point["rays_per_pixel"])
        assert row["s_width"] == SMALL["width"] and row["s_stride"] == 1.0
        assert row["scene"] == "box_stack" and json.loads(row["scene_spec"]) == "box_stack"
        assert row["reference"] == "thesis" and row["reference_rays_per_pixel"] == THESIS_GROUND_TRUTH["rays_per_pixel"]
        for key, value in row.items():
            if isinstance(value, float):
                assert math.isfinite(value), f"row {i}: {key} = {value}"
        assert 0 < row["reflective_pixels"] < SMALL["width"] * SMALL["height"]
        assert row["mean_fetches"] > 0
        assert row["time_frame_ms"] == row["gpu_total_ms"]
        # repeats=1: the median of one sum is the sum of the passes.
        assert row["time_reflections_ms"] == pytest.approx(row["gpu_trace_linear_ms"] + row["gpu_resolve_ms"])
        assert row["ssrlab_version"] == ssrlab.__version__ and row["git_revision"]
        assert row["gl_renderer"] and row["device"] in ("cpu", "gpu")
    # A column for every timing of the frame, and no other.
    first = layer_rows[0]
    frame = renderer.render(ssrlab.scenes.box_stack(), settings=ssrlab.Settings.from_dict(
        {k[len(bench.SETTINGS_PREFIX):]: v for k, v in first.items() if k.startswith(bench.SETTINGS_PREFIX)}))
    expected = {"gpu_" + k.replace(".", "_") + "_ms" for k in frame.timings}
    assert {k for k in first if k.startswith("gpu_") and k.endswith("_ms")} == expected
    # ... each with its spread over the repeats: min, max, and no IQR from a single repeat.
    assert {k for k in first if k.startswith("gpu_")} == {c + s for c in expected for s in ("", "_min", "_max",
                                                                                              "_iqr")}
    for c in [*expected, "time_frame_ms", "time_reflections_ms", "wall_ms"]:
        assert first[c + "_min"] == first[c] == first[c + "_max"] and first[c + "_iqr"] is None


def test_the_reference_settings_score_zero_error_in_every_view(layer_rows):
    at_reference = [r for r in layer_rows if r["s_layers"] == THESIS_GROUND_TRUTH["layers"]
                    and r["s_rays_per_pixel"] == THESIS_GROUND_TRUTH["rays_per_pixel"]]
    assert [r["view"] for r in at_reference] == ["default", "low"]
    for r in at_reference:
        assert r["thesis_error"] == 0.0 and r["thesis_error_reflective"] == 0.0 and r["rmse"] == 0.0
        assert r["psnr"] == metrics.PSNR_CAP_DB
    # ... and nothing else does: the metrics can tell configurations apart.
    others = [r for r in layer_rows if r not in at_reference]
    assert all(r["thesis_error"] > 0 for r in others)


def test_more_layers_do_not_increase_the_error_on_box_stack(layer_rows):
    for view in ("default", "low"):
        for rays in RAYS:
            errors = [r["thesis_error_reflective"] for r in layer_rows
                      if r["view"] == view and r["s_rays_per_pixel"] == rays]
            assert len(errors) == len(LAYERS)
            assert all(b <= a for a, b in zip(errors, errors[1:])), f"{view}, {rays} rays: {errors}"
            assert errors[-1] < errors[0], f"{view}, {rays} rays: layers must matter on box_stack: {errors}"


def test_a_view_renders_from_its_own_camera(layer_rows):
    default = [r["thesis_error"] for r in layer_rows if r["view"] == "default"]
    low = [r["thesis_error"] for r in layer_rows if r["view"] == "low"]
    assert default != low


def test_sweep_checks_its_arguments_before_rendering(cache):
    ok = dict(grid={"layers": [1]}, scenes=["box_stack"], reference="thesis", progress=False, cache_folder=cache)
    cases = [
        (dict(scenes="box_stack"), "scenes must be a non-empty list"),
        (dict(scenes=["cathedral"]), r"scenes\[0\]: unknown scene 'cathedral'"),
        (dict(scenes=[{"name": "box_stack", "colour": "red"}]), r"scenes\[0\]: scene 'box_stack' has no option"),
        (dict(scenes=[{"with_suzanne": True}]), r"scenes\[0\]: a scene dict needs a 'name'"),
        (dict(views=["default", {"name": "x", "position": [0, 1], "target": [0, 0, 0]}]),
         r"views\[1\]: position must be 3"),
        (dict(views=[{"name": "x", "position": [0, 1, 2], "target": [0, 0, 0], "zoom": 2}]),
         r"views\[0\]: unknown view key\(s\) zoom"),
        (dict(views=[{"name": "x", "target": [0, 0, 0]}]), r"views\[0\]: a view dict needs 'position'"),
        (dict(views=["default", "default"]), "distinct names"),
        (dict(base={"layers": 0}), "base: Settings.layers"),
        (dict(base={"colour": 1}), "base: unknown Settings field"),
        (dict(grid={"layers": [1, 2]}, base={"hiz_start_level": 99}), "Settings.hiz_start_level"),
        (dict(repeats=0), "repeats must be an integer >= 1"),
        (dict(warmup=-1), "warmup must be an integer >= 0"),
        (dict(reference="best"), "reference must be one of"),
        (dict(reference_rays=0), "reference_rays must be"),
        (dict(reference_rays=64), "reference_rays applies to the converged reference only"),
        (dict(device="tpu"), "device must be"),
        (dict(executor=object()), "executor must have a submit"),
    ]
    for change, match in cases:
        with pytest.raises(ValueError, match=match):
            bench.sweep(**{**ok, **change})
    with pytest.raises(FileNotFoundError, match="nowhere.glb"):
        bench.sweep(**{**ok, "scenes": ["nowhere.glb"]})


def test_a_thread_pool_worker_opens_its_own_context_and_matches_in_process(cache, renderer):
    kw = dict(grid={"method": ["linear", "hiz", "off"]}, scenes=["mirror_test"], base=SMALL, repeats=1, warmup=0,
              reference="thesis", progress=False, cache_folder=cache)
    here = bench.sweep(**kw)
    with concurrent.futures.ThreadPoolExecutor(max_workers=1) as pool:
        threaded = bench.sweep(**kw, executor=pool)
        pool_thread = pool.submit(threading.get_ident).result()
    opened_by = [r["thread"] for r in bench.opened_renderers()]
    assert opened_by.count(pool_thread) == 1, "the pool's thread opens one Renderer of its own"
    assert threading.get_ident() in opened_by
    assert _deterministic(here) == _deterministic(threaded)
    off = here[2]
    assert off["s_method"] == "off" and off["mean_fetches"] is None and off["time_reflections_ms"] == 0.0


def _deterministic(rows):
    return [{k: v for k, v in r.items() if not bench.is_volatile(k)} for r in rows]


# -- results -----------------------------------------------------------------------------------------------
def test_write_results_files_and_no_overwriting(layer_rows, tmp_path):
    files = bench.write_results(layer_rows, tmp_path / "out", error_key="thesis_error_reflective")
    names = sorted(p.name for p in files)
    # Two settings vary (layers and rays per pixel): no plot against a single one.
    assert names == sorted(["rows.csv", "rows.json", "pareto.csv", "error_vs_time.png"])
    data = json.loads((tmp_path / "out" / "rows.json").read_text())
    assert _deterministic(data) == _deterministic(layer_rows)
    lines = (tmp_path / "out" / "rows.csv").read_text().splitlines()
    assert len(lines) == 1 + len(layer_rows) and "thesis_error_reflective" in lines[0].split(",")
    pareto = (tmp_path / "out" / "pareto.csv").read_text().splitlines()
    fronts = bench.pareto_fronts(layer_rows, error_key="thesis_error_reflective")
    assert list(fronts) == [("box_stack", "default"), ("box_stack", "low")]
    assert len(pareto) == 1 + sum(len(f) for f in fronts.values())
    # ssrlab replaces its own files, never someone else's.
    bench.write_results(layer_rows, tmp_path / "out")
    (tmp_path / "out" / "pareto.csv").write_text("edited by hand")
    with pytest.raises(FileExistsError, match="pareto.csv"):
        bench.write_results(layer_rows, tmp_path / "out")
    assert (tmp_path / "out" / "pareto.csv").read_text() == "edited by hand"
    with pytest.raises(ValueError, match="time_key='seconds'"):
        bench.write_results(layer_rows, tmp_path / "other", time_key="seconds")


def _rows_2x2x2():
    """Rows of a 2 x 2 x 2 sweep (method, rays, glossy) with made-up times and errors: on the front,
    by construction, rows 0 (fastest), 3 and 6 (least error); every other row is beaten by one of
    them."""
    import itertools

    times = [10.0, 11.0, 13.0, 12.0, 30.0, 31.0, 40.0, 41.0]
    errors = [0.30, 0.35, 0.40, 0.20, 0.25, 0.33, 0.10, 0.12]
    rows = []
    for i, (method, rays, glossy) in enumerate(itertools.product(["linear", "hiz"], [1, 4], ["stochastic", "cone"])):
        rows.append({"index": i, "scene": "box_stack", "view": "default", "gl_renderer": "llvmpipe", "repeats": 3,
                     "s_method": method, "s_rays_per_pixel": rays, "s_glossy": glossy, "s_width": 96,
                     "time_frame_ms": times[i], "time_frame_ms_min": times[i] - 1.0,
                     "time_frame_ms_max": times[i] + 2.0, "thesis_error": errors[i]})
    return rows


def test_the_error_against_time_plot_names_every_point_and_draws_its_time_spread():
    from matplotlib.collections import LineCollection

    rows = _rows_2x2x2()
    labels = bench.point_labels(rows)
    assert labels[0] == "method=linear, rays_per_pixel=1, glossy=stochastic"
    assert labels[5] == "method=hiz, rays_per_pixel=1, glossy=cone"
    assert len(set(labels)) == 8  # s_width is the same everywhere: not named
    assert bench.technique_settings(rows) == ["method", "glossy"]  # rays are a parameter, not a technique
    groups = bench.technique_groups(rows)
    assert groups[3] == "method=linear, glossy=cone" and len(set(groups)) == 4
    assert [r["index"] for r in bench.pareto_front(rows)] == [0, 3, 6]

    fig = bench.plot_error_vs_time(rows)
    ax, side = fig.axes
    legend = [t.get_text() for t in side.get_legend().get_texts()]
    assert legend == ["method=linear, glossy=stochastic", "method=linear, glossy=cone",
                      "method=hiz, glossy=stochastic", "method=hiz, glossy=cone", "Pareto front (labelled)"]
    texts = [t.get_text() for t in ax.texts]
    # The front labelled (long labels wrapped over lines).
    assert sorted(t.replace("\n", " ") for t in texts if "=" in t) == sorted(labels[i] for i in (0, 3, 6))
    assert sorted(t for t in texts if "=" not in t) == [str(i) for i in range(8)]  # every point numbered
    key = "\n".join(t.get_text() for t in side.texts)
    for i, label in enumerate(labels):  # every point named in the key, the front's marked
        assert f"{i}: {label}" + ("  (front)" if i in (0, 3, 6) else "") in key.splitlines()
    # Each point's time spread: a bar from its fastest to its slowest repeat, at its error.
    bars = sorted((min(x for x, _ in seg), max(x for x, _ in seg), seg[0][1])
                  for c in ax.collections if isinstance(c, LineCollection) for seg in c.get_segments())
    assert bars == sorted((r["time_frame_ms_min"], r["time_frame_ms_max"], r["thesis_error"]) for r in rows)
    # One colour per technique group.
    colours = {}
    for c, g in zip([c for c in ax.collections if not isinstance(c, LineCollection)], groups):
        colours.setdefault(g, set()).add(tuple(c.get_facecolor()[0]))
    assert all(len(v) == 1 for v in colours.values()) and len({next(iter(v)) for v in colours.values()}) == 4
    png = bench.SweepRows(rows)._repr_png_()  # how a notebook shows a sweep's rows
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def test_points_of_several_scenes_are_told_apart_by_marker_and_name():
    rows = _rows_2x2x2()[:4] + [{**r, "scene": "hall", "index": r["index"] + 4} for r in _rows_2x2x2()[:4]]
    labels = bench.point_labels(rows)
    assert labels[4] == "scene=hall, rays_per_pixel=1, glossy=stochastic"  # method is linear throughout
    fig = bench.plot_error_vs_time(rows)
    legend = [t.get_text() for t in fig.axes[1].get_legend().get_texts()]
    assert legend == ["glossy=stochastic", "glossy=cone", "box_stack", "hall", "Pareto front of each (labelled)"]
    markers = {tuple(c.get_paths()[0].vertices.round(3).ravel()) for c in fig.axes[0].collections
               if type(c).__name__ == "PathCollection"}
    assert len(markers) == 2  # one marker per scene


# -- sweep files ----------------------------------------------------------------------------------------
def test_load_sweep_toml_and_json(tmp_path):
    toml = tmp_path / "s.toml"
    toml.write_text('scenes = ["hall", {name = "spheres_and_boxes", with_suzanne = true}]\n'
                    'views = ["default", {name = "side", position = [4, 2, 4], target = [0, 1, 0], fov_y = 40}]\n'
                    'repeats = 3\nreference = "thesis"\n[base]\nwidth = 80\n[grid]\nlayers = [1, 2]\n')
    config = bench.load_sweep(toml)
    assert config == {"scenes": ["hall", {"name": "spheres_and_boxes", "with_suzanne": True}],
                      "views": ["default", {"name": "side", "position": [4, 2, 4], "target": [0, 1, 0], "fov_y": 40}],
                      "repeats": 3, "reference": "thesis", "base": {"width": 80}, "grid": {"layers": [1, 2]}}
    as_json = tmp_path / "s.json"
    as_json.write_text(json.dumps(config))
    assert bench.load_sweep(as_json) == config
    plan = bench.plan_sweep(config["grid"], config["scenes"], config["views"], config["base"])
    assert len(plan) == 2 * 2 * 2 and plan[-1]["view_name"] == "side" and plan[-1]["settings"]["layers"] == 2


@pytest.mark.parametrize("text, match", [
    ('scenes = ["hall"]\nrepeat = 3\n', "unknown key.*repeat"),
    ('views = ["default"]\n', "'scenes' is required"),
    ('scenes = ["hall"]\ngrid = 3\n', "'grid' must be a table"),
    ('scenes = ["hall"\n', "s.toml"),
])
def test_load_sweep_rejects_bad_files(tmp_path, text, match):
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(ValueError, match=match):
        bench.load_sweep(path)


def test_load_sweep_finds_a_gltf_beside_the_sweep_file(tmp_path):
    ssrlab.scenes.mirror_test().save(tmp_path / "mirror.glb")
    (tmp_path / "s.toml").write_text('scenes = ["mirror.glb"]\n')
    scenes = bench.load_sweep(tmp_path / "s.toml")["scenes"]
    assert scenes == [str((tmp_path / "mirror.glb").resolve())]
    assert bench.plan_sweep({}, scenes)[0]["scene_spec"] == scenes[0]


@pytest.mark.parametrize("path", sorted((REPO / "benchmarks" / "sweeps").glob("*.toml")), ids=lambda p: p.name)
def test_example_sweep_files_are_valid(path):
    config = bench.load_sweep(path)
    plan = bench.plan_sweep(config["grid"], config["scenes"], config.get("views"), config.get("base"))
    expected = len(config["scenes"]) * len(config.get("views") or ["default"]) * math.prod(
        len(v) for v in config["grid"].values())
    assert len(plan) == expected > 0


def test_spread_of_repeats():
    assert bench.spread([3.0, 1.0, 2.0, 10.0]) == {"min": 1.0, "median": 2.5, "max": 10.0,
                                                   "iqr": pytest.approx(float(np.percentile([1, 2, 3, 10], 75)
                                                                              - np.percentile([1, 2, 3, 10], 25)))}
    assert bench.spread([4.0])["iqr"] is None
    with pytest.raises(ValueError):
        bench.spread([])


def test_timed_repeats_give_min_median_max_and_iqr(cache):
    row, = bench.sweep({}, ["mirror_test"], base=SMALL, repeats=4, warmup=1, reference="thesis", progress=False,
                       cache_folder=cache)
    for c in [k for k in row if k.startswith("gpu_") and k.endswith("_ms")] + ["time_frame_ms", "wall_ms"]:
        assert row[c + "_min"] <= row[c] <= row[c + "_max"], c
        assert 0.0 <= row[c + "_iqr"] <= row[c + "_max"] - row[c + "_min"] + 1e-9, c
        assert bench.is_volatile(c + "_iqr") and bench.is_volatile(c + "_min")
    assert not bench.is_volatile("thesis_error") and not bench.is_volatile("s_max_steps")


def test_pareto_fronts_never_mix_scenes_or_views():
    rows = [
        {"scene": "a", "view": "default", "time_frame_ms": 1.0, "thesis_error": 5.0},
        {"scene": "a", "view": "default", "time_frame_ms": 2.0, "thesis_error": 4.0},
        {"scene": "b", "view": "default", "time_frame_ms": 3.0, "thesis_error": 1.0},  # would dominate a's
        {"scene": "b", "view": "default", "time_frame_ms": 0.5, "thesis_error": 9.0},
        {"scene": "a", "view": "side", "time_frame_ms": 9.0, "thesis_error": 9.0},
    ]
    fronts = bench.pareto_fronts(rows)
    assert list(fronts) == [("a", "default"), ("b", "default"), ("a", "side")]
    assert [r["time_frame_ms"] for r in fronts[("a", "default")]] == [1.0, 2.0]
    assert [r["time_frame_ms"] for r in fronts[("b", "default")]] == [0.5, 3.0]
    with pytest.raises(ValueError, match="use pareto_fronts"):
        bench.pareto_front(rows)


def test_timing_workers_are_limited_by_cores(monkeypatch):
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    monkeypatch.delenv("LP_NUM_THREADS", raising=False)
    assert bench.max_timing_workers("cpu") == 1 and bench.max_timing_workers("auto") == 1
    with pytest.raises(ValueError, match="--timing-workers"):
        bench.check_timing_workers(2, "cpu")
    bench.check_timing_workers(1, "cpu")
    monkeypatch.setenv("LP_NUM_THREADS", "1")  # one rasteriser thread per render: two fit on two cores
    assert bench.max_timing_workers("cpu") == 2 and bench.max_timing_workers("gpu") == 1
    bench.check_timing_workers(2, "cpu")
    with pytest.raises(ValueError, match="one GPU"):
        bench.check_timing_workers(2, "gpu")


# -- the command line -----------------------------------------------------------------------------------
def run_cli(*args, cache):
    env = {**os.environ, "SSRLAB_CACHE": str(cache)}
    return subprocess.run([sys.executable, "-m", "ssrlab", *args], capture_output=True, text=True, cwd=REPO, env=env)


def test_cli_bench_writes_rows_pareto_and_plots(tmp_path, cache):
    out = tmp_path / "smoke"
    r = run_cli("bench", "benchmarks/sweeps/smoke.toml", "--out", str(out), cache=cache)
    assert r.returncode == 0, r.stderr
    config = bench.load_sweep(REPO / "benchmarks" / "sweeps" / "smoke.toml")
    (key, values), = config["grid"].items()
    names = {p.name for p in out.iterdir()}
    assert {"rows.csv", "rows.json", "pareto.csv", "error_vs_time.png", f"{key}.png"} <= names
    rows = json.loads((out / "rows.json").read_text())
    assert [row[f"s_{key}"] for row in rows] == values
    assert "Pareto front" in r.stdout and f"wrote {out / 'rows.csv'}" in r.stdout
    for png in ("error_vs_time.png", f"{key}.png"):
        pixels, _ = ssrlab.io.read_image(out / png)
        assert pixels.shape[0] > 100 and pixels.shape[1] > 100, png
        assert pixels.std() > 0.05, f"{png} is blank"
        assert len(np.unique(pixels.reshape(-1, pixels.shape[-1])[:, 0])) > 10, f"{png} has no content"
    # A second run replaces ssrlab's files; a user's file stops it.
    assert run_cli("bench", "benchmarks/sweeps/smoke.toml", "--out", str(out), cache=cache).returncode == 0
    (out / "rows.csv").write_text("mine")
    r = run_cli("bench", "benchmarks/sweeps/smoke.toml", "--out", str(out), cache=cache)
    assert r.returncode == 1 and "rows.csv exists and was changed" in r.stderr
    assert (out / "rows.csv").read_text() == "mine"


def test_cli_bench_refuses_timing_workers_and_missing_scene_files_before_a_cluster(tmp_path, cache):
    sweep = tmp_path / "s.toml"
    sweep.write_text('scenes = ["mirror_test"]\nrepeats = 1\nwarmup = 0\nreference = "thesis"\n'
                     '[base]\nwidth = 32\nheight = 24\n')
    env = {**os.environ, "SSRLAB_CACHE": str(cache)}
    env.pop("LP_NUM_THREADS", None)
    workers = (os.cpu_count() or 1) + 1  # more workers than cores: never timeable side by side
    r = subprocess.run([sys.executable, "-m", "ssrlab", "bench", str(sweep), "--executor", "dask", "--workers",
                        str(workers), "--out", str(tmp_path / "out")], capture_output=True, text=True, env=env)
    assert r.returncode == 1 and "--timing-workers" in r.stderr and "dask:" not in r.stderr
    assert not (tmp_path / "out").exists()
    # A scene file that does not exist is named before anything starts.
    missing = tmp_path / "m.toml"
    missing.write_text('scenes = ["mirror_test", "/nowhere/model.glb"]\n')
    r = subprocess.run([sys.executable, "-m", "ssrlab", "bench", str(missing), "--executor", "dask", "--workers",
                        "1", "--out", str(tmp_path / "out")], capture_output=True, text=True, env=env)
    assert r.returncode == 1 and "/nowhere/model.glb" in r.stderr and "not found" in r.stderr
    assert "dask:" not in r.stderr, "no cluster was started"


def test_cli_bench_rejects_a_bad_sweep_file(tmp_path, cache):
    bad = tmp_path / "bad.toml"
    bad.write_text('scenes = ["box_stack"]\nlayers = [1, 2]\n')
    r = run_cli("bench", str(bad), "--out", str(tmp_path / "out"), cache=cache)
    assert r.returncode == 1 and "unknown key(s) layers" in r.stderr
    assert not (tmp_path / "out").exists()


# -- dask ---------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def dask_client():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None)
    try:
        client = distributed.Client(cluster)
        try:
            yield client
        finally:
            client.close()
    finally:
        cluster.close()


def test_dask_workers_give_the_same_rows_as_in_process(dask_client, cache):
    kw = dict(grid={"layers": [1, 2], "method": ["linear", "hiz"]},
              scenes=["box_stack", {"name": "spheres_and_boxes", "count": 6}], views=["default", LOW_VIEW],
              base=SMALL, repeats=2, warmup=1, reference="thesis", progress=False, cache_folder=cache)
    here = bench.sweep(**kw)
    distributed = bench.sweep(**kw, executor=dask_client)
    assert len(distributed) == len(here) == 16
    # Everything but times, timestamps and workers, the metrics included, exactly.
    assert _deterministic(distributed) == _deterministic(here)
    # Each worker process opened an EGL context of its own, and only the workers rendered.
    opened = dask_client.run(bench.opened_renderers)
    worker_pids = {entry["pid"] for entries in opened.values() for entry in entries}
    row_pids = {int(r["worker"].rsplit(":", 1)[1]) for r in distributed}
    assert os.getpid() not in row_pids and row_pids <= worker_pids
    for pid in row_pids:  # one context per worker process, reused by all its configurations
        assert [e["pid"] for entries in opened.values() for e in entries].count(pid) == 1


def test_sweep_against_the_converged_reference(tmp_path):
    """On the mirror, SSR against the traced truth: small error where rays are traced, and far
    more without reflections; the reference is computed once and then read from the cache."""
    rows = bench.sweep({"method": ["hiz", "off"]}, ["mirror_test"], base=dict(SMALL, sampling="mirror"),
                       repeats=1, warmup=0, reference="converged", reference_rays=1, progress=False,
                       cache_folder=tmp_path)
    hiz, off = rows
    assert hiz["reference"] == "converged" and hiz["reflective_pixels"] > 0
    assert hiz["thesis_error_reflective"] < 0.25 * off["thesis_error_reflective"]
    assert len(list(tmp_path.rglob("*.npz"))) == 1
