"""The thesis's experiments with its TAA on: a sweep can time and score the frames of one
running sequence (bench.sweep(sequence=True)), and ssrlab.experiments passes its `taa` through."""

import numpy as np
import pytest

import ssrlab
import ssrlab.lab.run
from ssrlab import bench, experiments, metrics, scenes
from ssrlab.reference import reference_image

BASE = dict(width=64, height=48, shadow_map_size=256, rays_per_pixel=4, downscale=2, stride=4.0, max_steps=250)


def test_a_sequence_sweep_times_and_scores_every_frame_after_the_warm_up(renderer, tmp_path):
    rows = bench.sweep({"taa": ["thesis"]}, ["mirror_test"], base=BASE, repeats=3, warmup=1, sequence=True,
                       reference="thesis", progress=False, cache_folder=tmp_path)
    row = rows[0]
    assert row["sequence"] is True and row["frames"] == 4 and row["repeats"] == 3
    assert row["gpu_taa_ms"] is not None
    assert row.get("gpu_reproject_ms") is None  # the thesis's blend reads the same pixel: nothing reprojects
    assert row["time_frame_ms_iqr"] is not None  # three timed frames: a spread
    # The metrics are the mean over frames 1-3 of one sequence (frame 0 only fills the history),
    # each scored against the unjittered reference.
    scene = scenes.mirror_test()
    s = ssrlab.Settings(taa="thesis", **BASE)
    ref = reference_image(renderer, scene, scene.camera, s.replace(taa="off"), kind="thesis", cache=True,
                          folder=str(tmp_path))
    reflective = np.asarray(ref.reflective, bool)
    scores = [metrics.image_metrics(f.color, ref.color, reflective)
              for f in list(renderer.render_sequence(scene, [scene.camera] * 4, s))[1:]]
    errors = [m["thesis_error"] for m in scores]
    assert len(set(errors)) > 1  # new rays each frame: the frames differ, so the mean is not any one of them
    assert row["thesis_error"] == pytest.approx(np.mean(errors), rel=1e-5)
    assert row["rmse"] == pytest.approx(np.mean([m["rmse"] for m in scores]), rel=1e-5)
    assert row["thesis_error_frame_min"] == pytest.approx(min(errors), rel=1e-5)
    assert row["thesis_error_frame_max"] == pytest.approx(max(errors), rel=1e-5)


@pytest.mark.parametrize("kwargs, match", [
    (dict(sequence=True, frames=3), "frames must be 1"),
    (dict(sequence=True, warmup=0), "warmup >= 1"),
    (dict(sequence="yes"), "sequence must be True or False"),
])
def test_a_sequence_sweep_checks_its_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        bench.sweep({}, ["mirror_test"], base=BASE, progress=False, **kwargs)


class _Stop(Exception):
    pass


@pytest.mark.parametrize("experiment, default", [(experiments.layers, "thesis"),
                                                 (experiments.downscale_rays_stride, "thesis"),
                                                 (experiments.hiz_vs_linear, "off")])
def test_experiments_pass_their_taa_to_the_sweeps(experiment, default, monkeypatch):
    calls = []

    def fake_sweep(**kwargs):
        calls.append(kwargs)
        raise _Stop

    monkeypatch.setattr(ssrlab.lab.run, "sweep", fake_sweep)  # what the experiments call
    for taa in (None, "thesis", "off"):
        with pytest.raises(_Stop):
            experiment("small") if taa is None else experiment("small", taa=taa)
        expected = default if taa is None else taa
        assert calls[-1]["base"]["taa"] == expected
        assert calls[-1]["sequence"] is (expected != "off")
    with pytest.raises(ValueError, match="taa must be one of"):
        experiment("small", taa="on")


def test_a_sweep_file_can_ask_for_one_sequence(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('scenes = ["mirror_test"]\nsequence = true\nwarmup = 2\nrepeats = 3\n[grid]\ntaa = ["thesis"]\n')
    cfg = bench.load_sweep(path)
    assert cfg["sequence"] is True and cfg["warmup"] == 2
