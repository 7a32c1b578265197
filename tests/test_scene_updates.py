"""Scenes that change between renders pay for what changed only, and every image stays what a fresh
renderer makes of the scene's new state:

- shadow maps (and point lights' cubes) are drawn again only when what they store changed (a light's
  frustum, a caster's transform or geometry, an alpha-tested material's test, the map's settings,
  the scene's bounds that fit it), are reused otherwise (frame.stats["shadow_maps_reused"], the
  pass's timing 0), and are never stale: each input is changed in turn and the map compared with a
  second renderer's, which renders it from nothing;
- a moved object or an edited material rewrites its entry of the scene's GPU copy (no geometry
  upload), and the BVH rebuilds the moved object's tree only; every pass family that reads the
  scene (the G-buffer, the shadow map, the BVH tracer and fallback, the probes, the GLSL and CPU
  references) gives the fresh renderer's image bit for bit."""

import numpy as np
import pytest

import ssrlab
from ssrlab import transforms as T
from conftest import small
from test_gltf_alpha import masked_scene

S = dict(width=64, height=48, shadow_map_size=256)


@pytest.fixture(scope="module")
def fresh():
    """A second renderer: it draws every scene it is given (a copy: a new scene to its caches) from nothing."""
    return ssrlab.Renderer("auto")


def render_fresh(fresh, scene, settings):
    return fresh.render(scene.copy(), settings=settings)


def shadow_textures(frame):
    """The frame's shadow maps: per-renderer scratch, read right after the render (a later render
    may reuse or redraw them)."""
    return {name: frame.read(name) for name in ("shadow_map", "shadow_cubes") if name in frame.texture_names}


def snap(frame):
    """What is compared of a frame: its image and its shadow maps, read right after the render."""
    return {"color": frame.color, **shadow_textures(frame)}


def assert_same_frame(a, b):
    a, b = (x if isinstance(x, dict) else snap(x) for x in (a, b))
    assert a.keys() == b.keys()
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def assert_same_reference(a, b):
    for name in a.TEXTURES:
        np.testing.assert_array_equal(a._read(name), b._read(name), err_msg=name)


def lit_scene():
    """spheres_and_boxes with a shadow-casting sun, a spot and a point light (a layer each for the
    sun and the spot, a cube for the point light)."""
    s = ssrlab.scenes.spheres_and_boxes(seed=2, count=6)
    s.add_light(ssrlab.spot_light((1.5, 4.0, 1.0), (-0.3, -1.0, -0.4), outer_cone=0.7, intensity=20.0,
                                  cast_shadow=True))
    s.add_light(ssrlab.point_light((-1.5, 2.5, 0.5), intensity=8.0, cast_shadow=True))
    return s


def replace_light(scene, index, light=None, **changes):
    lights = scene.lights
    if light is not None:
        lights[index] = light
    for k, v in changes.items():
        setattr(lights[index], k, v)
    scene.clear_lights()
    for light in lights:
        scene.add_light(light)


# -- shadow maps -----------------------------------------------------------------------------------------------
def test_shadow_maps_are_reused_while_nothing_they_store_changes(renderer, fresh):
    scene = lit_scene()
    s = small(**S)
    first = renderer.render(scene, settings=s)
    assert first.stats["shadow_maps_rendered"] == 3  # sun and spot layers, the point light's cube
    first = snap(first)
    again = renderer.render(scene, settings=s)
    assert again.stats["shadow_maps_reused"] == 3 and again.stats["shadow_maps_rendered"] == 0
    assert again.timings["shadow_map"] == 0.0
    assert_same_frame(first, again)
    # Reflection settings, the camera, lights' colours and receivers' filtering store nothing in a map.
    cam = scene.camera
    moved_camera = ssrlab.Camera(position=tuple(np.add(cam.position, (0.4, 0.1, 0.0))), target=tuple(cam.target),
                                 fov_y=cam.fov_y, near=cam.near, far=cam.far)
    replace_light(scene, 0, color=(1.0, 0.8, 0.6), intensity=2.0)
    sweep = [(s.replace(method="hiz", rays_per_pixel=2), scene.camera),
             (s.replace(shadow_pcf_radius=2, shadow_normal_offset=1.0), scene.camera),
             (s.replace(depth_mode="reversed_z"), moved_camera)]
    for settings, camera in sweep:
        f = renderer.render(scene, camera=camera, settings=settings)
        assert f.stats["shadow_maps_reused"] == 3, settings
        assert f.timings["shadow_map"] == 0.0
        truth = fresh.render(scene.copy(), camera=camera, settings=settings)
        assert truth.stats["shadow_maps_rendered"] == 3
        assert_same_frame(f, truth)


