"""The passes read their float inputs by imageLoad on the CPU device and by texelFetch on
a GPU (Renderer(input_fetch=...), shaders/lib/input_fetch.glsl), and with imageLoad the resolve
takes its neighbours' rays from resolve_fetch's textures instead of its shared tile. Both paths
run here on the device at hand (llvmpipe without a GPU, where texelFetch is the GPU's path; the GPU
where there is one, where imageLoad is llvmpipe's), and every output must be the same."""

import numpy as np
import pytest

import ssrlab
from conftest import gpu_paths_skip, small


@pytest.fixture(scope="module")
def both():
    from conftest import image_load_refusal

    if image_load_refusal():
        pytest.skip(f"nothing to compare on this device: {image_load_refusal()}")
    return ssrlab.Renderer("auto", input_fetch="imageLoad"), ssrlab.Renderer("auto", input_fetch="texelFetch")


CONFIGS = {
    # the thesis's configuration: 4 layers, 4 GGX rays at half resolution, the tiled resolve
    "thesis": dict(layers=4, rays_per_pixel=4, stride=4.0, downscale=2, max_steps=250),
    # the Hi-Z mirror frame: own rays only, no tile
    "hiz_mirror": dict(layers=1, method="hiz", sampling="mirror", rays_per_pixel=1, reuse_radius=1),
    # full resolution, radius 2, BRDF weights, edge-aware: the tile holds 2 rays per chunk
    "reuse_radius_2": dict(layers=2, method="hiz", sampling="vndf", rays_per_pixel=3, reuse_radius=2,
                           reuse_weighting="brdf", edge_aware=True),
    # rays.radiance from the BVH fallback, linear tracer with refinement, skip off
    "fallback_bvh": dict(layers=2, sampling="ggx", rays_per_pixel=2, fallback="bvh", refine_steps=2, skip=False),
    # the pbr composite, a quarter-resolution trace
    "pbr_quarter": dict(layers=1, method="hiz", sampling="ggx", rays_per_pixel=2, downscale=4, composite="pbr"),
}


@pytest.mark.parametrize("name", sorted(CONFIGS))
@pytest.mark.parametrize("scene_name", ["spheres_and_boxes", "hall"])
def test_image_and_texel_fetch_give_the_same_frame(both, name, scene_name):
    by_image, by_texel = both
    scene = getattr(ssrlab.scenes, scene_name)()
    s = small(width=120, height=72, **CONFIGS[name])
    fi, ft = by_image.render(scene, settings=s), by_texel.render(scene, settings=s)
    tiled = not (s.downscale == 1 and (s.reuse_radius == 0 or (s.sampling == "mirror" and s.reuse_weighting == "brdf")))
    assert ("resolve_fetch" in fi.passes) == tiled
    assert "resolve_fetch" not in ft.passes
    for what in ("color", "reflection", "rays.hit", "rays.sample", "rays.direction", "lit", "linear_depth"):
        a = np.asarray(fi.read(what) if "." in what or what in ("lit", "linear_depth") else getattr(fi, what))
        b = np.asarray(ft.read(what) if "." in what or what in ("lit", "linear_depth") else getattr(ft, what))
        assert np.isfinite(a).all(), what
        np.testing.assert_array_equal(a, b, err_msg=f"{name}/{scene_name}: {what}")
    assert fi.stats["depth_fetches"] == ft.stats["depth_fetches"]


def test_reference_and_temporal_composites_read_their_rgba32f_inputs(both):
    # The composite's direct light and reflection change format with the chain (the reference's
    # and the temporal accumulation's are RGBA32F, lit and the resolve's RGBA16F): the image path
    # must read each with its own format.
    by_image, by_texel = both
    scene = ssrlab.scenes.spheres_and_boxes()
    s = small(width=80, height=48, layers=1, method="hiz", rays_per_pixel=2, temporal_reflections=True)
    cameras = [scene.camera, scene.camera]
    fi = list(by_image.render_sequence(scene, cameras, settings=s))[-1]
    ft = list(by_texel.render_sequence(scene, cameras, settings=s))[-1]
    assert "temporal" in fi.passes
    np.testing.assert_array_equal(fi.color, ft.color)
    f1, f2 = by_image.render(scene, settings=s), by_texel.render(scene, settings=s)
    ri, rt = f1.reference("converged", rays=4), f2.reference("converged", rays=4)
    np.testing.assert_array_equal(np.asarray(ri.color), np.asarray(rt.color))


@gpu_paths_skip
def test_the_renderer_says_how_it_reads(both):
    by_image, by_texel = both
    assert by_image.info["input_fetch"] == "imageLoad"
    assert by_texel.info["input_fetch"] == "texelFetch"
    # "auto": imageLoad on the CPU device (llvmpipe), texelFetch on a GPU
    auto = ssrlab.Renderer("auto")
    expected = "imageLoad" if auto.info["device"] == "cpu" else "texelFetch"
    assert auto.info["input_fetch"] == expected


def test_input_fetch_is_validated():
    with pytest.raises(ValueError, match="input_fetch must be 'auto', 'imageLoad' or 'texelFetch'"):
        ssrlab.Renderer("auto", input_fetch="sampler")
