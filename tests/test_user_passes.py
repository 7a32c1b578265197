"""User passes (ssrlab.UserPass): a technique in one GLSL file and a Python declaration, run,
checked, timed and scored like a built-in pass (docs/guide/your-first-technique.md)."""

import sys
from pathlib import Path

import numpy as np
import pytest

import ssrlab
from ssrlab import bench, scenes

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).with_name("data") / "user_passes"


def bilateral_filter():
    # The example as a user loads it (what a sweep file's user_passes names), not imported by path.
    return ssrlab.user_pass.load("examples/bilateral_filter/technique.py:bilateral_filter", ROOT)

SMALL = dict(width=96, height=64)
RAYS = ("rays.hit", "rays.sample", "rays.direction")


@pytest.fixture(scope="module")
def renderer():
    r = ssrlab.Renderer()
    r.register_pass(ssrlab.UserPass("hiz_copy", DATA / "hiz_copy.comp", "trace", reads=("hiz_trace",)))
    r.register_pass(bilateral_filter())
    return r


@pytest.mark.parametrize("extra", [dict(skip=False), dict(skip=True), dict(layers=2, rays_per_pixel=2)])
def test_a_user_trace_that_is_the_hiz_walk_equals_method_hiz_bit_for_bit(renderer, extra):
    scene = scenes.box_stack()
    s = ssrlab.Settings(**SMALL, method="hiz", sampling="vndf", **extra)
    built_in = renderer.render(scene, settings=s)
    user = renderer.render(scene, settings=s.replace(user_passes=("hiz_copy",)))
    assert "trace_hiz" in built_in.passes and "trace_hiz" not in user.passes
    assert user.passes == [("hiz_copy" if p == "trace_hiz" else p) for p in built_in.passes]
    for name in (*RAYS, "reflection", "color"):
        assert np.array_equal(built_in.read(name), user.read(name)), name
    stats = dict(user.stats)
    assert stats.pop("hiz_copy.groups") > 0  # the user pass named in the stats
    # (the second frame reuses the first's shadow maps: those counts differ by design)
    def same(st):
        return {k: v for k, v in st.items() if not k.startswith("shadow_maps_")}
    assert same(stats) == same(dict(built_in.stats))
    assert user.timings["hiz_copy"] > 0.0 and "trace_hiz" not in user.timings


def test_the_chain_lists_the_user_passes_in_their_stage(renderer):
    chain = renderer.chain(ssrlab.Settings(method="hiz", user_passes=("hiz_copy", "bilateral_filter")))
    names = chain.names
    assert names.index("hiz_copy") < names.index("resolve") == names.index("bilateral_filter") - 1
    p = chain[names.index("bilateral_filter")]
    assert p.inputs == ("reflection", "linear_depth", "gbuffer.normal") and "trace_hiz" not in names


def test_a_reflection_filter_runs_after_the_resolve_and_its_parameters_act(renderer):
    scene = scenes.box_stack(floor_roughness=0.4)
    s = ssrlab.Settings(**SMALL, method="hiz", sampling="vndf")
    plain = renderer.render(scene, settings=s)
    filtered = renderer.render(scene, settings=s.replace(user_passes=("bilateral_filter",)))
    off = renderer.render(scene, settings=s.replace(user_passes=("bilateral_filter",),
                                                    user_params={"bilateral_filter.radius": 0}))
    assert filtered.passes[filtered.passes.index("resolve") + 1] == "bilateral_filter"
    changed = np.abs(filtered.read("reflection") - plain.read("reflection")).max()
    assert changed > 0.01  # the filter rewrote the reflection the composite reads
    assert not np.array_equal(filtered.color, plain.color)
    assert np.array_equal(off.color, plain.color)  # radius 0: every pixel kept as traced
    assert filtered.stats["bilateral_filter.groups"] == 12 * 8


def test_parameters_are_validated_and_described(renderer):
    with pytest.raises(ValueError, match=r"bilateral_filter.radius.*\[0, 8\]"):
        ssrlab.Settings(user_params={"bilateral_filter.radius": 9})
    with pytest.raises(ValueError, match="must be an integer"):
        ssrlab.Settings().replace(**{"bilateral_filter.radius": 1.5})
    with pytest.raises(ValueError, match="has no parameter 'radus'.*radius"):
        ssrlab.Settings(user_params={"bilateral_filter.radus": 1})
    with pytest.raises(ValueError, match="no user pass 'nowhere'"):
        ssrlab.Settings(user_params={"nowhere.x": 1})
    s = ssrlab.Settings().replace(**{"bilateral_filter.sigma_depth": 0.1})
    assert s.user_params == {"bilateral_filter.sigma_depth": 0.1}
    assert "bilateral_filter.normal_power = 32.0" in ssrlab.Settings.describe()
    with pytest.raises(ValueError, match="Settings.user_passes names 'unknown'.*registered: hiz_copy"):
        renderer.render(scenes.box_stack(), settings=ssrlab.Settings(**SMALL, user_passes=("unknown",)))
    with pytest.raises(ValueError, match="Settings.method must be 'linear' or 'hiz'"):
        renderer.render(scenes.box_stack(), settings=ssrlab.Settings(**SMALL, method="bvh", user_passes=("hiz_copy",)))