def _move_sphere(scene):
    scene.set_object_transform(1, T.translate((0.4, 0.3, 0.2)) @ scene.object_transform(1))


def _move_far(scene):
    # The scene's bounds grow: the sun's frustum (fitted to them) and the spot's and cube's depth ranges follow.
    scene.set_object_transform(2, T.translate((9.0, 0.0, -9.0)) @ scene.object_transform(2))


def _add_box(scene):
    scene.add_box(center=(0.5, 0.6, 0.5), size=(0.5, 0.5, 0.5))


# Each input that changes what a map stores, and the maps it changes (sun, spot, point cube).
CHANGES = {
    "sun direction": (lambda sc: replace_light(sc, 0, direction=(0.3, -1.0, -0.6)), {"shadow_map"}),
    "spot position": (lambda sc: replace_light(sc, 1, position=(1.2, 4.2, 1.3)), {"shadow_map"}),
    "spot cone": (lambda sc: replace_light(sc, 1, outer_cone=0.5), {"shadow_map"}),
    "point position": (lambda sc: replace_light(sc, 2, position=(-1.2, 2.8, 0.2)), {"shadow_cubes"}),
    "point to spot": (lambda sc: replace_light(sc, 2, ssrlab.spot_light((-1.5, 2.5, 0.5), (0.0, -1.0, 0.0),
                                                                       cast_shadow=True)), {"shadow_map"}),
    "caster moved": (_move_sphere, {"shadow_map", "shadow_cubes"}),
    "bounds grew": (_move_far, {"shadow_map", "shadow_cubes"}),
    "geometry added": (_add_box, {"shadow_map", "shadow_cubes"}),
}


@pytest.mark.parametrize("change", list(CHANGES))
def test_a_shadow_map_follows_each_input(renderer, fresh, change):
    scene = lit_scene()
    s = small(**S)
    before = renderer.render(scene, settings=s)
    old = shadow_textures(before)
    apply, touched = CHANGES[change]
    apply(scene)
    after = renderer.render(scene, settings=s)
    assert after.stats["shadow_maps_rendered"] + after.stats["shadow_maps_updated"] >= 1
    if change == "caster moved":  # the same frusta: only the texels the sphere's old and new bounds reach
        assert after.stats["shadow_maps_rendered"] == 0
    truth = render_fresh(fresh, scene, s)
    assert_same_frame(after, truth)
    new = shadow_textures(after)
    # The change does reach the map (the comparison above would hold for an unchanged map too).
    assert any(k not in old or old[k].shape != new[k].shape or not np.array_equal(old[k], new[k]) for k in touched)


@pytest.mark.parametrize("setting, value", [("shadow_map_size", 128), ("shadow_map_size", 512)])
def test_a_shadow_map_follows_its_settings(renderer, fresh, setting, value):
    scene = lit_scene()
    s = small(**S)
    renderer.render(scene, settings=s)
    f = renderer.render(scene, settings=s.replace(**{setting: value}))
    assert f.stats["shadow_maps_rendered"] == 3
    assert_same_frame(f, render_fresh(fresh, scene, s.replace(**{setting: value})))
    back = renderer.render(scene, settings=s)  # and back: the texture was replaced in between
    assert back.stats["shadow_maps_rendered"] == 3
    assert_same_frame(back, render_fresh(fresh, scene, s))


