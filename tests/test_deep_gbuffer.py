"""The deep G-buffer in one geometry pass (Settings.deep_gbuffer 'lists': per-pixel fragment
lists, Yang et al. 2010) against depth peeling (seed 000, 1.5.1 and 2.2): the same layers bit
for bit, ties at equal depth included, and a fragment store that never truncates."""

import time

import numpy as np
import pytest

import ssrlab
from conftest import bits, small

LAYER_COUNTS = (1, 2, 4, 8, 16)
TEXTURES = ("gbuffer.depth", "gbuffer.normal", "gbuffer.albedo", "gbuffer.material")


def tiny(**kw) -> ssrlab.Settings:
    # The G-buffer only: no shadow map, no reflections (the passes after it read the same textures).
    kw.setdefault("width", 48)
    kw.setdefault("height", 32)
    return small(shadow_map_size=0, method="off", **kw)


def assert_same_layers(renderer, scene, camera, what: str, **kw) -> ssrlab.Frame:
    peel = renderer.render(scene, camera, tiny(deep_gbuffer="peel", **kw))
    lists = renderer.render(scene, camera, tiny(deep_gbuffer="lists", **kw))
    assert lists.stats["deep_gbuffer_method"] == "lists" and "deep_gbuffer_method" not in peel.stats
    # A scene with an emissive texture has a 4th output (gbuffer.emission), in both or neither.
    # ... and one with a KHR_materials_specular texture an output after it (gbuffer.specular).
    extra = tuple(n for n in ("gbuffer.emission", "gbuffer.specular") if n in peel.texture_names)
    assert extra == tuple(n for n in ("gbuffer.emission", "gbuffer.specular") if n in lists.texture_names)
    for name in TEXTURES + extra:
        a, b = peel.read(name), lists.read(name)
        diff = bits(a) != bits(b)
        if diff.any():
            layer, y, x = np.argwhere(diff.reshape(diff.shape[0], diff.shape[1], diff.shape[2], -1).any(-1))[0]
            raise AssertionError(f"{what} {kw}: {name} differs at {int(diff.sum())} components, first at layer "
                                 f"{layer} pixel ({x}, {y}): peel {a[layer, y, x]} lists {b[layer, y, x]}")
    gp, gl = peel.gbuffer, lists.gbuffer
    np.testing.assert_array_equal(gp.coverage, gl.coverage)
    np.testing.assert_array_equal(gp.object_id, gl.object_id)
    assert peel.stats["layers_used"] == lists.stats["layers_used"]
    assert [n > 0 for n in peel.layer_samples] == [n > 0 for n in lists.layer_samples]
    # Pixels the lists' write covered: exactly the covered texels of each layer.
    assert lists.layer_samples == [int(c) for c in gl.coverage.sum(axis=(1, 2))]
    return lists


def scene_cases():
    cases = [pytest.param(name, id=name) for name in ssrlab.scenes.SCENES]
    cases += [pytest.param(f"model:{m}", id=m) for m in ("Suzanne", "2CylinderEngine")]
    return cases


def load(name: str) -> ssrlab.Scene:
    if name.startswith("model:"):
        try:
            path = ssrlab.models.find(name[6:])
        except (FileNotFoundError, ValueError, KeyError) as e:
            pytest.skip(f"sample model {name[6:]} not found: {e}")
        return ssrlab.scenes.load(str(path))
    return ssrlab.scenes.load(name)


@pytest.mark.parametrize("name", scene_cases())
def test_lists_equal_peeling_bit_for_bit(renderer, name):
    """Every procedural scene and both sample models (alpha-less glTF), 1-16 layers, back faces
    culled and not: depth, normal, albedo (sRGB8), material, object ids and coverage agree."""
    scene = load(name)
    deepest = 0
    for culling in (False, True):
        for layers in LAYER_COUNTS:
            f = assert_same_layers(renderer, scene, None, name, layers=layers, backface_culling=culling)
            deepest = max(deepest, f.stats["layers_used"])
    assert deepest >= 2, "the scene must have more than one layer somewhere for the comparison to mean much"