def test_a_user_trace_on_the_linear_method_lacks_the_pyramid_and_says_so(renderer):
    with pytest.raises(RuntimeError, match="hiz_copy reads 'hiz_trace', which no earlier pass writes"):
        renderer.render(scenes.box_stack(), settings=ssrlab.Settings(**SMALL, method="linear",
                                                                    user_passes=("hiz_copy",)))


@pytest.mark.parametrize("kwargs, match", [
    (dict(stage="trace", reads=("reflection",)), r"reads 'reflection', which no pass before its stage 'trace' "
                                                 r"writes \('cone_trace' writes it later\)"),
    (dict(stage="trace", reads=("no_such",)), "reads 'no_such', which no pass writes"),
    (dict(stage="reflection_filter", writes=("reflection", "gbuffer.normal")),
     "writes 'gbuffer.normal', which pass 'depth_peel' owns"),
    (dict(stage="reflection_filter", writes=("mine",)), "writes 'mine', which no pass declares"),
    (dict(stage="reflection_filter", creates=(ssrlab.user_pass.Texture("lit"),)),
     "creates 'lit', which pass 'lighting' owns already"),
    (dict(stage="trace", writes=("rays.hit",)), "a trace pass writes exactly 'rays.hit', 'rays.sample'"),
    (dict(stage="reflection_filter", reads=("hiz_copy_missing",)), "reads 'hiz_copy_missing'"),
])
def test_bad_declarations_are_refused_at_registration_naming_the_resource(renderer, kwargs, match):
    p = ssrlab.UserPass("bad", DATA / "hiz_copy.comp", **kwargs)
    with pytest.raises(ValueError, match=match):
        renderer.register_pass(p)
    assert p.name not in renderer.user_passes


def test_bad_declarations_are_refused_in_python_naming_the_field():
    with pytest.raises(ValueError, match="stage must be one of"):
        ssrlab.UserPass("x", DATA / "hiz_copy.comp", "shade")
    with pytest.raises(FileNotFoundError, match="nowhere.comp"):
        ssrlab.UserPass("x", DATA / "nowhere.comp", "trace")
    with pytest.raises(ValueError, match="default of parameter 'k'"):
        ssrlab.UserPass("x", DATA / "hiz_copy.comp", "trace", params=(ssrlab.Param("k", "int", 5, 0, 4),))
    with pytest.raises(ValueError, match="dispatch for stage 'trace'"):
        ssrlab.UserPass("x", DATA / "hiz_copy.comp", "trace", dispatch="pixel")


def test_a_compile_error_names_the_users_file_and_line(renderer, tmp_path):
    src = (DATA / "hiz_copy.comp").read_text().splitlines()
    line = next(i for i, t in enumerate(src) if "walk_step(w0);" in t)
    src[line] = "        walk_step(w0) oops;"
    broken = tmp_path / "broken_trace.comp"
    broken.write_text("\n".join(src) + "\n")
    renderer.register_pass(ssrlab.UserPass("broken", broken, "trace", reads=("hiz_trace",)))
    with pytest.raises(ssrlab.ShaderError) as e:
        renderer.render(scenes.box_stack(), settings=ssrlab.Settings(**SMALL, method="hiz", user_passes=("broken",)))
    assert e.value.file == str(broken) and e.value.line == line + 1
    assert f"{broken}:{line + 1}" in str(e.value)


def test_a_sweep_varies_a_user_parameter_and_scores_it_against_the_converged_reference(tmp_path):
    bilateral_filter()  # declared already by the module's renderer (the sweep's renderer registers it)
    rows = bench.sweep({"bilateral_filter.radius": [0, 4]}, [{"name": "box_stack", "floor_roughness": 0.4}],
                       base={**SMALL, "method": "hiz", "sampling": "vndf", "user_passes": ("bilateral_filter",)},
                       repeats=1, warmup=0, reference="converged", reference_rays=16, progress=False,
                       cache_folder=tmp_path, device="cpu")
    assert [r["s_bilateral_filter.radius"] for r in rows] == [0, 4]
    assert "bilateral_filter.radius" in bench.varying_settings(rows)
    for r in rows:
        assert r["gpu_bilateral_filter_ms"] > 0.0 and np.isfinite(r["thesis_error"])
    assert rows[0]["thesis_error"] != rows[1]["thesis_error"]
    assert len(bench.pareto_front(rows)) >= 1


