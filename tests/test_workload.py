"""Long work says so before it starts, and a budget refuses it by name (ssrlab.workload): the fuzzer's
instancing mutant, 2CylinderEngine's mesh drawn by 20,000 glTF nodes (43 million triangles from a
file of a few MB), warns at once, naming its triangle count, and is refused beyond a set budget; no
test here draws it."""

from __future__ import annotations

import subprocess
import sys
import time
import warnings

import pytest

import ssrlab
from ssrlab import workload
from ssrlab.lab import hostile_gltf

INSTANCES = 20_000
MESH_TRIANGLES = 2163  # 2CylinderEngine's mesh 3, the one hostile_gltf.instanced draws


@pytest.fixture(scope="module")
def mutant(tmp_path_factory):
    path = hostile_gltf.instanced(tmp_path_factory.mktemp("instanced") / "engine_x20000.glb", INSTANCES)
    assert path.stat().st_size < 4_000_000
    return path


@pytest.fixture
def budget(renderer):
    """The session renderer's budget, put back after the test."""
    before = renderer.max_triangles
    yield renderer
    renderer.max_triangles = before


def test_the_mutant_loads_fast_and_counts_every_instance(mutant):
    start = time.perf_counter()
    scene = ssrlab.Scene.load(mutant)
    assert time.perf_counter() - start < 5
    assert scene.object_count == INSTANCES
    assert scene.triangle_count == INSTANCES * MESH_TRIANGLES == 43_260_000


def test_render_warns_within_a_second_naming_the_triangle_count(renderer, budget, mutant):
    scene = ssrlab.Scene.load(mutant)
    renderer.max_triangles = None
    uploads = renderer.stats["scene_uploads"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)  # the warning stops the render before it draws
        start = time.perf_counter()
        with pytest.raises(ssrlab.SceneWarning) as info:
            renderer.render(scene, settings=ssrlab.Settings(width=64, height=48))
        assert time.perf_counter() - start < 1.0
    message = str(info.value)
    assert "Renderer.render" in message and repr(scene.name) in message
    assert "43,260,000 triangles" in message
    assert " s on this device" in message or " min on this device" in message
    assert "max_triangles" in message and "SSRLAB_MAX_TRIANGLES" in message
    assert renderer.stats["scene_uploads"] == uploads  # nothing was uploaded, let alone drawn


def test_render_sequence_warns_at_the_call_for_the_whole_sequence(renderer, budget, mutant):
    scene = ssrlab.scenes.load(str(mutant))  # with the default sun: a shadow map's pass too
    renderer.max_triangles = None
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)
        with pytest.raises(ssrlab.SceneWarning, match=r"render_sequence: .*43,260,000 triangles.*over 3 frames"):
            renderer.render_sequence(scene, [scene.camera] * 3, ssrlab.Settings(width=64, height=48))


def test_a_set_budget_refuses_the_scene_by_name(renderer, budget, mutant):
    scene = ssrlab.Scene.load(mutant)
    renderer.max_triangles = 10_000_000
    uploads = renderer.stats["scene_uploads"]
    start = time.perf_counter()
    with pytest.raises(ssrlab.SceneError) as info:
        renderer.render(scene, settings=ssrlab.Settings(width=64, height=48))
    assert time.perf_counter() - start < 1.0
    message = str(info.value)
    assert repr(scene.name) in message and "43,260,000 triangles" in message
    assert "budget of 10,000,000 triangles" in message and "nothing was rendered" in message
    assert "Renderer(max_triangles=44_000_000)" in message and "SSRLAB_MAX_TRIANGLES" in message
    with pytest.raises(ssrlab.SceneError, match="budget of 10,000,000"):
        next(iter(renderer.render_sequence(scene, [scene.camera], ssrlab.Settings(width=64, height=48))))
    assert renderer.stats["scene_uploads"] == uploads


def test_the_budget_from_the_environment(monkeypatch, mutant):
    monkeypatch.setenv(workload.MAX_TRIANGLES_ENV, "2e7")
    r = ssrlab.Renderer()
    assert r.max_triangles == 20_000_000
    with pytest.raises(ssrlab.SceneError, match=r"43,260,000 triangles.*budget of 20,000,000"):
        r.render(ssrlab.Scene.load(mutant))
    assert ssrlab.Renderer(max_triangles=0).max_triangles is None  # 0: no budget, whatever the variable says
    assert ssrlab.Renderer(max_triangles=5).max_triangles == 5
    monkeypatch.setenv(workload.MAX_TRIANGLES_ENV, "lots")
    with pytest.raises(ValueError, match=r"\$SSRLAB_MAX_TRIANGLES must be a whole number.*'lots'"):
        ssrlab.Renderer()
    monkeypatch.setenv(workload.MAX_TRIANGLES_ENV, "")
    assert ssrlab.Renderer().max_triangles is None


@pytest.mark.parametrize("bad", [-1, 1.5, "10", True])
def test_a_bad_budget_is_refused_by_name(renderer, budget, bad):
    with pytest.raises(ValueError, match="Renderer.max_triangles must be"):
        renderer.max_triangles = bad


def test_scenes_of_ordinary_size_do_not_warn(renderer):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)
        frame = renderer.render(ssrlab.scenes.hall(), settings=ssrlab.Settings(width=48, height=32, layers=2))
    assert frame.color.shape == (32, 48, 3)
    engine = ssrlab.scenes.load(str(ssrlab.models.find("2CylinderEngine")))
    assert not renderer.estimate(engine, layers=4).long  # auto's measurement counted: a few seconds here


