"""What glTF scenes are made of beyond metallic-roughness: emission (emissiveFactor x
KHR_materials_emissive_strength) in the lit colour, in what SSR reflects and in the reference."""

import json
import warnings

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import pixel_rays
from conftest import small

EMISSIVE = np.array([3.0, 1.5, 0.75])
BOX_CENTER, BOX_SIZE = np.array([0.0, 0.75, -3.0]), np.array([1.5, 1.5, 1.5])


def emissive_over_mirror():
    """A mirror floor and an emissive box on it; no light, ambient or sky: every bright pixel
    is the box's own emission or its reflection."""
    s = ssrlab.Scene()
    floor = s.add_plane((0, 0, -2), (16, 16), material=ssrlab.Material(
        base_color=(1, 1, 1), roughness=0.0, metallic=1.0, reflectivity=1.0))
    lamp = ssrlab.Material(base_color=(0, 0, 0), roughness=1.0)
    lamp.emissive = tuple(EMISSIVE)
    box = s.add_box(tuple(BOX_CENTER), tuple(BOX_SIZE), material=lamp)
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 1.5, 4.0), target=(0.0, 0.3, -3.0), fov_y=50.0, near=0.1, far=50.0)
    return s, floor, box


def mirrored_box_mask(f):
    """Pixels whose camera ray meets the floor (y = 0) and whose mirrored ray then meets the box
    (a slab test), with the slab distances' margin to the box's edges."""
    cam, d = pixel_rays(f)
    t_floor = -cam[1] / d[..., 1]
    p = cam + d * t_floor[..., None]
    r = d * np.array([1.0, -1.0, 1.0])
    lo, hi = BOX_CENTER - BOX_SIZE / 2, BOX_CENTER + BOX_SIZE / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (lo - p) / r, (hi - p) / r
    t_near = np.minimum(t0, t1).max(-1)
    t_far = np.maximum(t0, t1).min(-1)
    on_floor = (t_floor > 0) & (np.abs(p[..., 0]) < 8) & (p[..., 2] > -10) & (p[..., 2] < 6)
    return on_floor & (t_far > np.maximum(t_near, 0)), t_far - np.maximum(t_near, 0)


def test_emission_is_lit_reflected_and_in_the_reference(renderer):
    scene, floor, box = emissive_over_mirror()
    f = renderer.render(scene, settings=small(width=128, height=96))
    g = f.gbuffer
    on_box = g.coverage[0] & (g.object_id[0] == box)
    on_floor = g.coverage[0] & (g.object_id[0] == floor)
    assert on_box.sum() > 200 and on_floor.sum() > 2000
    # The lit colour of a black emitter with no light is its emission (half floats: 1e-3).
    np.testing.assert_allclose(g.lit[0][on_box], np.broadcast_to(EMISSIVE, (on_box.sum(), 3)), rtol=1e-3)
    # The mirror floor itself emits and receives nothing: only its reflection is bright.
    np.testing.assert_allclose(g.lit[0][on_floor], 0.0, atol=1e-6)

    mirrored, margin = mirrored_box_mask(f)
    inside = on_floor & mirrored & (margin > 0.05)  # away from the image's edges
    outside = on_floor & ~mirrored
    assert inside.sum() > 100
    ref = f.reference("converged", rays=1)
    for name, reflection in [("SSR", f.reflection), ("reference", ref.reflection)]:
        # The mirror shows the box's emission (metal F0 = 1): exactly where the box is mirrored.
        hit = np.all(np.abs(reflection - EMISSIVE) < 0.02 * EMISSIVE, axis=-1)
        assert hit[inside].mean() > 0.95, f"{name}: {hit[inside].mean():.3f} of the mirror image shows the emission"
        dark = np.all(reflection < 1e-3, axis=-1)
        # SSR may miss a few pixels off the box's mirrored silhouette, never light dark floor.
        assert dark[outside & ~np.roll(mirrored, 1, 0) & ~np.roll(mirrored, -1, 0)].mean() > 0.98, name


def test_emissive_strength_round_trips_through_gltf(tmp_path):
    scene, _, box = emissive_over_mirror()
    path = scene.save(tmp_path / "lamp.gltf")
    doc = json.loads(path.read_text())
    assert "KHR_materials_emissive_strength" in doc["extensionsUsed"]
    m = [m for m in doc["materials"] if "KHR_materials_emissive_strength" in m.get("extensions", {})]
    assert len(m) == 1
    assert m[0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] == pytest.approx(3.0)
    np.testing.assert_allclose(m[0]["emissiveFactor"], EMISSIVE / 3.0, rtol=1e-6)
    loaded = ssrlab.Scene.load(path)
    np.testing.assert_allclose(loaded.material(box).emissive, EMISSIVE, rtol=1e-6)

    # A strength that would overflow the half-float lighting buffers is refused by name.
    m[0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = 1e6
    path.write_text(json.dumps(doc))
    with pytest.raises(ssrlab.SceneError, match="emissiveStrength"):
        ssrlab.Scene.load(path)
    with pytest.raises(ValueError, match="Material.emissive"):
        ssrlab.Material().emissive = (2e3, 0.0, 0.0)
