"""KHR_materials_ior and KHR_materials_specular: a dielectric's F0 as the extensions define it,
min(((ior - 1) / (ior + 1))^2 x specularColorFactor, 1) x specularFactor, through a glTF file
into the lit colour."""

import json

import numpy as np
import pytest

import ssrlab
from conftest import small

CAMERA = ssrlab.Camera(position=(0.0, 3.0, 3.0), target=(0.0, 0.0, 0.0), fov_y=20.0, near=0.1, far=50.0)


def specular_floor(**material):
    """A black dielectric floor (no diffuse) lit by a directional light travelling along the
    camera's view axis: every pixel's half vector is within a few degrees of its view vector, so
    Schlick's (1 - V.H)^5 is below 1e-10 and the lit colour is F0 times one factor per pixel."""
    s = ssrlab.Scene()
    m = ssrlab.Material(base_color=(0, 0, 0), metallic=0.0, roughness=1.0, reflectivity=0.0, name="floor")
    for k, v in material.items():
        setattr(m, k, v)
    s.add_plane((0, 0, 0), (8, 8), material=m)
    view = np.array(CAMERA.target) - np.array(CAMERA.position)
    s.add_light(ssrlab.directional_light(tuple(view / np.linalg.norm(view)), intensity=3.0))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = CAMERA
    return s


@pytest.mark.filterwarnings("ignore::ssrlab.NoReflectionWarning")  # nothing reflects: lighting only
def test_ior_and_specular_set_f0_through_gltf(renderer, tmp_path):
    cases = {"default": {}, "ior2": dict(ior=2.0),
             "specular": dict(specular=0.5, specular_color=(1.0, 0.5, 0.25))}
    expected = {"default": np.full(3, 0.04), "ior2": np.full(3, (1 / 3) ** 2),
                "specular": 0.04 * 0.5 * np.array([1.0, 0.5, 0.25])}
    lit = {}
    for name, material in cases.items():
        path = specular_floor(**material).save(tmp_path / f"{name}.gltf")
        doc = json.loads(path.read_text())
        ext = doc["materials"][0].get("extensions", {})
        assert ("KHR_materials_ior" in ext) == ("ior" in material)
        assert ("KHR_materials_specular" in ext) == ("specular" in material)
        loaded = ssrlab.Scene.load(path)
        np.testing.assert_allclose(loaded.material(0).dielectric_f0, expected[name], rtol=1e-6)
        f = renderer.render(loaded, settings=small(width=96, height=64))
        assert f.gbuffer.coverage[0].all()
        lit[name] = f.gbuffer.lit[0].reshape(-1, 3).astype(np.float64)
    base = lit["default"]
    assert base.min() > 3e-3
    for name in ("ior2", "specular"):
        ratio = lit[name] / base
        print(f"{name}: lit / default lit deviates from F0 / 0.04 by at most "
              f"{np.abs(ratio / (expected[name] / 0.04) - 1).max():.2e} (relative) on {len(ratio)} pixels")
        np.testing.assert_allclose(ratio, np.broadcast_to(expected[name] / 0.04, ratio.shape), rtol=3e-3,
                                   err_msg=name)


def test_extension_values_are_checked(tmp_path):
    path = specular_floor(ior=1.8).save(tmp_path / "f.gltf")
    doc = json.loads(path.read_text())
    doc["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 0.5
    path.write_text(json.dumps(doc))
    with pytest.raises(ssrlab.SceneError, match="ior"):
        ssrlab.Scene.load(path)
    doc["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 1.8
    doc["materials"][0]["extensions"]["KHR_materials_specular"] = {"specularFactor": 0.3,
                                                                   "specularTexture": {"index": 0}}
    doc["extensionsUsed"] = ["KHR_materials_ior", "KHR_materials_specular"]
    path.write_text(json.dumps(doc))
    # The file has no texture 0: a clear error naming the extension's texture.
    with pytest.raises(ssrlab.SceneError, match="KHR_materials_specular.specularTexture"):
        ssrlab.Scene.load(path)
    del doc["materials"][0]["extensions"]["KHR_materials_specular"]["specularTexture"]
    path.write_text(json.dumps(doc))
    loaded = ssrlab.Scene.load(path)
    assert loaded.material(0).specular == pytest.approx(0.3) and loaded.material(0).ior == pytest.approx(1.8)
    with pytest.raises(ValueError, match="ior"):
        ssrlab.Material().ior = 0.7
    with pytest.raises(ValueError, match="specular"):
        ssrlab.Material().specular = 1.5


def test_references_reflect_the_material_f0(renderer):
    """A mirror floor reflecting a black dielectric wall (its light is all specular, F0-scaled):
    the converged reference on the GLSL tracer and on Embree + C++ see the wall's own F0
    (KHR_materials_ior), not the default 0.04."""
    refl = {}
    for ior in (1.5, 2.0):
        s = ssrlab.Scene()
        s.add_plane((0, 0, 0), (12, 12), material=ssrlab.Material(base_color=(1, 1, 1), roughness=0.0, metallic=1.0,
                                                                   reflectivity=1.0), name="floor")
        wall = ssrlab.Material(base_color=(0, 0, 0), metallic=0.0, roughness=0.6, reflectivity=0.0, name="wall")
        wall.ior = ior
        s.add_plane((0, 1.5, -2.0), (8, 3), normal=(0, 0, 1), material=wall, name="wall")
        s.add_light(ssrlab.directional_light((0.0, -0.3, -1.0), intensity=4.0))
        s.ambient = (0.0, 0.0, 0.0)
        s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
        s.camera = ssrlab.Camera(position=(0.0, 1.0, 3.0), target=(0.0, 0.3, -2.0), fov_y=45.0, near=0.1, far=30.0)
        f = renderer.render(s, settings=small(width=80, height=60, layers=2))
        refl[ior] = {t: f.reference("converged", rays=1, tracer=t).reflection[..., :3] for t in ("glsl", "cpu")}
    seen = refl[1.5]["glsl"].max(axis=-1) > 1e-3
    assert seen.sum() > 200, "the floor reflects the lit wall"
    for ior in (1.5, 2.0):
        np.testing.assert_allclose(refl[ior]["cpu"][seen], refl[ior]["glsl"][seen], rtol=0.03, atol=1e-4,
                                   err_msg=f"ior {ior}")
    # F0 (1/3)^2 against 0.04: the wall's specular light (Schlick's F0 term dominates off grazing).
    ratio = np.median(refl[2.0]["cpu"][seen] / np.maximum(refl[1.5]["cpu"][seen], 1e-9))
    assert 2.0 < ratio < 2.9, ratio
