"""What glTF scenes are made of beyond metallic-roughness: emission (emissiveFactor x
KHR_materials_emissive_strength) in the lit colour, in what SSR reflects and in the reference."""

import json

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import pixel_rays
from conftest import model_path, small

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


def spot_floor(light):
    """A matte floor lit by one light from above; nothing else lights it."""
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), (12, 12), material=ssrlab.Material(
        base_color=(0.8, 0.8, 0.8), roughness=1.0, metallic=0.0, reflectivity=0.0))
    s.add_light(light)
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 7.0, 3.0), target=(0.0, 0.0, 0.0), fov_y=60.0, near=0.1, far=50.0)
    return s


SPOT = dict(position=(0.5, 3.0, -0.5), direction=(-0.2, -1.0, 0.1), inner_cone=0.25, outer_cone=0.6, range=6.0)


@pytest.mark.filterwarnings("ignore::ssrlab.NoReflectionWarning")  # a matte floor: nothing reflects
def test_spot_cone_and_range_follow_khr_lights_punctual(renderer):
    settings = small(width=128, height=96)
    spot = renderer.render(spot_floor(ssrlab.spot_light(intensity=20.0, **SPOT)), settings=settings)
    point = renderer.render(spot_floor(ssrlab.point_light(SPOT["position"], intensity=20.0)), settings=settings)
    # Shading is linear in the light's intensity: spot / point is the cone's and the range's
    # attenuation alone, which the extension's recommended implementation defines.
    cam, d = pixel_rays(spot)
    p = cam + d * (-cam[1] / d[..., 1])[..., None]
    to_p = p - np.array(SPOT["position"])
    dist = np.linalg.norm(to_p, axis=-1)
    axis = np.array(SPOT["direction"]) / np.linalg.norm(SPOT["direction"])
    cd = (to_p / dist[..., None]) @ axis
    scale = 1.0 / max(0.001, np.cos(SPOT["inner_cone"]) - np.cos(SPOT["outer_cone"]))
    offset = -np.cos(SPOT["outer_cone"]) * scale
    cone = np.clip(cd * scale + offset, 0, 1) ** 2
    window = np.clip(1 - (dist / SPOT["range"]) ** 4, 0, 1) ** 2
    expected = cone * window
    g = point.gbuffer
    lit_point = point.gbuffer.lit[0][..., 1]
    ok = g.coverage[0] & (lit_point > 1e-2)
    ratio = spot.gbuffer.lit[0][..., 1][ok] / lit_point[ok]
    assert ok.sum() > 5000
    np.testing.assert_allclose(ratio, expected[ok], atol=0.01)
    # The picture holds all three regions: the full cone, the falloff and the dark outside.
    assert (cone[ok] == 1).sum() > 100 and ((cone[ok] > 0.05) & (cone[ok] < 0.95)).sum() > 300
    assert (cone[ok] == 0).sum() > 300
    assert window[ok & (cone > 0)].min() < 0.8  # the range window acts too


def test_spot_light_round_trips_and_is_checked(tmp_path):
    s = spot_floor(ssrlab.spot_light(intensity=20.0, **SPOT))
    loaded = ssrlab.Scene.load(s.save(tmp_path / "spot.gltf"))
    (l,) = loaded.lights
    assert l.type == "spot"
    assert (l.inner_cone, l.outer_cone, l.range) == pytest.approx((0.25, 0.6, 6.0))
    np.testing.assert_allclose(l.direction, np.array(SPOT["direction"]) / np.linalg.norm(SPOT["direction"]), atol=1e-6)
    with pytest.raises(ValueError, match="cone"):
        ssrlab.spot_light((0, 1, 0), (0, -1, 0), inner_cone=0.7, outer_cone=0.5)


def suzanne():
    return model_path("Suzanne/Suzanne.gltf")


