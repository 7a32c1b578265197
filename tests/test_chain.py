"""Renderer.chain: the passes a render runs, in order, with what each reads and writes, known
before rendering; it must equal what the render then runs, and every input, texture or buffer,
must be written by an earlier pass."""

from __future__ import annotations

import pytest

import ssrlab
from conftest import small

COMBINATIONS = [
    dict(),
    dict(method="hiz"),
    dict(method="off"),
    dict(method="bvh"),
    dict(fallback="bvh"),
    dict(fallback="probes", probe_size=16),
    dict(fallback="none"),
    dict(glossy="cone", method="hiz"),
    dict(glossy="blur_mips"),
    dict(skip=True),
    dict(skip=True, variance_rays=True, adaptive_rays=True, rays_per_pixel=4),
    dict(skip=True, glossy="stochastic", method="hiz"),
    dict(skip=False, glossy="stochastic"),
    dict(rays_per_pixel=4, reuse_radius=0),
    dict(temporal_reflections=True),
    dict(denoise="svgf"),
    dict(taa="thesis"),
    dict(taa="clamped"),
    dict(bounces="history"),
    dict(downscale=2, rays_per_pixel=2),
]
SCENES = {"mirror_test": ssrlab.scenes.mirror_test, "hall": lambda: ssrlab.scenes.hall(floor_roughness=0.2),
          "matte": lambda: _matte()}


def _matte() -> ssrlab.Scene:
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), 10, name="floor")
    s.add_light(ssrlab.point_light((0, 3, 0)))
    s.camera = ssrlab.Camera(position=(0, 2, 4), target=(0, 0, 0))
    return s


def _ids(kw: dict) -> str:
    return ",".join(f"{k}={v}" for k, v in kw.items()) or "defaults"


@pytest.mark.parametrize("scene_name", sorted(SCENES))
@pytest.mark.parametrize("kw", COMBINATIONS, ids=_ids)
def test_chain_is_what_the_render_runs(renderer, scene_name, kw):
    scene = SCENES[scene_name]()
    settings = small(width=48, height=32, **kw)
    chain = renderer.chain(settings, scene)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ssrlab.NoReflectionWarning)
        f = renderer.render(scene, settings=settings)
    assert chain.names == f.passes
    written: set[str] = set()
    buffers: set[str] = set()
    for p in chain:
        missing = [i for i in p.inputs if i not in written]
        assert not missing, f"{p.name} reads {missing} before any pass writes them"
        missing = [i for i in p.buffer_inputs if i not in buffers]
        assert not missing, f"{p.name} reads the buffers {missing} before any pass writes them"
        written.update(p.outputs)
        buffers.update(p.buffer_outputs)
    # A screen-space trace after classify (skip) runs over its list, and says so.
    for p in chain:
        if p.name in ("trace_linear", "trace_hiz"):
            assert ("ray_list" in p.buffer_inputs) == ("classify" in chain.names), (p.name, p.buffer_inputs)
    # Every texture the frame holds (its own, not the renderer's scratch) is some pass's output.
    assert set(f.texture_names) <= written | {n for n in f.texture_names if n.startswith("reference.")}
    f.release()


def test_chain_prints_and_draws(renderer):
    chain = renderer.chain(small(method="hiz"))
    text = str(chain)
    assert "trace_hiz" in text and "reads:" in text and "writes:" in text
    md = chain.markdown()
    assert md.splitlines()[0] == "| # | pass | reads | writes |" and "`trace_hiz`" in md
    # The buffers a pass hands to the next: the peeling's covered tiles, classify's lists.
    skip = renderer.chain(small(method="hiz", skip=True))
    by_name = {p.name: p for p in skip}
    assert by_name["depth_peel"].buffer_outputs == ("covered_tiles",)
    assert "covered_tiles" in by_name["lighting"].buffer_inputs
    assert "ray_list" in by_name["classify"].buffer_outputs and "ray_list" in by_name["trace_hiz"].buffer_inputs
    assert "writes buffers: ray_list" in str(skip) and "*`ray_list`*" in skip.markdown()


def test_chain_validates_its_settings(renderer):
    with pytest.raises(ValueError, match="layers"):
        renderer.chain(small(), layers=0)
