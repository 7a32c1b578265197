"""glTF emissiveTexture: the emitted radiance is emissiveFactor x KHR_materials_emissive_strength x
the texture's sRGB-decoded texel, in the lit colour (through gbuffer.emission, which only a scene
with an emissive texture has), in what SSR and the BVH fallback reflect, and in the converged
references (GLSL and the C++ port). The lists' copy of gbuffer.emission: tests/test_deep_gbuffer.py."""

import json

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import pixel_rays
from conftest import small

FACTOR = np.array([4.0, 2.0, 1.0])  # saved as a [0, 1] factor x emissiveStrength 4
CELLS, TEXELS = 4, 64  # a 4 x 4 checkerboard of 16-texel cells
BRIGHT, DIM = 255, 64  # sRGB8 values of the two cells
X0, X1, Y0, Y1, QUAD_Z = -0.75, 0.75, 0.1, 1.6, -3.0  # the emitting quad (facing +z)


def srgb_decode(c):
    c = np.asarray(c, dtype=np.float64) / 255.0
    return np.where(c < 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def checkerboard():
    cell = TEXELS // CELLS
    i, j = np.meshgrid(np.arange(TEXELS) // cell, np.arange(TEXELS) // cell, indexing="ij")
    v = np.where((i + j) % 2 == 0, BRIGHT, DIM).astype(np.uint8)
    return np.stack([v, v, v, np.full_like(v, 255)], -1)


def expected_emission(u, v):
    """factor x decoded texel at texture coordinates (u, v) (v = 0 at the image's top row), and
    whether (u, v) is far enough from a cell's edge that mipmapped and level-0 filtering agree."""
    cu, cv = np.nan_to_num(u, nan=-1.0) * CELLS, np.nan_to_num(v, nan=-1.0) * CELLS
    bright = (np.floor(cu).astype(int) + np.floor(cv).astype(int)) % 2 == 0
    texel = np.where(bright, srgb_decode(BRIGHT), srgb_decode(DIM))
    centred = (np.abs(cu - np.floor(cu) - 0.5) < 0.3) & (np.abs(cv - np.floor(cv) - 0.5) < 0.3)
    inside = (u > 0) & (u < 1) & (v > 0) & (v < 1)
    return texel[..., None] * FACTOR, centred & inside


def emissive_quad_over_mirror():
    """A mirror floor and a black quad emitting a checkerboard; no light, ambient or sky."""
    s = ssrlab.Scene()
    floor = s.add_plane((0, 0, -2), (16, 16), material=ssrlab.Material(
        base_color=(1, 1, 1), roughness=0.0, metallic=1.0, reflectivity=1.0))
    image = s.add_image(checkerboard(), name="checker")
    lamp = ssrlab.Material(base_color=(0, 0, 0), roughness=1.0, emissive_texture=image)
    lamp.emissive = tuple(FACTOR)
    p = [(X0, Y0, QUAD_Z), (X1, Y0, QUAD_Z), (X1, Y1, QUAD_Z), (X0, Y1, QUAD_Z)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]  # v = 0 at the top edge
    quad = s.add_mesh(p, indices=[0, 1, 2, 0, 2, 3], normals=[(0, 0, 1)] * 4, uvs=uv, material=lamp, name="quad")
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 1.2, 3.0), target=(0.0, 0.4, -3.0), fov_y=45.0, near=0.1, far=50.0)
    return s, floor, quad


