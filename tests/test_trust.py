"""Numbers a researcher can trust at first contact: glTF materials reflect as their
metallic-roughness parameters say, the pbr composite carries the GGX directional albedo, the
converged reference is exact (robust origins, traced shadows), and timings never include
compilation or first-use costs."""

import warnings

import numpy as np
import pytest

import ssrlab
import ssrlab.analytic
from conftest import assert_finite, model_path, small


from ssrlab.analytic import specular_albedo_lookup as bilinear


# -- the split-sum table -----------------------------------------------------------------------------

@pytest.mark.parametrize("roughness,nov", [(0.2, 0.9), (0.5, 0.5), (0.8, 0.3), (1.0, 1.0)])
def test_specular_albedo_table_matches_the_samplers_integral(renderer, roughness, nov):
    """A and B equal a Monte-Carlo integral over directions drawn by the tracers' own GLSL sampler."""
    table = renderer.specular_albedo_table()
    assert table.shape == (32, 32, 2)
    alpha = roughness ** 2
    v = np.array([np.sqrt(1 - nov * nov), 0.0, nov])
    s = renderer.sample_reflections("ggx", alpha, v, 1 << 17, seed=3)  # another sampler than the table's
    h = s["l"] + v
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    fc = (1 - np.clip(h @ v, 0, 1)) ** 5
    w = s["weight"]
    expected = np.array([np.mean(w * (1 - fc)), np.mean(w * fc)])
    # Table entries sit on a grid: evaluate it where the integral was taken.
    got = bilinear(table, np.array(nov), np.array(roughness))
    np.testing.assert_allclose(got, expected, atol=6e-3)


def test_specular_albedo_table_limits(renderer):
    t = renderer.specular_albedo_table()
    e = t.sum(-1)  # the directional albedo with F = 1
    assert np.all(e <= 1.0 + 1e-4), "a lobe cannot reflect more than it receives"
    np.testing.assert_allclose(t[0, -1], [1.0, 0.0], atol=1e-5)  # a mirror seen head-on
    assert np.all(np.diff(e[:, -1]) <= 1e-4), "at normal incidence rougher lobes lose more to masking"


# -- glTF materials reflect by default ------------------------------------------------------------------

def test_material_reflectivity_auto_api(tmp_path):
    m = ssrlab.Material(reflectivity="auto")
    assert m.reflectivity == "auto"
    assert ssrlab.Material().reflectivity == 0.0
    with pytest.raises(ValueError, match="reflectivity"):
        ssrlab.Material(reflectivity="shiny")
    with pytest.raises(ValueError, match="reflectivity"):
        ssrlab.Material(reflectivity=-1.0)
    m.reflectivity = 0.25
    assert m.reflectivity == pytest.approx(0.25)
    m.reflectivity = "auto"
    # Round trip through glTF: "auto" writes no ssrlab extras, an explicit r does.
    scene = ssrlab.Scene()
    scene.add_plane(material=ssrlab.Material(reflectivity="auto", metallic=1.0, roughness=0.1))
    scene.add_box(center=(0, 0.5, 0), material=ssrlab.Material(reflectivity=0.4))
    path = scene.save(tmp_path / "r.glb")
    back = ssrlab.Scene.load(path)
    assert sorted(str(back.material(i).reflectivity)[:3] for i in range(back.object_count)) == ["0.4", "aut"]


@pytest.mark.parametrize("model", ["Suzanne/Suzanne.gltf", "2CylinderEngine/2CylinderEngine.glb"])
def test_user_gltf_reflects_at_default_settings(renderer, model):
    scene = ssrlab.scenes.load(str(model_path(model)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.NoReflectionWarning)
        f = renderer.render(scene, settings=small())
    assert {"trace_linear", "resolve"} <= set(f.passes)
    g = f.gbuffer
    covered = g.coverage[0]
    assert (g.reflectivity[0][covered] > 0).all(), "every glTF surface reflects some light (F0 >= 0.04)"
    refl = np.abs(f.reflection).sum(-1)
    metal_smooth = covered & (g.metallic[0] > 0.5) & (g.roughness[0] < 0.5)
    if "Suzanne" in model:
        assert metal_smooth.sum() > 100
        assert (refl[metal_smooth] > 0).mean() > 0.99
        # A metallic surface reflects more than any dielectric (F0 = its dark base colour, not
        # 0.04: a dielectric's r stays below ~0.06 away from grazing angles).
        assert g.reflectivity[0][metal_smooth].mean() > 0.08
    assert (refl[covered] > 0).mean() > 0.99
    assert_finite(f.color, "color")


def test_auto_reflectivity_is_the_specular_albedo(renderer):
    """r of an 'auto' material is the luminance of F0 A + B at the pixel's view angle."""
    scene = ssrlab.scenes.mirror_test()
    for i in range(scene.object_count):
        m = scene.material(i)
        if m.reflectivity > 0.5:  # the mirror floor: make it a gold-ish glossy metal, auto
            m.metallic, m.roughness, m.base_color = 1.0, 0.3, (0.9, 0.7, 0.3, 1.0)
            m.reflectivity = "auto"
            scene.set_material(i, m)
    f = renderer.render(scene, settings=small(width=128, height=72))
    g = f.gbuffer
    floor = g.coverage[0] & (g.metallic[0] > 0.5)
    assert floor.sum() > 500
    pos_dir = ssrlab.analytic.pixel_rays(f)[1]  # world-space unit view rays
    nov = np.clip(-pos_dir[..., 1], 0, 1)  # the floor's normal is +y
    ab = bilinear(renderer.specular_albedo_table(), nov, g.roughness[0])
    F0 = g.albedo[0]
    e = F0 * ab[..., :1] + ab[..., 1:]
    expected = e @ np.array([0.2126, 0.7152, 0.0722])
    np.testing.assert_allclose(g.reflectivity[0][floor], expected[floor], atol=2.5 / 255)


def test_no_reflection_warning(renderer):
    scene = ssrlab.Scene()
    scene.add_plane(size=(4, 4), material=ssrlab.Material(reflectivity=0.0))
    scene.add_light(ssrlab.directional_light((0, -1, -0.3)))
    scene.camera = ssrlab.Camera(position=(0, 2, 3), target=(0, 0, 0))
    with pytest.warns(ssrlab.NoReflectionWarning, match="no surface"):
        renderer.render(scene, settings=small())
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.NoReflectionWarning)
        renderer.render(scene, settings=small(method="off"))


