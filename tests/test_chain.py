"""Renderer.chain and frame.passes against chains written out by hand from the papers' pipelines:
shadow map, deep G-buffer and its lighting first (seed 000, 2.1-2.2), then what the technique
needs before its trace (the Hi-Z pyramid and the cone's pre-convolved and pre-integrated mips,
seed 002, 4.4; the reprojection of temporal techniques), classify's ray list where screen-space
work is skipped (seed 003), the trace (and the variance-guided second trace over the rays the first
left out), the fallback for the rays that missed (seed 004; thesis 4.3), the resolve or the cone
trace that replaces it, the temporal accumulation or SVGF's three passes (seed 003), the composite,
and TAA on the final colour (seed 000, 2.5), in the order the passes' declarations give. A wrong
chain (a pass missing, added or moved) fails; so does a chain that needs a GL context to be listed."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings

import pytest

import ssrlab
from conftest import small

W, H = 48, 32


def _fetch(renderer) -> list[str]:
    # Where the passes read their float inputs by imageLoad (llvmpipe's default), the resolve's
    # neighbour rays come from resolve_fetch's textures instead of its own shared tile, a pass of
    # its own right before it (passes/resolve.h); a GPU fills the tile in the resolve.
    return ["resolve_fetch"] if renderer.info["input_fetch"] == "imageLoad" else []


# settings -> the chain a render of the stand-in scene (a sun that casts a shadow, a mirror floor)
# runs, typed by hand: each pass after the writers of what it reads, passes that do not depend on
# each other in the order of their names (render/pass_registry.h). "FETCH" stands for
# _fetch(renderer). skip is given explicitly: its default 'auto' differs between devices.
CHAINS = {
    "linear, 1 layer": (
        dict(method="linear", layers=1, skip=False),
        ["depth_peel", "shadow_map", "lighting", "trace_linear", "specular_occlusion", "FETCH", "resolve",
         "composite"]),
    "hiz + cone glossy": (
        dict(method="hiz", glossy="cone", skip=False),
        ["depth_peel", "hiz_build", "preintegrate", "shadow_map", "lighting", "preconvolve", "trace_hiz",
         "specular_occlusion", "cone_trace", "composite"]),
    "linear + blur_mips glossy": (
        dict(method="linear", glossy="blur_mips", skip=False),
        ["depth_peel", "shadow_map", "lighting", "preconvolve", "trace_linear", "specular_occlusion", "blur_mips",
         "composite"]),
    "skip + adaptive and variance rays": (
        dict(method="linear", skip=True, adaptive_rays=True, variance_rays=True, rays_per_pixel=4),
        ["depth_peel", "shadow_map", "lighting", "classify", "trace_linear", "variance_rays", "trace_linear_extra",
         "specular_occlusion", "FETCH", "resolve", "composite"]),
    "hiz + skip": (
        dict(method="hiz", skip=True),
        ["depth_peel", "hiz_build", "shadow_map", "lighting", "classify", "trace_hiz", "specular_occlusion", "FETCH",
         "resolve", "composite"]),
    "fallback bvh": (
        dict(method="linear", fallback="bvh", skip=False),
        ["depth_peel", "shadow_map", "lighting", "trace_linear", "fallback_bvh", "FETCH", "resolve", "composite"]),
    "ray-traced (bvh)": (
        dict(method="bvh", skip=False),
        ["depth_peel", "shadow_map", "lighting", "trace_bvh", "FETCH", "resolve", "composite"]),
    "svgf": (
        dict(method="linear", denoise="svgf", skip=False),
        ["depth_peel", "shadow_map", "lighting", "reproject", "trace_linear", "specular_occlusion", "FETCH", "resolve",
         "svgf_temporal", "svgf_variance", "svgf_atrous", "composite"]),
    "reflections off": (
        dict(method="off"),
        ["depth_peel", "shadow_map", "lighting", "composite"]),
    # The reflection reprojected by its hits: after the trace whose hits it follows, before the
    # temporal pass that reads it.
    "svgf, hit-point reprojection": (
        dict(method="linear", denoise="svgf", reflection_reprojection="hit", skip=False),
        ["depth_peel", "shadow_map", "lighting", "reproject", "trace_linear", "specular_occlusion",
         "reproject_reflection", "FETCH", "resolve", "svgf_temporal", "svgf_variance", "svgf_atrous", "composite"]),
    "fragment lists": (
        dict(method="linear", deep_gbuffer="lists", layers=3, skip=False),
        ["fragment_lists", "shadow_map", "lighting", "trace_linear", "specular_occlusion", "FETCH", "resolve",
         "composite"]),
    "visibility buffer": (
        dict(method="linear", deep_gbuffer="visibility", layers=3, skip=False),
        ["shadow_map", "visibility_buffer", "gbuffer_attributes", "lighting", "trace_linear", "specular_occlusion",
         "FETCH", "resolve", "composite"]),
    "visibility lists + hiz + skip": (
        dict(method="hiz", deep_gbuffer="visibility_lists", layers=3, skip=True),
        ["shadow_map", "visibility_buffer", "gbuffer_attributes", "hiz_build", "lighting", "classify", "trace_hiz",
         "specular_occlusion", "FETCH", "resolve", "composite"]),
    "thesis taa": (
        dict(method="linear", taa="thesis", skip=False),
        ["depth_peel", "shadow_map", "lighting", "trace_linear", "specular_occlusion", "FETCH", "resolve", "composite",
         "taa"]),
    "bounces from history": (
        dict(method="linear", bounces="history", skip=False),
        ["depth_peel", "shadow_map", "lighting", "reproject", "trace_linear", "specular_occlusion", "FETCH", "resolve",
         "composite"]),
    "temporal ray reuse": (
        dict(method="linear", temporal_ray_reuse=True, skip=False),
        ["depth_peel", "shadow_map", "lighting", "reproject", "trace_linear", "specular_occlusion", "FETCH", "resolve",
         "composite"]),
    "downscale 2": (
        dict(method="hiz", downscale=2, skip=False),
        ["depth_peel", "hiz_build", "shadow_map", "lighting", "trace_hiz", "specular_occlusion", "FETCH", "resolve",
         "composite"]),
    "horizon occlusion": (
        dict(method="hiz", specular_occlusion="horizon", skip=False),
        ["depth_peel", "hiz_build", "shadow_map", "lighting", "trace_hiz", "specular_occlusion", "FETCH", "resolve",
         "composite"]),
    "hiz + svgf + skip": (
        dict(method="hiz", denoise="svgf", skip=True),
        ["depth_peel", "hiz_build", "shadow_map", "lighting", "classify", "reproject", "trace_hiz",
         "specular_occlusion", "FETCH", "resolve", "svgf_temporal", "svgf_variance", "svgf_atrous", "composite"]),
    "bvh + svgf": (
        dict(method="bvh", denoise="svgf", skip=False),
        ["depth_peel", "shadow_map", "lighting", "reproject", "trace_bvh", "FETCH", "resolve", "svgf_temporal",
         "svgf_variance", "svgf_atrous", "composite"]),
}
# Rendered as a sequence of two frames: the temporal accumulation after the resolve, clamped TAA
# after the composite, both reading the reprojection made right after the lighting.
SEQUENCE = (dict(method="linear", temporal_reflections=True, taa="clamped", skip=False),
            ["depth_peel", "shadow_map", "lighting", "reproject", "trace_linear", "specular_occlusion", "FETCH",
             "resolve", "temporal", "composite", "taa"])
# The same with hit-point reprojection of the reflection (the surface's still feeds TAA).
SEQUENCE_HIT = (dict(SEQUENCE[0], reflection_reprojection="hit"),
                ["depth_peel", "shadow_map", "lighting", "reproject", "trace_linear", "specular_occlusion",
                 "reproject_reflection", "FETCH", "resolve", "temporal", "composite", "taa"])


def _expected(renderer, names: list[str]) -> list[str]:
    return [n for name in names for n in (_fetch(renderer) if name == "FETCH" else [name])]


@pytest.fixture(scope="module")
def stand_in():
    return ssrlab.scenes.stand_in()


@pytest.mark.parametrize("case", list(CHAINS))
def test_the_chain_is_the_papers_pipeline(renderer, stand_in, case):
    kw, names = CHAINS[case]
    expected = _expected(renderer, names)
    settings = small(width=W, height=H, **kw)
    frame = renderer.render(stand_in, settings=settings)
    assert frame.passes == expected
    assert renderer.chain(settings, stand_in).names == expected
    frame.release()


# Listing a chain makes no GL context: a process that only lists chains never loads a GL driver
# (Mesa's EGL vendor library and its DRI driver, or a GPU vendor's). Its chains are the renderer's.
NO_CONTEXT = r"""
import json, sys
import ssrlab
from ssrlab.chain import derive
cases = json.loads(sys.argv[1])
out = {k: derive(ssrlab.Settings(width=48, height=32, **kw), device="cpu").names for k, kw in cases.items()}
drivers = sorted({l.split()[-1] for l in open("/proc/self/maps")
                  if "libEGL_" in l or "_dri.so" in l or "libgallium" in l or "nvidia" in l})
