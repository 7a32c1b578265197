"""glTF alphaMode MASK (and BLEND, tested as MASK at 0.5): a masked quad's holes in every pass that
decides visibility — the G-buffer (peeling and the one-pass lists), the lit colour, SSR's hits,
the BVH traversals (per-ray truth, converged reference on the GLSL tracer and on Embree) and the
shadow map."""

import json
import warnings

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import pixel_rays
from conftest import small

# The quad: x in [-1, 1], y in [Y0, Y1] at z = QZ, facing +z; uv (0, 0) at its top-left.
QZ, Y0, Y1 = -1.0, 0.3, 1.7
WALL_Z = -3.0
CELLS = 4  # checker cells across the quad; even cells (cx + cy even) opaque, odd ones holes
LIGHT_DIR = np.array([0.6, -0.2, -1.0]) / np.linalg.norm([0.6, -0.2, -1.0])


def checker_rgba(texels_per_cell=4):
    n = CELLS * texels_per_cell
    c = np.arange(n) // texels_per_cell
    opaque = (c[:, None] + c[None, :]) % 2 == 0
    img = np.zeros((n, n, 4), np.uint8)
    img[..., 0] = 230
    img[..., 1] = 25
    img[..., 2] = 25
    img[..., 3] = np.where(opaque, 255, 0)
    return img


def masked_scene(alpha_mode="MASK", cutoff=0.5, base_alpha=1.0):
    """A mirror floor, a green matte wall, and a red quad with a checkerboard alpha between the
    camera and the wall; a directional light from behind the camera casts the quad's shadow."""
    s = ssrlab.Scene()
    floor = s.add_plane((0, 0, 0), (16, 16), material=ssrlab.Material(
        base_color=(1, 1, 1), roughness=0.0, metallic=1.0, reflectivity=1.0), name="floor")
    wall = s.add_plane((0, 2, WALL_Z), (10, 4), normal=(0, 0, 1), material=ssrlab.Material(
        base_color=(0.1, 0.8, 0.1), roughness=1.0, reflectivity=0.0), name="wall")
    tex = s.add_image(checker_rgba(), name="checker")
    mat = ssrlab.Material(base_color=(1, 1, 1, base_alpha), roughness=1.0, reflectivity=0.0, base_color_texture=tex,
                          double_sided=True, alpha_mode=alpha_mode, alpha_cutoff=cutoff, name="masked")
    quad = s.add_mesh([(-1, Y0, QZ), (1, Y0, QZ), (1, Y1, QZ), (-1, Y1, QZ)], [(0, 1, 2), (0, 2, 3)],
                      uvs=[(0, 1), (1, 1), (1, 0), (0, 0)], material=mat, name="quad")
    s.add_light(ssrlab.directional_light(tuple(LIGHT_DIR), intensity=3.0, cast_shadow=True))
    s.ambient = (0.05, 0.05, 0.05)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 1.3, 4.0), target=(0.0, 0.7, -2.0), fov_y=45.0, near=0.1, far=50.0)
    return s, floor, wall, quad


def classify(points, dirs):
    """Where rays from `points` along `dirs` cross the quad's plane: 1 through an opaque cell,
    0 through a hole, -1 outside the quad, behind the origin or too near a cell's edge (bilinear
    filtering blends the alpha within half a texel of it)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (QZ - points[..., 2]) / dirs[..., 2]
    p = points + dirs * t[..., None]
    u, v = (p[..., 0] + 1) / 2, (Y1 - p[..., 1]) / (Y1 - Y0)
    cu, cv = u * CELLS, v * CELLS
    fu, fv = cu - np.floor(cu), cv - np.floor(cv)
    clear = (fu > 0.2) & (fu < 0.8) & (fv > 0.2) & (fv < 0.8)
    inside = (t > 1e-3) & (u > 0) & (u < 1) & (v > 0) & (v < 1) & clear
    opaque = (np.floor(cu) + np.floor(cv)) % 2 == 0
    return np.where(inside, np.where(opaque, 1, 0), -1)


def floor_mirror_rays(f):
    """Floor points seen by the camera and their mirrored ray directions."""
    cam, d = pixel_rays(f)
    t = -cam[1] / d[..., 1]
    p = cam + d * t[..., None]
    return p, d * np.array([1.0, -1.0, 1.0]), t > 0


def ssr_hit_object(f):
    """The object at the G-buffer texel SSR's (single) ray hit, -1 for a miss."""
    r = f.rays
    layer = r.hit_layer[0] - 1
    px = np.clip(np.floor(r.hit_pixel[0]).astype(int), 0, [f.settings.width - 1, f.settings.height - 1])
    obj = f.gbuffer.object_id[np.maximum(layer, 0), px[..., 1], px[..., 0]]
    return np.where(layer >= 0, obj, -1)