@pytest.mark.parametrize("depth_mode", ["standard", "reversed_z"])
def test_coplanar_fragments_collapse_as_in_peeling(renderer, depth_mode):
    """Equal depths make one layer, and the fragment peeling keeps (the first drawn object's)
    is the one the lists keep: two boxes at exactly the same place, of different colours."""
    s = ssrlab.Scene()
    red = ssrlab.Material(base_color=(1, 0, 0), roughness=0.5)
    blue = ssrlab.Material(base_color=(0, 0, 1), roughness=0.2, reflectivity=0.5)
    a = s.add_box((0, 0, 0), (1, 1, 1), material=red)
    s.add_box((0, 0, 0), (1, 1, 1), material=blue)
    cam = ssrlab.Camera(position=(0.3, 0.4, 4), target=(0, 0, 0), fov_y=40, near=0.5, far=20)
    f = assert_same_layers(renderer, s, cam, "coplanar boxes", layers=4, depth_mode=depth_mode)
    g = f.gbuffer
    centre = (16, 24)
    # Front and back of the box: two layers, not four.
    assert g.coverage[:, centre[0], centre[1]].tolist() == [True, True, False, False]
    assert g.object_id[0, centre[0], centre[1]] == a
    assert g.object_id[1, centre[0], centre[1]] == a


NEAR = ssrlab.Camera(position=(0, 0, 3.5), target=(0, 0, 0), fov_y=90, near=0.1, far=100)


def nested_spheres() -> ssrlab.Scene:
    s = ssrlab.Scene()
    for r in (1.0, 2.0, 3.0):
        s.add_sphere((0, 0, 0), r, segments=48)
    return s


def test_a_store_too_small_is_redone_not_truncated(renderer):
    """The store is sized by the previous frame: a frame with more fragments runs the geometry
    pass again with a store that fits, and says so; the layers still equal peeling's."""
    scene = nested_spheres()
    far = ssrlab.Camera(position=(0, 0, 60), target=(0, 0, 0), fov_y=40, near=0.5, far=100)
    near = ssrlab.Camera(position=(0, 0, 3.5), target=(0, 0, 0), fov_y=90, near=0.1, far=100)
    r = ssrlab.Renderer("auto")
    settings = tiny(deep_gbuffer="lists", layers=8)
    first = r.render(scene, far, settings)
    assert first.stats["deep_gbuffer_redone"] == 0
    # Six surfaces over most pixels: more fragments than the first frame's store (2 a pixel).
    second = r.render(scene, near, settings)
    st = second.stats
    assert st["deep_gbuffer_method"] == "lists" and st["deep_gbuffer_redone"] == 1, dict(st)
    assert st["deep_gbuffer_fragments"] > 2 * 48 * 32
    assert st["deep_gbuffer_bytes"] >= 64 * st["deep_gbuffer_fragments"]
    assert second.stats["layers_used"] == 6
    peel = r.render(scene, near, settings.replace(deep_gbuffer="peel"))
    for name in TEXTURES:
        np.testing.assert_array_equal(bits(second.read(name)), bits(peel.read(name)), err_msg=name)
    # The grown store serves the next frame without a redo.
    assert r.render(scene, near, settings).stats["deep_gbuffer_redone"] == 0


def test_fragments_beyond_the_budget_are_peeled(renderer):
    """A budget the frame's fragments exceed: the frame is peeled (never truncated) and says so."""
    scene = nested_spheres()
    cam = ssrlab.Camera(position=(0, 0, 3.5), target=(0, 0, 0), fov_y=90, near=0.1, far=100)
    # 1 MiB holds 16384 fragments: 6 surfaces over 256 x 128 pixels are many more.
    kw = dict(width=256, height=128, layers=8)
    f = renderer.render(scene, cam, tiny(deep_gbuffer="lists", deep_gbuffer_budget=1, **kw))
    st = f.stats
    assert st["deep_gbuffer_method"] == "peel" and st["deep_gbuffer_fell_back"] == 1, dict(st)
    assert st["deep_gbuffer_fragments"] > 16384
    peel = renderer.render(scene, cam, tiny(deep_gbuffer="peel", **kw))
    for name in TEXTURES:
        np.testing.assert_array_equal(bits(f.read(name)), bits(peel.read(name)), err_msg=name)
    assert f.stats["layers_used"] == 6