@pytest.mark.parametrize("edit", ["cutoff", "base alpha", "texture", "opaque"])
def test_a_shadow_map_follows_an_alpha_tested_material(renderer, fresh, edit):
    scene, floor, wall, quad = masked_scene()
    checker = scene.image(scene.material(quad).base_color_texture)
    flipped = scene.add_image(np.ascontiguousarray(checker[:, ::-1]), name="flipped")  # (new images are new geometry)
    s = small(**S)
    before = renderer.render(scene, settings=s).read("shadow_map")
    m = scene.material(quad)
    if edit == "cutoff":
        m.alpha_cutoff = 0.0  # every texel passes: no holes
    elif edit == "base alpha":
        m.base_color = (1.0, 1.0, 1.0, 0.4)  # every texel below the cutoff: the quad casts nothing
    elif edit == "texture":
        m.base_color_texture = flipped
    else:
        m.alpha_mode = "OPAQUE"
    scene.set_material(quad, m)
    after = renderer.render(scene, settings=s)
    assert after.stats["shadow_maps_updated"] == 1  # the quad's texels drawn again
    assert not np.array_equal(before, after.read("shadow_map"))
    assert_same_frame(after, render_fresh(fresh, scene, s))


def test_a_material_edit_without_an_alpha_test_keeps_the_maps(renderer, fresh):
    scene = lit_scene()
    s = small(**S)
    renderer.render(scene, settings=s)
    m = scene.material(3)
    m.base_color = (0.2, 0.9, 0.3, 1.0)
    m.roughness = 0.1
    scene.set_material(3, m)
    f = renderer.render(scene, settings=s)
    assert f.stats["shadow_maps_reused"] == 3
    assert_same_frame(f, render_fresh(fresh, scene, s))


def test_two_scenes_rendered_in_turn_keep_their_own_maps(renderer, fresh):
    a, b = lit_scene(), ssrlab.scenes.box_stack()
    s = small(**S)
    truth = {id(a): snap(render_fresh(fresh, a, s)), id(b): snap(render_fresh(fresh, b, s))}
    for scene in (a, b, a, b):
        f = renderer.render(scene, settings=s)
        assert f.stats["shadow_maps_reused"] == 0  # the other scene's maps were there
        assert_same_frame(f, truth[id(scene)])


def test_a_reference_after_other_renders_uses_its_own_frames_maps(renderer, fresh):
    scene, other = lit_scene(), ssrlab.scenes.box_stack()
    s = small(**S)
    f = renderer.render(scene, settings=s)
    renderer.render(other, settings=s)  # the shared maps now hold another scene's
    ref = f.reference("per_ray", viewer="camera", shadows="map")
    g = render_fresh(fresh, scene, s)
    truth = g.reference("per_ray", viewer="camera", shadows="map")
    assert_same_reference(ref, truth)


# -- moving objects and editing materials -----------------------------------------------------------------------
# Each pass family that reads the scene: the settings of a frame and the reference it is checked with.
FAMILIES = {
    "gbuffer and shadow map": (dict(method="linear"), None),
    "bvh": (dict(method="bvh"), None),
    "bvh fallback": (dict(method="hiz", fallback="bvh"), None),
    "probes": (dict(method="hiz", fallback="probes", probe_size=16), None),
    "glsl reference": (dict(method="linear"), dict(kind="converged", rays=2, tracer="glsl")),
    "cpu reference": (dict(method="linear"), dict(kind="converged", rays=2, tracer="cpu", shadows="traced")),
    "embree reference": (dict(method="linear"), dict(kind="converged", rays=2, tracer="embree")),
    "per-ray reference": (dict(method="linear"), dict(kind="per_ray")),
}


def _frame_and_reference(r, scene, settings, reference):
    f = r.render(scene, settings=settings)
    ref = f.reference(**reference) if reference else None
    return f, ref


def _assert_same(f, ref, g, gref):
    assert_same_frame(f, g)
    if ref is not None:
        assert_same_reference(ref, gref)