print(json.dumps({"chains": out, "drivers": drivers}))
"""


def test_the_chain_is_listed_without_a_gl_context(renderer, stand_in):
    cases = {case: kw for case, (kw, _) in CHAINS.items()}
    run = subprocess.run([sys.executable, "-c", NO_CONTEXT, json.dumps(cases)], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    got = json.loads(run.stdout.strip().splitlines()[-1])
    assert got["drivers"] == [], f"listing a chain loaded a GL driver: {got['drivers']}"
    if renderer.info["device"] == "cpu":
        for case, (kw, names) in CHAINS.items():
            assert got["chains"][case] == _expected(renderer, names), case


@pytest.mark.parametrize("sequence", [SEQUENCE, SEQUENCE_HIT], ids=["surface", "hit"])
def test_a_sequence_runs_temporal_accumulation_and_taa_in_every_frame(renderer, stand_in, sequence):
    kw, names = sequence
    expected = _expected(renderer, names)
    settings = small(width=W, height=H, **kw)
    frames = list(renderer.render_sequence(stand_in, [stand_in.camera] * 2, settings))
    assert [f.passes for f in frames] == [expected, expected]
    assert renderer.chain(settings, stand_in).names == expected


def test_a_scene_without_reflections_runs_no_reflection_pass(renderer):
    matte = ssrlab.Scene()
    matte.add_plane((0, 0, 0), 10, name="floor")  # the default material reflects nothing
    matte.add_light(ssrlab.point_light((0, 3, 0), cast_shadow=True))
    matte.camera = ssrlab.Camera(position=(0, 2, 4), target=(0, 0, 0))
    settings = small(width=W, height=H, method="hiz", denoise="svgf", skip=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ssrlab.NoReflectionWarning)
        frame = renderer.render(matte, settings=settings)
    # The point light's shadow cube, the G-buffer and its lighting, the composite: no trace, no
    # Hi-Z, no SVGF, but the reprojection SVGF would read is not made either.
    assert frame.passes == ["depth_peel", "shadow_map", "lighting", "composite"]
    assert renderer.chain(settings, matte).names == frame.passes


@pytest.mark.parametrize("kw", [dict(), dict(method="hiz", glossy="cone"), dict(denoise="svgf"),
                                dict(fallback="bvh"), dict(skip=True, shadow_map_size=0)],
                         ids=["defaults", "hiz+cone", "svgf", "fallback=bvh", "skip, no shadow map"])
def test_the_chain_without_a_scene_is_the_render_of_the_stand_in(renderer, kw):
    """Renderer.chain(settings) without a scene lists what a render of ssrlab.scenes.stand_in()
    runs, the shadow map included (its sun casts a shadow; shadow_map_size=0 switches it off)."""
    settings = small(width=W, height=H, **kw)
    names = renderer.chain(settings).names
    frame = renderer.render(ssrlab.scenes.stand_in(), settings=settings)
    assert names == frame.passes
    assert ("shadow_map" in names) == (settings.shadow_map_size > 0)
    frame.release()


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