def test_the_view_space_march_example_traces_and_its_steps_act():
    r = ssrlab.Renderer()
    r.register_pass(ssrlab.user_pass.load("examples/view_space_march/technique.py:view_space_march", ROOT))
    scene = scenes.mirror_test()
    s = ssrlab.Settings(**SMALL, method="linear", user_passes=("view_space_march",))
    hits = []
    for steps in (2, 64):
        f = r.render(scene, settings=s.replace(**{"view_space_march.steps": steps}))
        assert "view_space_march" in f.passes and "trace_linear" not in f.passes
        hits.append(int(np.count_nonzero(f.read("rays.hit")[..., 2] > 0)))
        assert f.stats["rays_traced"] > 0 and f.stats["depth_fetches"] > 0  # stats read its rays.sample
    assert 0 < hits[0] < hits[1]
    ref = f.reference("per_ray")  # the per-ray reference reads the user pass's rays unchanged
    assert ref.hit.shape[-2:] == (SMALL["height"], SMALL["width"]) and ref.hit.any()


def test_ssrlab_bench_sweeps_a_user_parameter_from_a_sweep_file(tmp_path):
    import csv
    import os
    import subprocess

    sweep = tmp_path / "user.toml"
    sweep.write_text(f'''
user_passes = ["{ROOT / "examples" / "view_space_march" / "technique.py"}:view_space_march"]
scenes = ["mirror_test"]
repeats = 1
warmup = 0
reference = "converged"
reference_rays = 4
device = "cpu"
[base]
width = 64
height = 48
method = "linear"
user_passes = ["view_space_march"]
[grid]
"view_space_march.steps" = [2, 64]
''')
    env = {**os.environ, "SSRLAB_CACHE": str(tmp_path / "cache")}
    r = subprocess.run([sys.executable, "-m", "ssrlab", "bench", str(sweep), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-4000:]
    rows = list(csv.DictReader((tmp_path / "out" / "rows.csv").open()))
    assert [row["s_view_space_march.steps"] for row in rows] == ["2", "64"]
    errors = [float(row["thesis_error"]) for row in rows]
    assert all(float(row["gpu_view_space_march_ms"]) > 0 for row in rows)
    assert errors[1] < errors[0]  # 64 steps find more of the mirror's reflection than 2


def test_the_example_sweep_file_loads_and_plans():
    config = bench.load_sweep(ROOT / "examples" / "sweeps" / "user_passes.toml")
    plan = bench.plan_sweep(config["grid"], config["scenes"], config.get("views"), config["base"])
    assert len(plan) == 6 and {"view_space_march", "bilateral_filter"} <= set(ssrlab.user_pass.declared())


def test_the_user_passes_notebook_places_the_examples_on_the_front(tmp_path, monkeypatch):
    nbclient = pytest.importorskip("nbclient")
    import nbformat

    monkeypatch.setenv("SSRLAB_NOTEBOOK_SCALE", "small")
    monkeypatch.setenv("SSRLAB_NOTEBOOK_OUT", str(tmp_path / "figures"))
    monkeypatch.setenv("SSRLAB_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("SSRLAB_EXAMPLES", str(ROOT / "examples"))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nb = nbformat.read(ROOT / "notebooks" / "user_passes.ipynb", as_version=4)
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    assert (tmp_path / "figures" / "user_passes_pareto.png").stat().st_size > 10_000
    text = "\n".join(o.get("data", {}).get("text/markdown", "") for c in nb.cells if c.cell_type == "code"
                     for o in c.get("outputs", []))
    rows = [l for l in text.splitlines() if l.startswith("| ") and "**" in l]
    assert len(rows) == 2 * (1 + 1 + 3 + 2)  # two scenes x every configuration
    assert any("view_space_march (steps=128)" in l for l in rows) and any("bilateral_filter" in l for l in rows)
    # one timed run: every verdict says it is too small to judge, and why
    assert all("**too small to judge**" in l and "one timed run" in l for l in rows)
    assert sum(l.split(" | ")[4] == "yes" for l in rows) == 2  # the least error of each scene, computed


def test_a_sequence_runs_the_user_passes_in_every_frame(renderer):
    scene = scenes.box_stack(floor_roughness=0.4)
    cam = scene.camera
    s = ssrlab.Settings(**SMALL, method="hiz", temporal_reflections=True,
                        user_passes=("hiz_copy", "bilateral_filter"))
    frames = list(renderer.render_sequence(scene, [cam, cam], s))
    for f in frames:
        assert {"hiz_copy", "bilateral_filter", "temporal"} <= set(f.passes)
        assert f.passes.index("bilateral_filter") < f.passes.index("temporal")  # the filter feeds the accumulation
        assert f.timings["hiz_copy"] > 0.0 and f.timings["bilateral_filter"] > 0.0
