"""KHR_texture_transform beyond the alpha mask (tests/test_gltf_alpha.py): a rotated normal texture
turns the tangent frame of a mesh's own tangents with it, as the derivative frame of a mesh
without tangents does; and the Embree + C++ reference samples every texture at its transformed
coordinates, as the G-buffer and the GLSL tracers do."""

import json
import math
import warnings

import numpy as np
import pytest

import ssrlab
from conftest import small

# A tangent-space normal tilted 30 degrees toward +u (the texture's own axis).
TILT = (0.5, 0.0, math.sqrt(0.75))


def _normal_rgba(n=4):
    img = np.zeros((n, n, 4), np.uint8)
    img[..., :3] = np.round((np.array(TILT) + 1.0) / 2.0 * 255.0).astype(np.uint8)
    img[..., 3] = 255
    return img


def _tilted_floor(with_tangents: bool) -> ssrlab.Scene:
    """A matte floor quad facing +y, u along +x and v along -z (so that B = N x T for T = +x),
    with a constant normal texture; a light straight above."""
    s = ssrlab.Scene()
    tex = s.add_image(_normal_rgba(), name="tilt")
    mat = ssrlab.Material(base_color=(0.8, 0.8, 0.8), roughness=1.0, reflectivity=0.0, normal_texture=tex,
                          name="tilted")
    pos = [(-1, 0, 1), (1, 0, 1), (1, 0, -1), (-1, 0, -1)]
    uvs = [((x + 1) / 2, (1 - z) / 2) for x, _, z in pos]
    tangents = [(1, 0, 0, 1)] * 4 if with_tangents else None
    s.add_mesh(pos, [(0, 1, 2), (0, 2, 3)], normals=[(0, 1, 0)] * 4, uvs=uvs, tangents=tangents, material=mat,
               name="floor")
    s.add_light(ssrlab.directional_light((0, -1, 0), intensity=2.0))
    s.camera = ssrlab.Camera(position=(0.0, 2.5, 0.01), target=(0.0, 0.0, 0.0), fov_y=40.0, near=0.1, far=20.0)
    return s


def _with_transform(scene: ssrlab.Scene, tmp_path, name: str, material: str, slot: str, transform: dict):
    """`scene` saved as glTF, with KHR_texture_transform `transform` on texture `slot` of
    `material`, loaded back."""
    path = scene.save(tmp_path / f"{name}.gltf")
    doc = json.loads(path.read_text())
    (m,) = [m for m in doc["materials"] if m.get("name") == material]
    ref = m[slot] if slot in m else m["pbrMetallicRoughness"][slot]
    ref["extensions"] = {"KHR_texture_transform": transform}
    doc.setdefault("extensionsUsed", []).append("KHR_texture_transform")
    path.write_text(json.dumps(doc))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)  # the extension is rendered: not named
        return ssrlab.Scene.load(path)


@pytest.mark.parametrize("rotation", [0.0, math.pi / 2, 2.0])
def test_rotated_normal_texture_turns_the_vertex_tangent_frame(renderer, tmp_path, rotation):
    """With its own tangents or without (the frame from the coordinates' screen derivatives, which
    follows the transform by construction), the same floor gets the same normals."""
    settings = small(width=96, height=96, layers=1, method="off", shadow_map_size=0)
    frames = {}
    for with_tangents in (True, False):
        scene = _with_transform(_tilted_floor(with_tangents), tmp_path, f"t{int(with_tangents)}", "tilted",
                                "normalTexture", {"rotation": rotation, "scale": [2.0, 2.0]})
        frames[with_tangents] = renderer.render(scene, settings=settings)
    cov = frames[True].gbuffer.coverage[0] & frames[False].gbuffer.coverage[0]
    assert cov.sum() > 2000
    a = frames[True].gbuffer.normal[0][cov]
    b = frames[False].gbuffer.normal[0][cov]
    np.testing.assert_allclose(a, b, atol=2e-2)
    # The tilt is seen (30 degrees off the surface normal), and it turns with the rotation.
    view_tilt = np.median(a, axis=0)
    assert abs(np.linalg.norm(view_tilt[:3]) - 1.0) < 1e-2
    unrotated = _with_transform(_tilted_floor(True), tmp_path, "r0", "tilted", "normalTexture",
                                {"rotation": 0.0, "scale": [2.0, 2.0]})
    base = np.median(renderer.render(unrotated, settings=settings).gbuffer.normal[0][cov], axis=0)
    turned = math.degrees(math.acos(np.clip(np.dot(base[:3], view_tilt[:3]), -1, 1)))
    expected = math.degrees(math.acos(0.75 + 0.25 * math.cos(rotation)))  # two 30-degree tilts, `rotation` apart
    assert turned == pytest.approx(expected, abs=3.0)