def test_a_budget_beyond_the_device_is_a_value_error(renderer):
    with pytest.raises(ValueError, match="deep_gbuffer_budget"):
        renderer.render(nested_spheres(), NEAR, tiny(deep_gbuffer="lists", deep_gbuffer_budget=1 << 20))
    # The renderer still works afterwards.
    assert renderer.render(nested_spheres(), NEAR, tiny(deep_gbuffer="lists")).stats["deep_gbuffer_method"] == "lists"


def test_setting_values_and_timings(renderer):
    with pytest.raises(ValueError, match="deep_gbuffer"):
        ssrlab.Settings(deep_gbuffer="layers")
    with pytest.raises(ValueError, match="deep_gbuffer_budget"):
        ssrlab.Settings(deep_gbuffer_budget=-1)
    scene = nested_spheres()

    def timed(settings):
        """The frame and the host's own clock around the render call (first use included)."""
        start = time.perf_counter()
        f = renderer.render(scene, NEAR, settings)
        return f, (time.perf_counter() - start) * 1e3

    # timings["deep_gbuffer"] is the construction's time whichever method built the layers: it
    # holds its parts (each timed by its own queries, nested in it), it is one pass among those the
    # frame ran (lighting and composite take time too), and it fits in the host's wall time.
    for method, parts in (("lists", ("fragment_lists.append", "fragment_lists.select", "fragment_lists.write")),
                          ("peel", tuple(f"depth_peel.layer{i}" for i in range(4)))):
        f, wall_ms = timed(tiny(deep_gbuffer=method, layers=4))
        t = f.timings
        assert f.settings.deep_gbuffer == method
        assert all(t[p] >= 0 for p in parts), {p: t.get(p) for p in parts}
        inside = sum(t[p] for p in parts)
        assert 0 < inside <= t["deep_gbuffer"] * 1.001, (method, inside, t["deep_gbuffer"])
        assert t["deep_gbuffer"] < t["total"] and t["deep_gbuffer"] < wall_ms, (method, t, wall_ms)
    # 'auto' is measured once per renderer, scene, size and layers, and the frame records the
    # method it ran with: the one measured fastest, unless within the spread of peeling's.
    r = ssrlab.Renderer("auto")
    auto = r.render(scene, NEAR, tiny(layers=4, deep_gbuffer="auto"))
    (key, measured), = r.deep_gbuffer_measurements.items()
    # The CPU device measures peeling and its lists only (their images are the same bit for bit).
    cpu = r.info["device"] == "cpu"
    assert set(measured) == ({"peel", "lists"} if cpu else {"peel", "lists", "visibility", "visibility_lists"})
    assert all(0 < m["min"] <= m["median"] <= m["max"] for m in measured.values()), measured
    fastest = min(measured, key=lambda m: measured[m]["median"])
    undecided = fastest != "peel" and measured[fastest]["max"] >= measured["peel"]["min"]
    assert auto.settings.deep_gbuffer == ("peel" if undecided else fastest), measured
    again = r.render(scene, NEAR, tiny(layers=4, deep_gbuffer="auto"))
    assert again.settings.deep_gbuffer == auto.settings.deep_gbuffer and len(r.deep_gbuffer_measurements) == 1
    # One layer on the CPU device is peeled without measuring (docs/deep_gbuffer.md).
    if r.info["device"] == "cpu":
        assert r.render(scene, NEAR, tiny(layers=1, deep_gbuffer="auto")).settings.deep_gbuffer == "peel"
        assert len(r.deep_gbuffer_measurements) == 1


def test_auto_takes_the_fastest_unless_within_peelings_spread():
    """choose_deep_gbuffer on measurements made up here: the fastest median wins where its range is
    clear of peeling's; an overlap keeps peeling."""
    from ssrlab.renderer import choose_deep_gbuffer

    def m(lo, med, hi):
        return {"min": lo, "median": med, "max": hi}

    assert choose_deep_gbuffer({"peel": m(9, 10, 11), "visibility": m(4, 5, 6)}) == "visibility"
    assert choose_deep_gbuffer({"peel": m(9, 10, 11), "visibility": m(8, 9.5, 9.6)}) == "peel"
    assert choose_deep_gbuffer({"peel": m(4, 5, 6), "lists": m(8, 9, 10), "visibility": m(6.5, 7, 8)}) == "peel"
    assert choose_deep_gbuffer({"peel": m(20, 21, 30), "lists": m(8, 9, 10), "visibility_lists": m(2, 3, 4)}) == \
        "visibility_lists"