def test_mirror_stage_reflects_suzanne(renderer):
    scene = ssrlab.scenes.load(str(suzanne()), stage="mirror")
    stage = scene.object_count - 1
    assert scene.object_name(stage) == "stage" and scene.material(stage).roughness == 0.0
    f = renderer.render(scene, settings=small(width=128, height=96))
    g = f.gbuffer
    floor = g.coverage[0] & (g.object_id[0] == stage)
    assert floor.mean() > 0.2, "the framing camera sees the stage"
    # The floor's reflection rays that truly meet Suzanne, and SSR finding them.
    truth = f.reference("per_ray")
    on_suzanne = floor & (truth.object[0] >= 0) & (truth.object[0] != stage)
    assert on_suzanne.sum() > 50
    assert (f.rays.hit[0] & on_suzanne).sum() > 0.5 * on_suzanne.sum()


def test_stage_options_are_checked():
    with pytest.raises(ValueError, match="stage must be"):
        ssrlab.scenes.load("mirror_test", stage="marble")
    with pytest.raises(ValueError, match="glTF files only"):
        ssrlab.scenes.load("mirror_test", stage="mirror")
    with pytest.raises(ValueError, match="stage_roughness"):
        ssrlab.scenes.load("x.gltf", stage="mirror", stage_roughness=0.3)
    with pytest.raises(ValueError, match="stage_roughness"):
        ssrlab.scenes.load("x.gltf", stage="glossy", stage_roughness=2.0)