def test_the_estimate_counts_passes_measurement_and_bvh(renderer):
    scene = ssrlab.scenes.hall()  # one sun that casts a shadow
    tri = scene.triangle_count
    one = renderer.estimate(scene, deep_gbuffer="peel", layers=3)
    assert one.triangles == tri and one.passes == 2 * 3 + 1 and not one.bvh
    assert dict(one.per_frame) == {"peeling, 3 layers": 6, "shadow map faces": 1}
    assert renderer.estimate(scene, deep_gbuffer="visibility", layers=3, shadow_map_size=0).passes == 3
    assert renderer.estimate(scene, deep_gbuffer="lists", layers=3).passes == 2
    assert renderer.estimate(scene, deep_gbuffer="peel", frames=5).passes == 5 * 3
    scene.add_light(ssrlab.point_light((0, 2, 0), cast_shadow=True))  # a cube map: six faces
    assert renderer.estimate(scene, deep_gbuffer="peel").passes == 2 + 1 + 6
    # deep_gbuffer 'auto' measures the constructions first (4 renders of each), where it measures
    auto = renderer.estimate(scene, deep_gbuffer="auto", layers=2, width=40, height=24)
    assert auto.passes > renderer.estimate(scene, deep_gbuffer="peel", layers=2, width=40, height=24).passes
    renderer.render(scene, settings=ssrlab.Settings(deep_gbuffer="auto", layers=2, width=40, height=24))
    after = renderer.estimate(scene, deep_gbuffer="auto", layers=2, width=40, height=24)
    assert after.passes == 4 + 1 + 6  # measured once: counted as peeling's passes from then on
    # the BVH is counted until this renderer has built it for the scene's geometry
    bvh = renderer.estimate(scene, deep_gbuffer="peel", fallback="bvh")
    assert bvh.bvh and bvh.seconds > renderer.estimate(scene, deep_gbuffer="peel").seconds
    renderer.render(scene, settings=ssrlab.Settings(deep_gbuffer="peel", fallback="bvh", width=40, height=24))
    assert not renderer.estimate(scene, deep_gbuffer="peel", fallback="bvh").bvh
    # the rates a renderer assumes can be set (a GPU's, measured by benchmarks/timing/render_estimate.py)
    rates = renderer.triangle_rates
    try:
        renderer.triangle_rates = {"draw": 1.0, "bvh": 1.0}
        slow = renderer.estimate(scene, deep_gbuffer="peel")
        assert slow.seconds == pytest.approx(tri * slow.passes) and slow.long
    finally:
        renderer.triangle_rates = rates


def test_the_cli_warns_before_it_renders_and_refuses_beyond_its_budget(tmp_path, mutant):
    # the warning made an error (what -W cannot do for a class of a package) stops the render where
    # it would start
    run = ("import sys, warnings, ssrlab; warnings.simplefilter('error', ssrlab.SceneWarning); "
           "from ssrlab.cli import main; sys.exit(main(sys.argv[1:]))")
    common = [sys.executable, "-c", run, "render", "--scene", str(mutant), "--width", "64", "--height", "48"]
    start = time.perf_counter()
    refused = subprocess.run(common + ["--max-triangles", "1000000", "--out", str(tmp_path / "a")],
                             capture_output=True, text=True, timeout=120)
    assert refused.returncode == 1, refused.stderr
    assert "SceneError" in refused.stderr and "43,260,000 triangles" in refused.stderr
    assert "budget of 1,000,000 triangles" in refused.stderr
    warned = subprocess.run(common + ["--out", str(tmp_path / "b")], capture_output=True, text=True, timeout=120)
    assert warned.returncode != 0
    assert "SceneWarning" in warned.stderr and "43,260,000 triangles" in warned.stderr, warned.stderr[-3000:]
    assert time.perf_counter() - start < 60
    assert not (tmp_path / "b" / "color.png").exists()


def test_the_cli_shows_the_warning_as_a_line_of_its_own(mutant, tmp_path, capsys, monkeypatch):
    """Without -W the warning is a line of ssrlab's own, before the render starts (which this test
    stops right after the check, so that nothing is drawn)."""
    from ssrlab import cli
    from ssrlab.renderer import Renderer

    def stop(self, *args):
        raise RuntimeError("stopped after the check")

    monkeypatch.setattr(Renderer, "_decide_deep_gbuffer", stop)  # the step after the check in render()
    assert cli.main(["render", "--scene", str(mutant), "--width", "64", "--height", "48",
                     "--out", str(tmp_path / "c")]) == 1
    err = capsys.readouterr().err
    assert ("ssrlab: SceneWarning: Renderer.render: scene 'engine_x20000' is long work: 43,260,000 triangles"
            in err), err[-3000:]
    assert err.index("SceneWarning") < err.index("stopped after the check")


def test_the_benchmark_prints_the_estimate_beside_the_measured_seconds():
    """benchmarks/timing/render_estimate.py, where ssrlab.workload.RATES come from, at a smoke size."""
    from pathlib import Path

    script = Path(__file__).resolve().parents[1] / "benchmarks" / "timing" / "render_estimate.py"
    r = subprocess.run([sys.executable, str(script), "--width", "32", "--height", "24", "--instances", "10",
                        "--stacked", "5"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    rows = [line.split() for line in r.stdout.splitlines() if line.startswith(("spread ", "stacked "))]
    assert len(rows) == 8 and {row[0] for row in rows} == {"spread", "stacked"}
    assert "draw rate" in r.stdout and "bvh rate" in r.stdout