@pytest.fixture(scope="module")
def frame_and_ids():
    r = ssrlab.Renderer("auto")
    scene, floor, wall, quad = masked_scene()
    f = r.render(scene, settings=small(width=160, height=120, layers=2, deep_gbuffer="peel"))
    yield r, scene, f, (floor, wall, quad)


def test_holes_in_gbuffer_and_colour(frame_and_ids):
    _, _, f, (floor, wall, quad) = frame_and_ids
    cam, d = pixel_rays(f)
    cls = classify(cam, d)
    g = f.gbuffer
    holes, solid = cls == 0, cls == 1
    assert holes.sum() > 200 and solid.sum() > 200
    # Through a hole the camera sees the wall, on an opaque cell the quad.
    assert (g.object_id[0][holes] == wall).mean() > 0.99
    assert (g.object_id[0][solid] == quad).mean() > 0.99
    # The second layer behind an opaque cell is the wall (peeling steps through the quad too).
    assert (g.object_id[1][solid] == wall).mean() > 0.99
    c = f.color
    assert (c[holes][:, 1] > c[holes][:, 0]).mean() > 0.99, "holes show the green wall"
    assert (c[solid][:, 0] > c[solid][:, 1]).mean() > 0.99, "opaque cells show the red quad"


def test_lists_construction_sees_the_same_holes(frame_and_ids):
    r, scene, f, _ = frame_and_ids
    lists = r.render(scene, settings=small(width=160, height=120, layers=2, deep_gbuffer="lists"))
    assert lists.stats["deep_gbuffer_method"] == "lists"
    np.testing.assert_array_equal(lists.gbuffer.object_id, f.gbuffer.object_id)
    np.testing.assert_array_equal(lists.gbuffer.coverage, f.gbuffer.coverage)


def test_reflections_see_the_holes_in_ssr_bvh_and_references(frame_and_ids):
    r, scene, f, (floor, wall, quad) = frame_and_ids
    p, rd, ahead = floor_mirror_rays(f)
    g = f.gbuffer
    on_floor = ahead & g.coverage[0] & (g.object_id[0] == floor)
    cls = np.where(on_floor, classify(p, rd), -1)
    holes, solid = cls == 0, cls == 1
    assert holes.sum() > 100 and solid.sum() > 100
    # The per-ray truth (the GLSL BVH traversal with its any-hit alpha test).
    truth = f.reference("per_ray")
    assert (truth.object[0][holes] == wall).mean() > 0.99
    assert (truth.object[0][solid] == quad).mean() > 0.99
    # SSR finds what the truth finds (the wall behind a hole from the deep G-buffer).
    ssr = ssr_hit_object(f)
    print(f"mirror pixels through holes {holes.sum()}, on cells {solid.sum()}; SSR finds the wall through "
          f"{(ssr[holes] == wall).mean():.3f} of the holes, the quad on {(ssr[solid] == quad).mean():.3f} of the cells")
    assert (ssr[holes] == wall).mean() > 0.9, (ssr[holes] == wall).mean()
    assert (ssr[solid] == quad).mean() > 0.9, (ssr[solid] == quad).mean()
    # method="bvh" traces the same BVH for every ray.
    bvh = r.render(scene, settings=small(width=160, height=120, layers=2, deep_gbuffer="peel", method="bvh"))
    for name, refl in [("SSR", f.reflection), ("method=bvh", bvh.reflection),
                       ("reference glsl", f.reference("converged", rays=1, tracer="glsl").reflection),
                       ("reference embree", f.reference("converged", rays=1, tracer="embree").reflection)]:
        print(f"{name}: green through {(refl[holes][:, 1] > refl[holes][:, 0]).mean():.3f} of the holes, red on "
              f"{(refl[solid][:, 0] > refl[solid][:, 1]).mean():.3f} of the cells")
        assert (refl[holes][:, 1] > refl[holes][:, 0]).mean() > 0.9, f"{name}: the wall through the holes"
        assert (refl[solid][:, 0] > refl[solid][:, 1]).mean() > 0.9, f"{name}: the quad's opaque cells"


def test_masked_quad_casts_holed_shadows(frame_and_ids):
    _, _, f, (floor, wall, quad) = frame_and_ids
    cam, d = pixel_rays(f)
    g = f.gbuffer
    t = (WALL_Z - cam[..., 2]) / d[..., 2]
    p = cam + d * t[..., None]
    on_wall = g.coverage[0] & (g.object_id[0] == wall)
    cls = np.where(on_wall, classify(p, -np.broadcast_to(LIGHT_DIR, p.shape)), -1)
    lit_through, shadowed = cls == 0, cls == 1
    lit = g.lit[0][..., 1]
    print(f"wall pixels lit through holes {lit_through.sum()}, shadowed {shadowed.sum()}; median lit "
          f"{np.median(lit[lit_through]):.4f} vs {np.median(lit[shadowed]):.4f}")
    assert lit_through.sum() > 100 and shadowed.sum() > 100
    # Light through a hole reaches the wall as if nothing were there; an opaque cell leaves the
    # ambient term only (the shadow map's filtering blurs edges, which the margin skips).
    assert np.median(lit[lit_through]) > 5 * np.median(lit[shadowed])
    assert (lit[lit_through] > 4 * np.median(lit[shadowed])).mean() > 0.95