# -- the physical composite -------------------------------------------------------------------------------

@pytest.mark.parametrize("auto", [False, True])
def test_pbr_composite_is_direct_plus_albedo_weighted_reflection(renderer, auto):
    scene = ssrlab.scenes.spheres_and_boxes(floor_roughness=0.3)
    if auto:
        for i in range(scene.object_count):
            m = scene.material(i)
            m.reflectivity = "auto"
            scene.set_material(i, m)
    f = renderer.render(scene, settings=small(composite="pbr", width=128, height=72))
    g = f.gbuffer
    cov = g.coverage[0]
    cam, d = ssrlab.analytic.pixel_rays(f)
    n_world = g.normal[0] @ f.view_matrix[:3, :3]  # view -> world (rotation)
    nov = np.clip(np.sum(-d * n_world, -1), 0, 1)
    ab = bilinear(renderer.specular_albedo_table(), nov, g.roughness[0])
    F0 = 0.04 * (1 - g.metallic[0][..., None]) + g.albedo[0] * g.metallic[0][..., None]
    k = np.ones_like(nov) if auto else g.reflectivity[0]
    expected = g.lit[0] + (k * (g.reflectivity[0] > 0))[..., None] * (F0 * ab[..., :1] + ab[..., 1:]) * f.reflection
    np.testing.assert_allclose(f.color[cov], expected[cov], rtol=2e-3, atol=2e-3)


# -- the exact reference ------------------------------------------------------------------------------------

def test_converged_reference_does_not_depend_on_origin_bias(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(floor_roughness=0.0)
    refs = []
    for bias in (0.002, 0.05):
        f = renderer.render(scene, settings=small(origin_bias=bias))
        refs.append(f.reference("converged", rays=1).reflection)
    np.testing.assert_allclose(refs[0], refs[1], atol=1e-5)


def test_traced_shadows_agree_with_the_shadow_map_away_from_edges(renderer):
    scene = ssrlab.scenes.spheres_and_boxes(floor_roughness=0.0)
    f = renderer.render(scene, settings=small(width=160, height=90, shadow_map_size=4096, shadow_pcf_radius=0))
    traced = f.reference("converged", rays=1, shadows="traced")
    t_color = traced.color.copy()
    mapped = f.reference("converged", rays=1, shadows="map")
    assert_finite(t_color, "traced reference")
    diff = np.abs(t_color - mapped.color).max(-1)
    # The two differ only along shadow boundaries (and where the map's bias lets light leak at contacts).
    assert (diff < 1e-2).mean() > 0.95
    assert (diff > 1e-2).any()  # they are two different shadowings: somewhere (a contact, an edge) they differ
    # The pixel's own direct light in the reference is the lit G-buffer's where shadows agree.
    direct = f.read("reference.direct")[0, :, :, :3]
    lit = f.gbuffer.lit[0]
    cov = f.gbuffer.coverage[0]
    assert (np.abs(direct - lit).max(-1)[cov] < 2e-2).mean() > 0.95


def test_reference_cache_key_holds_the_shader_sources(monkeypatch):
    from ssrlab import reference

    scene = ssrlab.scenes.mirror_test()
    s = small()
    k1 = reference.cache_key("converged", scene, scene.camera, s, 1, 0)
    assert k1 == reference.cache_key("converged", scene, scene.camera, s, 1, 0)
    assert k1 != reference.cache_key("converged", scene, scene.camera, s, 1, 0, shadows="map")
    monkeypatch.setattr(reference, "shader_sources_hash", lambda: "another shader tree")
    assert k1 != reference.cache_key("converged", scene, scene.camera, s, 1, 0)


# -- timings without compilation ----------------------------------------------------------------------------

def test_first_use_is_paid_outside_the_timers():
    r = ssrlab.Renderer()
    scene = ssrlab.scenes.spheres_and_boxes()
    s = small(method="hiz")
    f1 = r.render(scene, settings=s)
    assert f1.warmup_runs == 1, "a new variant runs once untimed"
    programs = r.compiled_programs
    f2 = r.render(scene, settings=s)
    assert f2.warmup_runs == 0 and r.compiled_programs == programs, "the timed run compiled nothing"
    assert f1.passes == f2.passes and set(f1.timings) == set(f2.timings)
    # Another variant (the pbr composite) is warmed again; prepare() warms ahead.
    r.prepare(s.replace(composite="pbr"), scene)
    assert r.render(scene, settings=s.replace(composite="pbr")).warmup_runs == 0
    # The same variant renders the same image whether or not it was warmed in this call.
    np.testing.assert_array_equal(f1.color, f2.color)