@pytest.mark.parametrize("scene_name", ["hall", "spheres_and_boxes"])
def test_the_whole_frame_is_the_same(renderer, scene_name):
    """Downstream of the layers nothing changes: lighting over the covered tiles (marked by the
    lists' selection instead of the shading pass), the trace over layer 0's reflective regions,
    the resolve and the composite give the same image bit for bit."""
    scene = ssrlab.scenes.load(scene_name)
    kw = dict(width=64, height=48, layers=4, shadow_map_size=256)
    peel = renderer.render(scene, settings=small(deep_gbuffer="peel", **kw))
    lists = renderer.render(scene, settings=small(deep_gbuffer="lists", **kw))
    assert lists.stats["deep_gbuffer_method"] == "lists"
    # The same chain, the construction under its own name.
    assert lists.passes == ["fragment_lists" if p == "depth_peel" else p for p in peel.passes]
    for name in ("lit", "color"):
        np.testing.assert_array_equal(bits(peel.read(name)), bits(lists.read(name)), err_msg=name)
    for key in ("layers_used", "layers_lit", "tiles_lit"):  # tiles_lit: with skip only (on by default on llvmpipe)
        assert (key in peel.stats) == (key in lists.stats), key
        if key in peel.stats:
            assert peel.stats[key] == lists.stats[key], key


def test_textured_and_normal_mapped_surfaces_are_equal(renderer):
    """Textures sampled with derivative-chosen mips and normal maps framed by screen-space
    gradients (no tangents): the append shades in the same 2x2 quads as peeling's shading pass."""
    s = ssrlab.Scene()
    rng = np.random.default_rng(5)
    colour = s.add_image(rng.integers(20, 255, size=(16, 16, 3), dtype=np.uint8), name="colour")
    bumps = s.add_image(rng.integers(90, 166, size=(16, 16, 3), dtype=np.uint8), name="bumps")
    mr = s.add_image(rng.integers(0, 255, size=(8, 8, 3), dtype=np.uint8), name="mr")
    textured = ssrlab.Material(base_color=(1, 1, 1), roughness=0.7, base_color_texture=colour, normal_texture=bumps,
                               metallic_roughness_texture=mr)
    s.add_sphere((0, 0, 0), 1.0, segments=24, material=textured)
    s.add_sphere((0.6, 0.2, -1.5), 1.2, segments=24, material=textured)
    s.add_plane((0, -1, 0), (8, 8), material=textured, uv_tiles=3.0)
    cam = ssrlab.Camera(position=(0.5, 1.5, 4), target=(0, 0, 0), fov_y=45, near=0.1, far=30)
    for culling in (False, True):
        f = assert_same_layers(renderer, s, cam, "textured", layers=4, backface_culling=culling)
        assert f.stats["layers_used"] >= 3


def test_emissive_textures_are_carried_bit_for_bit(renderer):
    """A scene with an emissive texture: the lists store each fragment's emission too (a longer
    fragment, EMISSION_TEXTURE) and write it to gbuffer.emission as peeling's 4th output does,
    for textured emitters, an emitter with a factor only, and surfaces that emit nothing."""
    s = ssrlab.Scene()
    rng = np.random.default_rng(7)
    glow = s.add_image(rng.integers(0, 255, size=(16, 16, 3), dtype=np.uint8), name="glow")
    colour = s.add_image(rng.integers(20, 255, size=(16, 16, 3), dtype=np.uint8), name="colour")
    lamp = ssrlab.Material(base_color=(0.2, 0.2, 0.2), roughness=0.5, emissive_texture=glow, base_color_texture=colour)
    lamp.emissive = (3.0, 2.0, 1.0)
    s.add_sphere((0, 0, 0), 1.0, segments=24, material=lamp)
    plain = ssrlab.Material(base_color=(0.5, 0.5, 0.5), roughness=0.4)
    plain.emissive = (0.5, 0.0, 0.25)
    s.add_sphere((0.6, 0.2, -1.5), 1.2, segments=24, material=plain)
    s.add_plane((0, -1, 0), (8, 8), material=ssrlab.Material(base_color=(0.8, 0.8, 0.8)), uv_tiles=3.0)
    cam = ssrlab.Camera(position=(0.5, 1.5, 4), target=(0, 0, 0), fov_y=45, near=0.1, far=30)
    for culling in (False, True):
        f = assert_same_layers(renderer, s, cam, "emissive", layers=4, backface_culling=culling)
        assert f.stats["layers_used"] >= 3
    e = f.read("gbuffer.emission")
    assert len(np.unique(e[0, ..., 0])) > 20  # the texture's texels, not one factor