def test_blend_is_a_mask_at_half_and_alpha_round_trips(tmp_path):
    # BLEND with a factor alpha of 0.4 is all holes, at 0.6 none (the texture's opaque cells).
    r = ssrlab.Renderer("auto")
    for base_alpha, expect_quad in [(0.4, False), (0.6, True)]:
        scene, _, wall, quad = masked_scene("BLEND", base_alpha=base_alpha)
        f = r.render(scene, settings=small(width=96, height=72, layers=1))
        cam, d = pixel_rays(f)
        solid = classify(cam, d) == 1
        assert solid.sum() > 50
        assert (f.gbuffer.object_id[0][solid] == (quad if expect_quad else wall)).mean() > 0.99
    # MASK's cutoff travels through glTF; BLEND loads with a SceneWarning naming the material.
    scene, _, _, quad = masked_scene("MASK", cutoff=0.3)
    path = scene.save(tmp_path / "masked.gltf")
    doc = json.loads(path.read_text())
    (m,) = [m for m in doc["materials"] if m.get("name") == "masked"]
    assert m["alphaMode"] == "MASK" and m["alphaCutoff"] == pytest.approx(0.3)
    loaded = ssrlab.Scene.load(path)
    assert loaded.material(quad).alpha_mode == "MASK" and loaded.material(quad).alpha_cutoff == pytest.approx(0.3)
    m["alphaMode"] = "BLEND"
    path.write_text(json.dumps(doc))
    with pytest.warns(ssrlab.SceneWarning, match="BLEND.*masked"):
        loaded = ssrlab.Scene.load(path)
    assert loaded.material(quad).alpha_mode == "BLEND"
    m["alphaMode"] = "CUTOUT"
    path.write_text(json.dumps(doc))
    with pytest.raises(ssrlab.SceneError, match="alphaMode"):
        ssrlab.Scene.load(path)
    with pytest.raises(ValueError, match="alpha_mode"):
        ssrlab.Material(alpha_mode="CUTOUT")
    with pytest.raises(ValueError, match="alpha_cutoff"):
        ssrlab.Material().alpha_cutoff = -0.5


def test_texture_transform_moves_the_holes(tmp_path):
    """KHR_texture_transform on the mask: an offset of one checker cell swaps holes and cells, in
    the G-buffer, the per-ray truth and Embree's converged reference alike; it survives a save."""
    r = ssrlab.Renderer("auto")
    scene, floor, wall, quad = masked_scene()
    path = scene.save(tmp_path / "masked.gltf")
    doc = json.loads(path.read_text())
    (m,) = [m for m in doc["materials"] if m.get("name") == "masked"]
    m["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
        "KHR_texture_transform": {"offset": [1.0 / CELLS, 0.0]}}
    doc.setdefault("extensionsUsed", []).append("KHR_texture_transform")
    path.write_text(json.dumps(doc))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)  # the extension is rendered: not named
        loaded = ssrlab.Scene.load(path)
    again = json.loads(loaded.save(tmp_path / "again.gltf").read_text())
    (m2,) = [m for m in again["materials"] if m.get("name") == "masked"]
    t = m2["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]
    np.testing.assert_allclose(t["offset"], [1.0 / CELLS, 0.0], atol=1e-7)
    np.testing.assert_allclose(t["scale"], [1.0, 1.0], atol=1e-7)
    assert t["rotation"] == pytest.approx(0.0, abs=1e-7)

    f = r.render(loaded, settings=small(width=160, height=120, layers=2, deep_gbuffer="peel"))
    cam, d = pixel_rays(f)
    cls = classify(cam, d)
    g = f.gbuffer
    # The untransformed pattern's holes now hold opaque cells and vice versa.
    assert (g.object_id[0][cls == 1] == wall).mean() > 0.99
    assert (g.object_id[0][cls == 0] == quad).mean() > 0.99
    p, rd, ahead = floor_mirror_rays(f)
    on_floor = ahead & g.coverage[0] & (g.object_id[0] == floor)
    mirrored = np.where(on_floor, classify(p, rd), -1)
    truth = f.reference("per_ray")
    assert (truth.object[0][mirrored == 1] == wall).mean() > 0.99
    assert (truth.object[0][mirrored == 0] == quad).mean() > 0.99
    refl = f.reference("converged", rays=1, tracer="embree").reflection
    assert (refl[mirrored == 1][:, 1] > refl[mirrored == 1][:, 0]).mean() > 0.9
    assert (refl[mirrored == 0][:, 0] > refl[mirrored == 0][:, 1]).mean() > 0.9
