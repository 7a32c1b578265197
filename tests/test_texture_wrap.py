"""The reference tracer's texture look-ups (shaders/lib/scene_textures.glsl) wrap texture
coordinates as the rasteriser's GL samplers do, negative coordinates included: GLSL leaves `%`
undefined for negative operands, so a plane whose uvs run below zero is the case to check."""

from __future__ import annotations

import json

import numpy as np
import pytest

import ssrlab
from conftest import small
from ssrlab.scene import Camera, Environment, Material, Scene, directional_light

WRAPS = {"repeat": 10497, "clamp": 33071, "mirrored": 33648}


def textured_plane(tmp_path, wrap: str):
    s = Scene()
    rng = np.random.default_rng(3)
    texels = rng.integers(30, 255, size=(4, 4, 3), dtype=np.uint8)
    image = s.add_image(np.repeat(np.repeat(texels, 1, 0), 1, 1), name="tiles")
    positions = np.float32([[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]])
    uvs = np.float32([[-1.6, -1.3], [1.4, -1.3], [1.4, 1.7], [-1.6, 1.7]])  # three periods, two below zero
    s.add_mesh(positions, np.array([[0, 2, 1], [0, 3, 2]]), uvs=uvs, normals=np.tile(np.float32([0, 1, 0]), (4, 1)),
               material=Material(base_color=(1, 1, 1), roughness=0.9, base_color_texture=image), name="plane")
    s.add_light(directional_light((0.1, -1.0, 0.2), intensity=2.0, cast_shadow=False))
    s.ambient = (0.05, 0.05, 0.05)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 4.0, 0.01), target=(0.0, 0.0, 0.0), fov_y=50.0, near=0.1, far=20.0)
    path = s.save(tmp_path / "plane.gltf")
    doc = json.loads(path.read_text())
    for sampler in doc.get("samplers", []):
        sampler["wrapS"] = sampler["wrapT"] = WRAPS[wrap]
        sampler["magFilter"] = 9729  # linear, as the reference filters
    if not doc.get("samplers"):
        doc["samplers"] = [{"wrapS": WRAPS[wrap], "wrapT": WRAPS[wrap], "magFilter": 9729}]
        for texture in doc["textures"]:
            texture["sampler"] = 0
    path.write_text(json.dumps(doc))
    return ssrlab.Scene.load(path)


@pytest.mark.filterwarnings("ignore::ssrlab.NoReflectionWarning")  # a diffuse plane: only the direct light matters
@pytest.mark.parametrize("wrap", sorted(WRAPS))
def test_reference_textures_wrap_like_the_rasteriser(renderer, tmp_path, wrap):
    scene = textured_plane(tmp_path, wrap)
    f = renderer.render(scene, settings=small(width=96, height=96, layers=1))
    lit = f.gbuffer.lit[0]
    cov = f.gbuffer.coverage[0]
    assert cov.mean() > 0.9, "the plane fills the view"
    f.reference("converged", rays=1)
    direct = f.read("reference.direct")[0, :, :, :3]
    assert lit[cov].std(axis=0).max() > 0.05, "the texture must show"
    close = np.abs(direct - lit).max(-1)[cov] < 2e-2
    # Texel edges may differ by a filter footprint between the two look-ups; the rest agrees.
    assert close.mean() > 0.95, f"{wrap}: only {close.mean():.3f} of the pixels agree"
