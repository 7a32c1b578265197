"""Renderer.raster_floor, the device's floors under the deep G-buffer: every floor timed on every
repeat (finite, positive; no speed is asserted), and what it counts agrees with itself through
different paths of the device (shader atomics, occlusion queries, the targets read back) and with
the constructions' own counts of the same scene (a peeled layer's samples, the one-pass lists'
fragments), which are counted by other code."""

import math

import pytest

import ssrlab

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