@pytest.mark.parametrize("family", list(FAMILIES))
def test_a_moved_object_renders_as_a_fresh_renderer_would(renderer, fresh, family):
    scene = lit_scene()
    extra, reference = FAMILIES[family]
    s = small(**S, **extra)
    _frame_and_reference(renderer, scene, s, reference)  # the caches: scene copy, BVH, Embree's scene
    before = renderer.stats
    # A sphere moves across the mirror floor, a box turns.
    scene.set_object_transform(1, T.translate((0.6, 0.2, 0.4)) @ scene.object_transform(1))
    scene.set_object_transform(4, scene.object_transform(4) @ T.rotate((0, 1, 0), 30.0))
    f, ref = _frame_and_reference(renderer, scene, s, reference)
    after = renderer.stats
    assert after["scene_uploads"] == before["scene_uploads"]  # no geometry upload
    assert after["bvh_builds"] == before["bvh_builds"]
    assert after["object_updates"] == before["object_updates"] + 2
    # The same frusta: each map redraws the texels the moved objects reach, or nothing.
    assert f.stats["shadow_maps_rendered"] == 0 and f.stats["shadow_maps_updated"] >= 1
    if after["bvh_updates"] > before["bvh_updates"]:  # the families that trace rebuilt the moved objects only
        moved = scene.object_mesh(1)["indices"].shape[0] + scene.object_mesh(4)["indices"].shape[0]
        assert after["bvh_update_last_triangles"] == moved
    g, gref = _frame_and_reference(fresh, scene.copy(), s, reference)
    _assert_same(f, ref, g, gref)


@pytest.mark.parametrize("family", ["gbuffer and shadow map", "bvh", "cpu reference", "glsl reference"])
def test_an_edited_material_renders_as_a_fresh_renderer_would(renderer, fresh, family):
    scene = lit_scene()
    extra, reference = FAMILIES[family]
    s = small(**S, **extra)
    _frame_and_reference(renderer, scene, s, reference)
    before = renderer.stats
    floor = scene.material(0)
    floor.roughness = 0.3
    floor.base_color = (0.3, 0.35, 0.6, 1.0)
    scene.set_material(0, floor)
    ball = scene.material(1)
    ball.metallic = 1.0
    ball.reflectivity = 0.7
    scene.set_material(1, ball)
    f, ref = _frame_and_reference(renderer, scene, s, reference)
    after = renderer.stats
    assert after["scene_uploads"] == before["scene_uploads"] and after["bvh_builds"] == before["bvh_builds"]
    assert after["material_updates"] == before["material_updates"] + 2
    assert after["bvh_updates"] == before["bvh_updates"]  # no alpha test changed: the BVH stays
    g, gref = _frame_and_reference(fresh, scene.copy(), s, reference)
    _assert_same(f, ref, g, gref)


@pytest.mark.parametrize("tracer", ["glsl", "cpu"])
def test_an_alpha_tested_object_moved_and_edited_traces_as_a_fresh_renderer_would(renderer, fresh, tracer):
    scene, floor, wall, quad = masked_scene()
    shadows = "traced" if tracer == "cpu" else "map"
    s = small(**S, method="bvh")
    renderer.render(scene, settings=s).reference("converged", rays=2, tracer=tracer, shadows=shadows)
    scene.set_object_transform(quad, T.translate((0.3, 0.1, 0.5)) @ T.rotate((0, 1, 0), 20.0))
    m = scene.material(quad)
    m.alpha_cutoff = 0.9
    scene.set_material(quad, m)
    m = scene.material(wall)
    m.alpha_mode = "MASK"  # an opaque material becomes alpha-tested (its base alpha is 1: no holes)
    scene.set_material(wall, m)
    f = renderer.render(scene, settings=s)
    ref = f.reference("converged", rays=2, tracer=tracer, shadows=shadows)
    g = fresh.render(scene.copy(), settings=s)
    gref = g.reference("converged", rays=2, tracer=tracer, shadows=shadows)
    _assert_same(f, ref, g, gref)