@pytest.mark.parametrize("with_emission", [False, True], ids=["specular", "specular+emission"])
def test_specular_textures_are_carried_bit_for_bit(renderer, with_emission):
    """A scene with KHR_materials_specular textures: the lists store each fragment's dielectric F0
    too (SPECULAR_TEXTURE) and write it to gbuffer.specular as peeling does, after gbuffer.emission
    where the scene has both, for textured materials, a factor-only one and the default F0."""
    s = ssrlab.Scene()
    rng = np.random.default_rng(11)
    spec = s.add_image(rng.integers(0, 255, size=(16, 16, 4), dtype=np.uint8), name="specular")
    tint = s.add_image(rng.integers(20, 255, size=(16, 16, 3), dtype=np.uint8), name="tint")
    textured = ssrlab.Material(base_color=(0.2, 0.2, 0.2), roughness=0.5, specular_texture=spec,
                               specular_color_texture=tint)
    textured.specular_color = (3.0, 2.0, 1.0)
    if with_emission:
        textured.emissive_texture = tint
        textured.emissive = (1.0, 1.0, 1.0)
    s.add_sphere((0, 0, 0), 1.0, segments=24, material=textured)
    factors = ssrlab.Material(base_color=(0.5, 0.5, 0.5), roughness=0.4)
    factors.specular, factors.ior = 0.5, 2.0
    s.add_sphere((0.6, 0.2, -1.5), 1.2, segments=24, material=factors)
    s.add_plane((0, -1, 0), (8, 8), material=ssrlab.Material(base_color=(0.8, 0.8, 0.8)), uv_tiles=3.0)
    cam = ssrlab.Camera(position=(0.5, 1.5, 4), target=(0, 0, 0), fov_y=45, near=0.1, far=30)
    for culling in (False, True):
        f = assert_same_layers(renderer, s, cam, "specular", layers=4, backface_culling=culling)
        assert f.stats["layers_used"] >= 3
    assert ("gbuffer.emission" in f.texture_names) == with_emission
    f0 = f.read("gbuffer.specular")
    assert len(np.unique(f0[0, ..., 0])) > 20  # the textures' texels, not one factor
    floor = f.gbuffer.coverage[0] & (f.gbuffer.object_id[0] == 2)
    np.testing.assert_allclose(f0[0][floor][:, :3], 0.04, rtol=1e-3)  # the default F0, per texel


def test_coplanar_triangles_of_one_draw_keep_peelings_winner(renderer):
    """Two triangles of one mesh in the same plane (their vertex normals differ): peeling's
    shading pass writes them in primitive order, so the later one shows; the lists keep it too."""
    s = ssrlab.Scene()
    p = np.float32([[-1, -1, 0], [1, -1, 0], [0, 1, 0]])
    positions = np.concatenate([p, p])
    normals = np.float32([[0, 0, 1]] * 3 + [[0.6, 0, 0.8]] * 3)
    s.add_mesh(positions, np.array([[0, 1, 2], [3, 4, 5]]), normals=normals, name="twice")
    cam = ssrlab.Camera(position=(0, 0, 3), target=(0, 0, 0), fov_y=60, near=0.1, far=10)
    f = assert_same_layers(renderer, s, cam, "coplanar triangles", layers=2)
    n = f.read("gbuffer.normal")[0, 16, 24, :3]
    assert f.gbuffer.coverage[:, 16, 24].tolist() == [True, False]
    np.testing.assert_allclose(n, [0.6, 0, 0.8], atol=2e-3)