def _mirror_and_wall():
    """A mirror floor reflecting a matte wall with a red/blue checker base colour and a tilted
    normal texture, lit from the front (no shadow: the CPU tracer traces its own)."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), (12, 12), material=ssrlab.Material(base_color=(1, 1, 1), roughness=0.0, metallic=1.0,
                                                               reflectivity=1.0), name="floor")
    n = 16
    c = np.arange(n) // 4
    checker = np.zeros((n, n, 4), np.uint8)
    red = (c[:, None] + c[None, :]) % 2 == 0
    checker[..., 0] = np.where(red, 230, 20)
    checker[..., 2] = np.where(red, 20, 230)
    checker[..., 3] = 255
    base = s.add_image(checker, name="checker")
    tilt = s.add_image(_normal_rgba(), name="tilt")
    mat = ssrlab.Material(base_color=(1, 1, 1), roughness=1.0, reflectivity=0.0, base_color_texture=base,
                          normal_texture=tilt, name="wall")
    pos = [(-2, 0.2, -2), (2, 0.2, -2), (2, 2.2, -2), (-2, 2.2, -2)]
    s.add_mesh(pos, [(0, 1, 2), (0, 2, 3)], normals=[(0, 0, 1)] * 4,
               uvs=[((x + 2) / 4, (2.2 - y) / 2) for x, y, _ in pos], tangents=[(1, 0, 0, 1)] * 4, material=mat,
               name="wall")
    s.add_light(ssrlab.directional_light((0.3, -0.4, -1.0), intensity=3.0))
    s.ambient = (0.05, 0.05, 0.05)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 1.0, 3.0), target=(0.0, 0.3, -2.0), fov_y=50.0, near=0.1, far=30.0)
    return s


def test_cpu_reference_samples_transformed_textures(renderer, tmp_path):
    """The converged reference on Embree + C++ equals the GLSL tracer's where the wall's base colour
    (moved by one checker cell) and normal texture (rotated) carry a transform."""
    scene = _with_transform(_mirror_and_wall(), tmp_path, "moved", "wall", "baseColorTexture",
                            {"offset": [0.25, 0.0]})
    path = scene.save(tmp_path / "moved2.gltf")
    doc = json.loads(path.read_text())
    (m,) = [m for m in doc["materials"] if m.get("name") == "wall"]
    m["normalTexture"]["extensions"] = {"KHR_texture_transform": {"rotation": math.pi / 2}}
    path.write_text(json.dumps(doc))
    scene = ssrlab.Scene.load(path)
    f = renderer.render(scene, settings=small(width=96, height=72, layers=2))
    glsl = f.reference("converged", rays=1, tracer="glsl").reflection
    cpu = f.reference("converged", rays=1, tracer="cpu").reflection
    lit = glsl[..., :3].max(axis=-1) > 0.05
    assert lit.sum() > 300, "the floor reflects the wall"
    # Red and blue cells in the same places, and the same shading of the tilted normals.
    red_g = glsl[..., 0] > glsl[..., 2]
    red_c = cpu[..., 0] > cpu[..., 2]
    assert (red_g[lit] == red_c[lit]).mean() > 0.97
    assert 0.2 < red_g[lit].mean() < 0.8
    np.testing.assert_allclose(cpu[lit][:, :3], glsl[lit][:, :3], atol=0.03, rtol=0.05)