def test_a_material_shared_by_objects_edited_for_one(renderer, fresh):
    scene = ssrlab.scenes.hall(columns_per_side=3)
    s = small(**S, method="bvh")
    renderer.render(scene, settings=s)
    uploads = renderer.stats["scene_uploads"]
    column = next(i for i in range(scene.object_count) if scene.object_name(i).startswith("column"))
    m = scene.material(column)
    m.base_color = (0.9, 0.1, 0.1, 1.0)
    scene.set_material(column, m)  # the columns share a material: this one gets its own
    f = renderer.render(scene, settings=s)
    assert renderer.stats["scene_uploads"] == uploads
    assert_same_frame(f, render_fresh(fresh, scene, s))


def test_a_reference_is_refused_for_a_frame_rendered_before_a_move(renderer):
    scene = lit_scene()
    f = renderer.render(scene, settings=small(**S))
    scene.set_object_transform(1, T.translate((0.2, 0.0, 0.0)) @ scene.object_transform(1))
    with pytest.raises(ValueError, match="scene"):
        f.reference("converged", rays=1)


def test_a_sequence_keeps_its_history_when_objects_move(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(seed=1, count=8, floor_roughness=0.2)
    s = ssrlab.Settings(width=64, height=48, shadow_map_size=256, temporal_reflections=True)
    frames = []
    for i, f in enumerate(renderer.render_sequence(scene, [scene.camera] * 3, s)):
        frames.append(f.read("reflection.temporal")[0, ..., 3].max())
        scene.set_object_transform(1, T.translate((0.05, 0.0, 0.0)) @ scene.object_transform(1))
    assert frames == [1, 2, 3]  # a move is no new scene: the history goes on (reprojection handles motion)
    scene.add_box(center=(0.0, 0.3, 1.0), size=(0.2, 0.2, 0.2))
    after = [f.read("reflection.temporal")[0, ..., 3].max()
             for f in renderer.render_sequence(scene, [scene.camera] * 2, s)]
    assert after == [1, 2]


def test_moving_an_object_does_not_measure_the_deep_gbuffer_again(renderer):
    scene = ssrlab.scenes.box_stack()
    s = small(width=64, height=48, layers=2, deep_gbuffer="auto")
    renderer.render(scene, settings=s)
    measured = len(renderer.deep_gbuffer_measurements)
    scene.set_object_transform(3, T.translate((0.1, 0.0, 0.0)) @ scene.object_transform(3))
    f = renderer.render(scene, settings=s)
    assert len(renderer.deep_gbuffer_measurements) == measured
    assert f.warmup_runs == 0  # the same programs and buffers: no first-use run either


def test_set_object_transform_checks_the_matrix():
    scene = ssrlab.scenes.box_stack()
    name = scene.object_name(2)
    with pytest.raises(ValueError, match=f"object '{name}'.*singular"):
        scene.set_object_transform(2, np.diag([1.0, 0.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match=f"object '{name}'"):
        scene.set_object_transform(2, np.full((4, 4), np.nan))
    with pytest.raises(IndexError):
        scene.set_object_transform(scene.object_count, np.eye(4))


def test_revisions_say_what_changed():
    scene = ssrlab.scenes.box_stack()
    r0 = (scene.revision, scene.geometry_revision, scene.transforms_revision, scene.materials_revision,
          scene.lights_revision)
    scene.set_object_transform(1, np.eye(4))
    assert scene.transforms_revision == scene.revision > r0[0] and scene.geometry_revision == r0[1]
    scene.set_material(1, ssrlab.Material(base_color=(1, 0, 0)))
    assert scene.materials_revision == scene.revision and scene.geometry_revision == r0[1]
    scene.clear_lights()
    assert scene.lights_revision == scene.revision and scene.geometry_revision == r0[1]
    scene.ambient = (0.2, 0.2, 0.2)
    assert scene.geometry_revision == r0[1]
    scene.add_box()
    assert scene.geometry_revision == scene.revision