# -- Settings.min_separation (Mara, McGuire, Nowrouzezahrai and Luebke 2016) ------------------------
def slab_scene() -> tuple[ssrlab.Scene, dict]:
    """A thin slab (2 cm) with a decal 5 mm in front of it, and a wall 2 m behind: the surfaces a
    minimum separation skips, and the one it keeps."""
    s = ssrlab.Scene()
    ids = {
        "decal": s.add_plane((0, 0, 0.015), (1.0, 1.0), normal=(0, 0, 1), material=ssrlab.Material(base_color=(1, 1, 0))),
        "slab": s.add_box((0, 0, 0), (2.0, 2.0, 0.02), material=ssrlab.Material(base_color=(1, 0, 0))),
        "wall": s.add_box((0, 0, -2.0), (6.0, 6.0, 0.2), material=ssrlab.Material(base_color=(0, 0, 1))),
    }
    return s, ids


SLAB_CAMERA = ssrlab.Camera(position=(0.2, 0.3, 4), target=(0, 0, 0), fov_y=40, near=0.5, far=20)


@pytest.mark.parametrize("depth_mode", ["standard", "reversed_z"])
def test_min_separation_skips_the_surfaces_just_behind_a_layer(renderer, depth_mode):
    """Without a separation layer 1 is the slab's front 5 mm behind the decal and layer 2 its back;
    with 0.1 m both are skipped and layer 1 is the wall. Every pixel's layers lie at least the
    separation apart, and the lists keep the same layers as peeling."""
    scene, ids = slab_scene()
    centre = (16, 24)  # (y, x): on the decal
    plain = assert_same_layers(renderer, scene, SLAB_CAMERA, "slab", layers=3, depth_mode=depth_mode)
    g = plain.gbuffer
    assert [int(g.object_id[k][centre]) for k in range(3)] == [ids["decal"], ids["slab"], ids["slab"]]
    gap = g.depth[1][centre] - g.depth[0][centre]
    assert 0.002 < gap < 0.02, gap

    sep = 0.1
    f = assert_same_layers(renderer, scene, SLAB_CAMERA, "slab", layers=3, depth_mode=depth_mode,
                           min_separation=sep)
    g = f.gbuffer
    assert int(g.object_id[0][centre]) == ids["decal"]
    assert int(g.object_id[1][centre]) == ids["wall"]  # the slab's two faces are skipped
    both = g.coverage[0] & g.coverage[1]
    assert both.sum() > 0.5 * both.size
    gaps = (g.depth[1] - g.depth[0])[both]
    assert gaps.min() > sep * (1 - 1e-3), gaps.min()
    deeper = g.coverage[1] & g.coverage[2]
    assert ((g.depth[2] - g.depth[1])[deeper] > sep * (1 - 1e-3)).all()
    # Layer 0 does not depend on the separation.
    for name in TEXTURES:
        np.testing.assert_array_equal(bits(f.read(name))[0], bits(plain.read(name))[0], err_msg=name)


@pytest.mark.parametrize("name", ["spheres_and_boxes", "box_stack", "hall", "model:Suzanne"])
def test_min_separation_lists_equal_peeling_bit_for_bit(renderer, name):
    """With a minimum separation both constructions keep the same layers, culling on and off."""
    scene = load(name)
    changed = False
    for culling in (False, True):
        for layers, sep in ((2, 0.05), (4, 0.5)):
            f = assert_same_layers(renderer, scene, None, name, layers=layers, backface_culling=culling,
                                   min_separation=sep)
            plain = renderer.render(scene, None, tiny(deep_gbuffer="peel", layers=layers, backface_culling=culling))
            changed |= not np.array_equal(bits(f.read("gbuffer.depth")), bits(plain.read("gbuffer.depth")))
    assert changed, "the separation changed no layer: the comparison would not test it"


def test_min_separation_is_checked(renderer):
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="min_separation"):
            ssrlab.Settings(min_separation=bad)
    assert ssrlab.Settings().min_separation == 0.0