def quad_uv(origin, d):
    """Where rays (origin, d) cross the quad's plane, as texture coordinates (nan behind)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (QUAD_Z - origin[..., 2]) / d[..., 2]
        p = origin + d * t[..., None]
    u = (p[..., 0] - X0) / (X1 - X0)
    v = (Y1 - p[..., 1]) / (Y1 - Y0)
    return np.where(t > 0, u, np.nan), np.where(t > 0, v, np.nan)


@pytest.fixture(scope="module")
def loaded(tmp_path_factory):
    """The scene saved as glTF and loaded back (the writer and the reader both in the loop)."""
    scene, floor, quad = emissive_quad_over_mirror()
    path = scene.save(tmp_path_factory.mktemp("emissive") / "emissive.gltf")
    doc = json.loads(path.read_text())
    m = [m for m in doc["materials"] if "emissiveTexture" in m]
    assert len(m) == 1 and m[0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] == 4.0
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)  # no "emissiveTexture is not rendered"
        back = ssrlab.Scene.load(path)
    assert back.material(quad).emissive_texture >= 0
    return back, floor, quad


def test_lit_colour_and_reflections_show_the_texture(renderer, loaded):
    scene, floor, quad = loaded
    f = renderer.render(scene, settings=small(width=128, height=96, fallback="bvh"))
    assert "gbuffer.emission" in [d for e in renderer.chain(f.settings, scene=scene) for d in e.outputs]
    emission = f.read("gbuffer.emission")
    g = f.gbuffer
    cam, d = pixel_rays(f)
    u, v = quad_uv(cam, d)
    want, centred = expected_emission(u, v)
    on_quad = g.coverage[0] & (g.object_id[0] == quad) & centred
    bright = on_quad & (want[..., 0] > FACTOR[0] * 0.5)
    dim = on_quad & (want[..., 0] < FACTOR[0] * 0.5)
    assert bright.sum() > 50 and dim.sum() > 50, (bright.sum(), dim.sum())
    # gbuffer.emission and the lit colour of a black emitter with no light: factor x texel
    # (half floats; llvmpipe's sRGB8 decode of 64 is 0.4 % above the exact curve's).
    np.testing.assert_allclose(emission[0][on_quad][:, :3], want[on_quad], rtol=6e-3)
    np.testing.assert_allclose(g.lit[0][on_quad], want[on_quad], rtol=6e-3)
    np.testing.assert_allclose(f.color[on_quad], want[on_quad], rtol=6e-3)

    # The mirror floor's reflection: the mirrored ray meets the quad where the texture says.
    on_floor = g.coverage[0] & (g.object_id[0] == floor)
    t = -cam[1] / d[..., 1]
    p = cam + d * t[..., None]
    mu, mv = quad_uv(p, d * np.array([1.0, -1.0, 1.0]))
    mwant, mcentred = expected_emission(mu, mv)
    mirrored = on_floor & mcentred
    mbright = mirrored & (mwant[..., 0] > FACTOR[0] * 0.5)
    mdim = mirrored & (mwant[..., 0] < FACTOR[0] * 0.5)
    assert mbright.sum() > 30 and mdim.sum() > 30, (mbright.sum(), mdim.sum())
    ref = f.reference("converged", rays=1, tracer="glsl")
    cpu = f.reference("converged", rays=1, tracer="cpu")
    bvh = renderer.render(scene, settings=small(width=128, height=96, method="bvh"))
    for name, reflection, tol in [("SSR", f.reflection, 0.03), ("reference (glsl)", ref.reflection, 0.01),
                                  ("reference (cpu)", cpu.reflection, 0.01), ("method bvh", bvh.reflection, 0.01)]:
        ok = np.all(np.abs(reflection - mwant) < tol * mwant, axis=-1)
        # The pattern, not just its mean: both kinds of cell are matched.
        for which, mask in [("bright", mbright), ("dim", mdim)]:
            assert ok[mask].mean() > 0.95, f"{name}: {ok[mask].mean():.3f} of the mirrored {which} cells match"
    # The probes' capture shades its hits through the same code (lib/trace_shade.glsl).
    probes = renderer.render(scene, settings=small(width=128, height=96, fallback="probes"))
    assert np.isfinite(probes.color).all()
    # The references' own pixels: the quad's direct light is its emission too.
    for name, r in [("glsl", ref), ("cpu", cpu)]:
        np.testing.assert_allclose(r.color[on_quad], want[on_quad], rtol=6e-3, err_msg=name)


def test_a_scene_without_an_emissive_texture_has_no_emission_layer(renderer):
    scene, _, quad = emissive_quad_over_mirror()
    with_texture = [(e.name, e.inputs, e.outputs) for e in renderer.chain(small(), scene=scene)]
    m = scene.material(quad)
    m.emissive_texture = -1
    scene.set_material(quad, m)
    chain = renderer.chain(small(), scene=scene)
    assert [e.name for e in chain] == [n for n, _, _ in with_texture]
    assert all("gbuffer.emission" not in e.outputs and "gbuffer.emission" not in e.inputs for e in chain)
    assert any("gbuffer.emission" in i for _, i, _ in with_texture)
    f = renderer.render(scene, settings=small())
    with pytest.raises(Exception, match="gbuffer.emission"):
        f.read("gbuffer.emission")
    # The factor alone is emitted (by object id, as before emissive textures).
    g = f.gbuffer
    on_quad = g.coverage[0] & (g.object_id[0] == quad)
    np.testing.assert_allclose(g.lit[0][on_quad], np.broadcast_to(FACTOR, (on_quad.sum(), 3)), rtol=1e-3)


def test_texture_transform_moves_the_emission(renderer, tmp_path):
    """KHR_texture_transform on the emissiveTexture (an offset of one cell along u) swaps the
    checkerboard's cells in the lit colour and in the C++ reference's mirror, and saving keeps it."""
    scene, floor, quad = emissive_quad_over_mirror()
    path = scene.save(tmp_path / "moved.gltf")
    doc = json.loads(path.read_text())
    m = [m for m in doc["materials"] if "emissiveTexture" in m][0]
    m["emissiveTexture"]["extensions"] = {"KHR_texture_transform": {"offset": [1.0 / CELLS, 0.0]}}
    doc["extensionsUsed"] = doc.get("extensionsUsed", []) + ["KHR_texture_transform"]
    path.write_text(json.dumps(doc))
    moved = ssrlab.Scene.load(path)
    again = json.loads(moved.save(tmp_path / "again.gltf").read_text())
    t = [m for m in again["materials"] if "emissiveTexture" in m][0]["emissiveTexture"]
    assert t["extensions"]["KHR_texture_transform"]["offset"] == pytest.approx([1.0 / CELLS, 0.0])

    f = renderer.render(moved, settings=small(width=128, height=96))
    g = f.gbuffer
    cam, d = pixel_rays(f)
    u, v = quad_uv(cam, d)
    want, centred = expected_emission(u + 1.0 / CELLS, v)
    on_quad = g.coverage[0] & (g.object_id[0] == quad) & centred & (u < 1.0 - 1.0 / CELLS)
    assert on_quad.sum() > 100
    np.testing.assert_allclose(g.lit[0][on_quad], want[on_quad], rtol=6e-3)

    on_floor = g.coverage[0] & (g.object_id[0] == floor)
    p = cam + d * (-cam[1] / d[..., 1])[..., None]
    mu, mv = quad_uv(p, d * np.array([1.0, -1.0, 1.0]))
    mwant, mcentred = expected_emission(mu + 1.0 / CELLS, mv)
    mirrored = on_floor & mcentred & (mu > 0.0) & (mu < 1.0 - 1.0 / CELLS)  # on the quad, unwrapped
    assert mirrored.sum() > 60
    cpu = f.reference("converged", rays=1, tracer="cpu")
    ok = np.all(np.abs(cpu.reflection - mwant) < 0.01 * mwant, axis=-1)
    assert ok[mirrored].mean() > 0.95, ok[mirrored].mean()