def test_render_cli_stage(tmp_path):
    import subprocess
    import sys

    path = suzanne()
    r = subprocess.run([sys.executable, "-m", "ssrlab", "render", "--scene", str(path), "--stage", "glossy",
                        "--stage-roughness", "0.3", "--width", "64", "--height", "48", "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    assert (tmp_path / "o" / "color.png").is_file()
    # The stage's material read back from the G-buffer the command wrote: the metal floor
    # (scenes.add_stage: base colour 0.95, metallic 1) fills the bottom of the framing and holds the
    # roughness asked for, to the G-buffer's 8 bits.
    g, names = ssrlab.io.read_image(tmp_path / "o" / "gbuffer_layer0.exr")
    ch = {n: g[..., i] for i, n in enumerate(names)}
    stage = ((ch["coverage"] > 0.5) & (ch["metallic"] > 0.99) &
             (np.abs(np.stack([ch["albedo.R"], ch["albedo.G"], ch["albedo.B"]], -1) - 0.95) < 0.01).all(-1))
    assert stage.mean() > 0.2 and stage[-4:].mean() > 0.9, (stage.mean(), stage[-4:].mean())
    np.testing.assert_allclose(ch["roughness"][stage], 0.3, atol=0.5 / 255 + 1e-6)


def test_unimplemented_extensions_are_named_in_one_warning(tmp_path):
    scene, _, _ = emissive_over_mirror()
    path = scene.save(tmp_path / "ext.gltf")
    doc = json.loads(path.read_text())
    doc["extensionsUsed"] = doc.get("extensionsUsed", []) + ["KHR_materials_clearcoat", "KHR_materials_sheen"]
    path.write_text(json.dumps(doc))
    with pytest.warns(ssrlab.SceneWarning) as record:
        ssrlab.Scene.load(path)
    named = [str(w.message) for w in record if "not rendered (ignored)" in str(w.message)]
    assert len(named) == 1 and "KHR_materials_clearcoat, KHR_materials_sheen" in named[0]
    doc["extensionsRequired"] = ["KHR_materials_clearcoat"]
    path.write_text(json.dumps(doc))
    with pytest.raises(ssrlab.SceneError, match="KHR_materials_clearcoat"):
        ssrlab.Scene.load(path)


@pytest.mark.filterwarnings("ignore::ssrlab.NoReflectionWarning")  # a matte floor: nothing reflects
def test_spot_light_casts_a_perspective_shadow(renderer, tmp_path):
    """A box under a shadow-casting spot light: the floor is dark exactly where the segment to the
    light crosses the box (a slab test in numpy), lit elsewhere inside the cone; glTF spot lights
    cast shadows by default."""
    light = ssrlab.spot_light((2.0, 2.5, 0.5), (-3.5, -2.5, -0.5), inner_cone=0.6, outer_cone=0.9, intensity=30.0)
    light.cast_shadow = True
    s = spot_floor(light)
    lo, hi = np.array([-0.6, 0.0, -0.6]), np.array([0.6, 1.2, 0.6])
    box = s.add_box(tuple((lo + hi) / 2), tuple(hi - lo), material=ssrlab.Material(base_color=(0.5, 0.5, 0.5)))
    f = renderer.render(s, settings=small(width=128, height=96))
    cam, d = pixel_rays(f)
    p = cam + d * (-cam[1] / d[..., 1])[..., None]
    to_light = np.array(light.position) - p
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (lo - p) / to_light, (hi - p) / to_light
    near, far = np.minimum(t0, t1).max(-1), np.maximum(t0, t1).min(-1)
    g = f.gbuffer
    floor = g.coverage[0] & (g.object_id[0] == 0)
    # Clear of the shadow's edge (the map's filtering blurs it) by a margin in the slab distances.
    shadowed = floor & (far - np.maximum(near, 0) > 0.08) & (near < 1)
    lit_area = floor & ((far < np.maximum(near, 0) - 0.08) | (near > 1.05))
    axis = np.array(light.direction) / np.linalg.norm(light.direction)
    in_cone = ((-to_light / np.linalg.norm(to_light, axis=-1, keepdims=True)) @ axis) > np.cos(0.55)
    lit = g.lit[0][..., 1]
    print(f"spot shadow: {shadowed.sum()} shadowed pixels, max lit {lit[shadowed].max():.4f}; "
          f"{(lit_area & in_cone).sum()} lit, min {lit[lit_area & in_cone].min():.4f}")
    assert shadowed.sum() > 200 and (lit_area & in_cone).sum() > 1000
    # (a pixel or two at the box's foot, where the normal offset lifts the lookup above the map's
    # depth, may leak: the contact line is the shadow's edge)
    dark = lit[shadowed] < 0.02 * np.median(lit[lit_area & in_cone])
    print(f"spot shadow: {dark.mean():.4f} of the shadowed pixels dark")
    assert dark.mean() > 0.99
    assert lit[lit_area & in_cone].min() > 0.15 * np.median(lit[lit_area & in_cone])  # distance and cosine vary
    # The box the slab tests above assume is the one drawn: the pixels whose camera ray enters
    # [lo, hi] (the same slab test, from the camera) show it, those whose ray passes clear of it do not.
    with np.errstate(divide="ignore", invalid="ignore"):
        c0, c1 = (lo - cam) / d, (hi - cam) / d
    enter, leave = np.minimum(c0, c1).max(-1), np.maximum(c0, c1).min(-1)
    seen = g.coverage[0] & (g.object_id[0] == box)
    inside, clear = leave - np.maximum(enter, 0) > 0.05, enter > leave + 0.05
    assert inside.sum() > 200 and seen[inside].mean() > 0.99 and not seen[clear].any(), \
        (int(inside.sum()), float(seen[inside].mean()), int(seen[clear].sum()))
    # Through glTF: a spot light casts its shadow by default (KHR_lights_punctual has no flag).
    path = s.save(tmp_path / "spot_shadow.gltf")
    doc = json.loads(path.read_text())
    for gl in doc["extensions"]["KHR_lights_punctual"]["lights"]:
        gl.get("extras", {}).pop("cast_shadow", None)
    path.write_text(json.dumps(doc))
    assert [l.cast_shadow for l in ssrlab.Scene.load(path).lights] == [True]


def test_point_light_asking_for_a_shadow_keeps_it(tmp_path, recwarn):
    """A point light casts a shadow when it asks (a cube map, tests/test_shadows_all_lights.py):
    no SceneWarning; glTF keeps the flag in extras, and a glTF point light without it casts none."""
    light = ssrlab.point_light((0.0, 3.0, 0.0), intensity=5.0, cast_shadow=True)
    s = ssrlab.Scene()
    s.add_light(light)
    s.add_plane((0, 0, 0), (4, 4))
    path = s.save(tmp_path / "point.gltf")
    assert [l.cast_shadow for l in ssrlab.Scene.load(path).lights] == [True]
    doc = json.loads(path.read_text())
    for gl in doc["extensions"]["KHR_lights_punctual"]["lights"]:
        gl.get("extras", {}).pop("cast_shadow", None)
    path.write_text(json.dumps(doc))
    assert [l.cast_shadow for l in ssrlab.Scene.load(path).lights] == [False]
    assert not [w for w in recwarn if issubclass(w.category, ssrlab.SceneWarning)]
