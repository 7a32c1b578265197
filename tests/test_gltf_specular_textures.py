"""KHR_materials_specular's textures: a dielectric's F0 per texel is
min(((ior - 1) / (ior + 1))^2 x specularColorFactor x specularColorTexture.rgb, 1) x specularFactor
x specularTexture.a (the colour texture sRGB-decoded), through a glTF file into the lit colour (via
gbuffer.specular, which only a scene with such a texture has), into what SSR and the BVH passes
reflect and into the converged references (GLSL and the C++ port). The lists' copy of
gbuffer.specular: tests/test_deep_gbuffer.py."""

import json
import warnings

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import pixel_rays
from conftest import small

TEXELS = 64
SPEC_CELLS, COLOR_CELLS = 8, 4  # two checkerboards of different periods: their product is a pattern
SPEC_A = (255, 64)  # the specular texture's alpha (linear) in its even and odd cells
COLOR_RGB = ((255, 128, 64), (64, 255, 128))  # the colour texture's sRGB texels, even and odd cells


def srgb_decode(c):
    c = np.asarray(c, dtype=np.float64) / 255.0
    return np.where(c < 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def checker(cells, even, odd):
    cell = TEXELS // cells
    i, j = np.meshgrid(np.arange(TEXELS) // cell, np.arange(TEXELS) // cell, indexing="ij")
    return np.where(((i + j) % 2 == 0)[..., None], np.asarray(even, np.uint8), np.asarray(odd, np.uint8))


def textures(scene):
    # RGB of the specular texture is noise: only its alpha may count.
    rgb = np.random.default_rng(3).integers(0, 255, size=(TEXELS, TEXELS, 3), dtype=np.uint8)
    spec = scene.add_image(np.concatenate([rgb, checker(SPEC_CELLS, [SPEC_A[0]], [SPEC_A[1]])], -1), name="spec")
    color = scene.add_image(checker(COLOR_CELLS, COLOR_RGB[0], COLOR_RGB[1]), name="spec_color")
    return spec, color


def parity(u, v, cells):
    """Even cell, and whether (u, v) is far enough from a cell's edge (and inside the texture)
    that mipmapped and level-0 filtering agree."""
    cu, cv = np.nan_to_num(u, nan=-1.0) * cells, np.nan_to_num(v, nan=-1.0) * cells
    even = (np.floor(cu).astype(int) + np.floor(cv).astype(int)) % 2 == 0
    centred = (np.abs(cu - np.floor(cu) - 0.5) < 0.3) & (np.abs(cv - np.floor(cv) - 0.5) < 0.3)
    return even, centred & (u > 0) & (u < 1) & (v > 0) & (v < 1)


def expected_f0(u, v, ior, specular, specular_color, spec=True, color=True):
    """The extension's per-texel F0 at texture coordinates (u, v) with the specular and / or the
    colour texture, and where it is testable (away from the used textures' cell edges)."""
    se, sc = parity(u, v, SPEC_CELLS)
    ce, cc = parity(u, v, COLOR_CELLS)
    a = np.where(se, SPEC_A[0], SPEC_A[1]) / 255.0 if spec else np.ones_like(u)
    tint = np.where(ce[..., None], srgb_decode(COLOR_RGB[0]), srgb_decode(COLOR_RGB[1])) if color else 1.0
    r = ((ior - 1) / (ior + 1)) ** 2
    f0 = np.minimum(r * np.asarray(specular_color) * tint, 1.0) * (specular * a)[..., None]
    return f0, (sc | (not spec)) & (cc | (not color)) & (u > 0) & (u < 1) & (v > 0) & (v < 1)


# -- a black dielectric floor lit along the view axis: its lit colour is F0 x one factor a pixel ----
CAMERA = ssrlab.Camera(position=(0.0, 3.0, 3.0), target=(0.0, 0.0, 0.0), fov_y=20.0, near=0.1, far=50.0)
HALF = 2.0  # the floor spans [-2, 2]^2 in x and z, the textures once (u along x, v along z)


def floor_scene(**material):
    s = ssrlab.Scene()
    m = ssrlab.Material(base_color=(0, 0, 0), metallic=0.0, roughness=1.0, reflectivity=0.0, name="floor")
    for k, v in material.items():
        setattr(m, k, v)
    p = [(-HALF, 0, HALF), (HALF, 0, HALF), (HALF, 0, -HALF), (-HALF, 0, -HALF)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    s.add_mesh(p, indices=[0, 1, 2, 0, 2, 3], normals=[(0, 1, 0)] * 4, uvs=uv, material=m, name="floor")
    view = np.array(CAMERA.target) - np.array(CAMERA.position)
    s.add_light(ssrlab.directional_light(tuple(view / np.linalg.norm(view)), intensity=3.0))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = CAMERA
    return s


def floor_uv(frame):
    cam, d = pixel_rays(frame)
    p = cam + d * (-cam[1] / d[..., 1])[..., None]
    return (p[..., 0] + HALF) / (2 * HALF), (p[..., 2] + HALF) / (2 * HALF)


FACTORS = dict(ior=3.0, specular=0.9, specular_color=(6.0, 2.0, 1.0))  # red clamps at 1 in its bright cells


@pytest.mark.filterwarnings("ignore::ssrlab.NoReflectionWarning")  # nothing reflects: lighting only
def test_lit_floor_shows_f0_per_texel_through_gltf(renderer, tmp_path):
    plain = floor_scene()
    base = renderer.render(plain, settings=small(width=96, height=64))
    assert "gbuffer.specular" not in base.texture_names
    cases = {"both": ("specular_texture", "specular_color_texture"), "specular": ("specular_texture",),
             "color": ("specular_color_texture",)}
    for name, which in cases.items():
        s = floor_scene(**FACTORS)
        spec, color = textures(s)
        m = s.material(0)
        for w in which:
            setattr(m, w, spec if w == "specular_texture" else color)
        s.set_material(0, m)
        path = s.save(tmp_path / f"{name}.gltf")
        ext = json.loads(path.read_text())["materials"][0]["extensions"]["KHR_materials_specular"]
        assert ("specularTexture" in ext) == ("specular_texture" in which)
        assert ("specularColorTexture" in ext) == ("specular_color_texture" in which)
        with warnings.catch_warnings():
            warnings.simplefilter("error", ssrlab.SceneWarning)  # no "is not rendered"
            loaded = ssrlab.Scene.load(path)
        lm = loaded.material(0)
        assert (lm.specular_texture >= 0) == ("specular_texture" in which)
        assert (lm.specular_color_texture >= 0) == ("specular_color_texture" in which)
        f = renderer.render(loaded, settings=small(width=96, height=64))
        assert "gbuffer.specular" in f.texture_names
        u, v = floor_uv(f)
        want, ok = expected_f0(u, v, **FACTORS, spec="specular_texture" in which,
                               color="specular_color_texture" in which)
        ok &= f.gbuffer.coverage[0]
        assert ok.sum() > 300, ok.sum()
        # Both kinds of cell, not just their mean (two F0 levels at least).
        assert len(np.unique(np.round(want[ok][:, 1], 6))) >= 2
        # gbuffer.specular holds the F0 (half floats: 2^-11; llvmpipe's sRGB8 decode of 64 is 0.4 %
        # above the exact curve's) ...
        np.testing.assert_allclose(f.read("gbuffer.specular")[0][ok][:, :3], want[ok], rtol=6e-3, err_msg=name)
        # ... and the lit colour is F0 x the same factor per pixel as the default F0's (0.04).
        ratio = f.gbuffer.lit[0][ok].astype(np.float64) / base.gbuffer.lit[0][ok]
        print(f"{name}: lit / default lit deviates from F0 / 0.04 by at most "
              f"{np.abs(ratio / (want[ok] / 0.04) - 1).max():.2e} (relative) on {int(ok.sum())} pixels")
        np.testing.assert_allclose(ratio, want[ok] / 0.04, rtol=6e-3, err_msg=name)


# -- a mirror floor reflecting a black dielectric wall: the reflection is the wall's F0 x its light -
WX0, WX1, WY0, WY1, WALL_Z = -2.0, 2.0, 0.0, 3.0, -2.0


def mirror_scene(textured: bool):
    s = ssrlab.Scene()
    floor = s.add_plane((0, 0, 0), (12, 12), material=ssrlab.Material(base_color=(1, 1, 1), roughness=0.0, metallic=1.0,
                                                                       reflectivity=1.0), name="floor")
    wall = ssrlab.Material(base_color=(0, 0, 0), metallic=0.0, roughness=0.6, reflectivity=0.0, name="wall")
    wall.specular_color = (2.0, 1.0, 0.5)
    if textured:
        wall.specular_texture, wall.specular_color_texture = textures(s)
    p = [(WX0, WY0, WALL_Z), (WX1, WY0, WALL_Z), (WX1, WY1, WALL_Z), (WX0, WY1, WALL_Z)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    s.add_mesh(p, indices=[0, 1, 2, 0, 2, 3], normals=[(0, 0, 1)] * 4, uvs=uv, material=wall, name="wall")
    s.add_light(ssrlab.directional_light((0.0, -0.3, -1.0), intensity=4.0))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 1.0, 3.0), target=(0.0, 0.5, -2.0), fov_y=45.0, near=0.1, far=30.0)
    return s, floor


def test_references_and_tracers_see_the_textured_f0_in_a_mirror(renderer, tmp_path):
    """The mirror's reflection of the textured wall against the same wall without textures: per
    pixel their ratio is Schlick's F of the texel's F0 over that of the factors', in the converged
    references (GLSL and
    Embree + C++), method bvh and the BVH fallback, and within SSR's tolerance in SSR."""
    plain, floor = mirror_scene(False)
    scene, _ = mirror_scene(True)
    scene = ssrlab.Scene.load(scene.save(tmp_path / "wall.gltf"))
    settings = small(width=128, height=96, layers=2)
    fp = renderer.render(plain, settings=settings)
    ft = renderer.render(scene, settings=settings)
    g = ft.gbuffer
    cam, d = pixel_rays(ft)
    p = cam + d * (-cam[1] / d[..., 1])[..., None]
    dm = d * np.array([1.0, -1.0, 1.0])
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (WALL_Z - p[..., 2]) / dm[..., 2]
    q = p + dm * t[..., None]
    u = np.where(t > 0, (q[..., 0] - WX0) / (WX1 - WX0), np.nan)
    v = np.where(t > 0, (WY1 - q[..., 1]) / (WY1 - WY0), np.nan)
    f0, centred = expected_f0(u, v, 1.5, 1.0, (2.0, 1.0, 0.5))
    # Schlick's Fresnel at the wall for the light and the view: only F differs between the two
    # walls, so the reflections' ratio is F(texel's F0) / F(factors' F0).
    to_light = -np.array([0.0, -0.3, -1.0]) / np.linalg.norm([0.0, -0.3, -1.0])
    plain_f0 = 0.04 * np.array([2.0, 1.0, 0.5])

    def f_ratio(view):
        """F(texel's F0) / F(factors' F0) for the wall seen along `view` (unit, wall to viewer)."""
        h = to_light + view
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        k = ((1.0 - np.clip(np.sum(view * h, axis=-1), 0.0, 1.0)) ** 5)[..., None]
        return (f0 + (1 - f0) * k) / (plain_f0 + (1 - plain_f0) * k)

    want = f_ratio(-dm)  # seen along the mirrored camera ray
    mirrored = g.coverage[0] & (g.object_id[0] == floor) & centred & (d[..., 1] < 0)
    assert mirrored.sum() > 150, mirrored.sum()
    bright = want[..., 1] > 0.5
    assert (mirrored & bright).sum() > 30 and (mirrored & ~bright).sum() > 30

    def ratio(a, b):
        return a[..., :3].astype(np.float64) / np.maximum(b[..., :3], 1e-12)

    refs = {}
    for tracer in ("glsl", "cpu"):
        rt = ft.reference("converged", rays=1, tracer=tracer).reflection
        rp = fp.reference("converged", rays=1, tracer=tracer).reflection
        assert rp[mirrored].min() > 1e-4, "the floor reflects the lit wall"
        refs[tracer] = rt
        r = ratio(rt, rp)[mirrored]
        print(f"reference ({tracer}): ratio deviates from the texel's F0 ratio by at most "
              f"{np.abs(r / want[mirrored] - 1).max():.2e} on {int(mirrored.sum())} pixels")
        np.testing.assert_allclose(r, want[mirrored], rtol=6e-3, err_msg=tracer)
    np.testing.assert_allclose(refs["cpu"][mirrored], refs["glsl"][mirrored], rtol=3e-3, atol=1e-6)
    # The BVH passes shade their hits with the same textures (lib/trace_shade.glsl).
    for name, kw, tol in [("method bvh", dict(method="bvh"), 6e-3), ("fallback bvh", dict(fallback="bvh"), 0.03),
                          ("SSR", dict(), 0.03)]:
        a = renderer.render(scene, settings=small(width=128, height=96, layers=2, **kw)).reflection
        b = renderer.render(plain, settings=small(width=128, height=96, layers=2, **kw)).reflection
        seen = mirrored & (b[..., 1] > 1e-4)
        assert seen.sum() > 0.8 * mirrored.sum(), name
        ok = np.all(np.abs(ratio(a, b) - want) < tol * want, axis=-1)
        assert ok[seen].mean() > 0.95, f"{name}: {ok[seen].mean():.3f} of the mirrored cells match"
    # The probes' capture shades its hits through the same code (lib/trace_shade.glsl). One probe
    # in front of the wall and a one-step trace, so that every ray is the probe's: per ray, the
    # textured wall's radiance over the plain one's is the same F ratio, at the angle the probe saw
    # the texel from. The cube map is coarser than the screen (a 128-texel face over 90 degrees),
    # so the cells are judged a quarter of a cell from their edges (about two of its texels).
    probe = np.array([0.0, 1.5, 2.5])
    plain.probes = scene.probes = [tuple(probe)]
    st = small(width=128, height=96, layers=2, fallback="probes", max_steps=1)
    rt, rp = (renderer.render(s, settings=st).read("rays.radiance")[0] for s in (scene, plain))
    inner = np.all([np.abs(np.nan_to_num(c) * SPEC_CELLS % 1.0 - 0.5) < 0.25 for c in (u, v)], axis=0)
    by_probe = mirrored & inner & (rp[..., 3] >= 0) & (rt[..., 3] >= 0)  # a distance: the probe saw a surface
    assert by_probe.sum() > 150 and (by_probe & bright).sum() > 30 and (by_probe & ~bright).sum() > 30
    to_probe = probe - q
    want_probe = f_ratio(to_probe / np.linalg.norm(to_probe, axis=-1, keepdims=True))
    r = ratio(rt, rp)[by_probe]
    print(f"probes: ratio deviates from the texel's F0 ratio by at most {np.abs(r / want_probe[by_probe] - 1).max():.2e} "
          f"on {int(by_probe.sum())} pixels")
    np.testing.assert_allclose(r, want_probe[by_probe], rtol=0.01)


def test_a_scene_without_specular_textures_has_no_specular_layer(renderer):
    scene, _ = mirror_scene(True)
    with_texture = renderer.chain(small(composite="pbr"), scene=scene)
    readers = {e.name for e in with_texture if "gbuffer.specular" in e.inputs}
    assert {"lighting", "composite"} <= readers, readers
    m = scene.material(1)
    m.specular_texture = m.specular_color_texture = -1
    scene.set_material(1, m)
    chain = renderer.chain(small(composite="pbr"), scene=scene)
    assert [e.name for e in chain] == [e.name for e in with_texture]
    assert all("gbuffer.specular" not in e.outputs and "gbuffer.specular" not in e.inputs for e in chain)
    f = renderer.render(scene, settings=small())
    assert "gbuffer.specular" not in f.texture_names
    with pytest.raises(Exception, match="gbuffer.specular"):
        f.read("gbuffer.specular")


def test_texture_transform_is_kept_and_bad_texture_infos_are_errors(renderer, tmp_path):
    """KHR_texture_transform on the specularColorTexture (an offset of one cell along u) moves the
    pattern in the lit colour and saving keeps it; bad texture infos are clear errors."""
    s = floor_scene(**FACTORS)
    spec, color = textures(s)
    m = s.material(0)
    m.specular_color_texture = color
    s.set_material(0, m)
    path = s.save(tmp_path / "moved.gltf")
    doc = json.loads(path.read_text())
    info = doc["materials"][0]["extensions"]["KHR_materials_specular"]["specularColorTexture"]
    info["extensions"] = {"KHR_texture_transform": {"offset": [1.0 / COLOR_CELLS, 0.0]}}
    doc["extensionsUsed"] = doc.get("extensionsUsed", []) + ["KHR_texture_transform"]
    path.write_text(json.dumps(doc))
    moved = ssrlab.Scene.load(path)
    again = json.loads(moved.save(tmp_path / "again.gltf").read_text())
    t = again["materials"][0]["extensions"]["KHR_materials_specular"]["specularColorTexture"]
    assert t["extensions"]["KHR_texture_transform"]["offset"] == pytest.approx([1.0 / COLOR_CELLS, 0.0])
    f = renderer.render(moved, settings=small(width=96, height=64, method="off"))
    u, v = floor_uv(f)
    want, ok = expected_f0(u + 1.0 / COLOR_CELLS, v, **FACTORS, spec=False)
    ok &= (u > 0) & (u < 1.0 - 1.0 / COLOR_CELLS) & f.gbuffer.coverage[0]
    assert ok.sum() > 200
    np.testing.assert_allclose(f.read("gbuffer.specular")[0][ok][:, :3], want[ok], rtol=6e-3)

    doc["materials"][0]["extensions"]["KHR_materials_specular"]["specularTexture"] = {"index": 99}
    path.write_text(json.dumps(doc))
    with pytest.raises(ssrlab.SceneError, match="specularTexture"):
        ssrlab.Scene.load(path)
    doc["materials"][0]["extensions"]["KHR_materials_specular"]["specularTexture"] = {"texCoord": 0}
    path.write_text(json.dumps(doc))
    with pytest.raises(ssrlab.SceneError, match="specularTexture"):
        ssrlab.Scene.load(path)


def test_mitsuba_crosscheck_refuses_specular_textures():
    """The Mitsuba cross-check's BSDF takes the factors' F0: a scene with the textures is refused
    (checked before Mitsuba is needed)."""
    from ssrlab import crosscheck as cc

    scene, _ = mirror_scene(False)
    cc.check_comparable(scene)
    textured, _ = mirror_scene(True)
    with pytest.raises(ValueError, match="has textures"):
        cc.check_comparable(textured)


@pytest.mark.filterwarnings("ignore::ssrlab.NoReflectionWarning")
def test_automatic_reflectivity_follows_the_texel_f0(renderer):
    """A material without an explicit reflectivity reflects its GGX specular albedo F0 A + B,
    computed in the G-buffer's shading pass: with the textures, from each texel's F0 (the ratio of
    r between the checker's two A levels is far from 1, where one F0 for the whole material gives 1)."""
    s = floor_scene(ior=3.0, specular=1.0, specular_color=(1.0, 1.0, 1.0))
    spec, _ = textures(s)
    m = s.material(0)
    m.reflectivity, m.roughness, m.specular_texture = "auto", 0.2, spec
    s.set_material(0, m)
    f = renderer.render(s, settings=small(width=96, height=64, method="off"))
    u, v = floor_uv(f)
    even, ok = parity(u, v, SPEC_CELLS)
    ok &= f.gbuffer.coverage[0]
    r = f.gbuffer.reflectivity[0]
    hi, lo = np.median(r[ok & even]), np.median(r[ok & ~even])
    # F0 0.25 against 0.25 x 64 / 255: E = F0 A + B with B small at this roughness.
    assert (ok & even).sum() > 100 and (ok & ~even).sum() > 100
    assert hi > 2.5 * lo > 0, (hi, lo)
