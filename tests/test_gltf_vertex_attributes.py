"""glTF vertex colours (COLOR_0) and the second texture coordinate set (TEXCOORD_1): a quad whose
colours vary across it shows them in the G-buffer, the lit colour, SSR's reflection in a mirror
floor and both converged references; a vertex alpha below a MASK cutoff makes holes in every pass
that decides visibility; a texture on texCoord 1 samples TEXCOORD_1 everywhere; the one-pass lists
equal peeling on these scenes; and all of it survives a save and load."""

import json
import warnings

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import pixel_rays
from conftest import small
from test_deep_gbuffer import assert_same_layers

# The quad: x in [-1, 1], y in [Y0, Y1] at z = QZ, facing +z; uv (0, 0) at its top-left.
QZ, Y0, Y1 = -1.0, 0.3, 1.7
WALL_Z = -3.0
CELLS = 4
# From behind the camera's right: the shadow of the quad's (solid) right half falls on the wall
# behind its left half, seen through the hole.
LIGHT_DIR = np.array([-0.6, -0.2, -1.0]) / np.linalg.norm([-0.6, -0.2, -1.0])
CORNERS = [(-1, Y0, QZ), (1, Y0, QZ), (1, Y1, QZ), (-1, Y1, QZ)]
UVS = [(0, 1), (1, 1), (1, 0), (0, 0)]
SIZE = dict(width=160, height=120, layers=2)


def colour_at(u, v):
    """The quad's vertex colours: affine in (u, v), so the rasteriser's and the tracers'
    interpolation over either triangle gives exactly this."""
    return np.stack([0.1 + 0.8 * u, 0.1 + 0.8 * v, np.full_like(u, 0.5)], axis=-1)


def quad_uv(points, dirs):
    """(u, v) where rays cross the quad's plane, and whether they meet the quad ahead, away from
    its border by `margin` (edges are sampled differently by rasteriser and tracers)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (QZ - points[..., 2]) / dirs[..., 2]
    p = points + dirs * t[..., None]
    u, v = (p[..., 0] + 1) / 2, (Y1 - p[..., 1]) / (Y1 - Y0)
    inside = (t > 1e-3) & (u > 0.03) & (u < 0.97) & (v > 0.03) & (v < 0.97)
    return u, v, inside


def floor_mirror_rays(f):
    cam, d = pixel_rays(f)
    t = -cam[1] / d[..., 1]
    return cam + d * t[..., None], d * np.array([1.0, -1.0, 1.0]), t > 0


def base_scene(quad_material, **mesh):
    s = ssrlab.Scene()
    floor = s.add_plane((0, 0, 0), (16, 16), material=ssrlab.Material(
        base_color=(1, 1, 1), roughness=0.0, metallic=1.0, reflectivity=1.0), name="floor")
    wall = s.add_plane((0, 2, WALL_Z), (10, 4), normal=(0, 0, 1), material=ssrlab.Material(
        base_color=(0.1, 0.8, 0.1), roughness=1.0, reflectivity=0.0), name="wall")
    quad = s.add_mesh(CORNERS, [(0, 1, 2), (0, 2, 3)], uvs=UVS, material=quad_material, name="quad", **mesh)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 1.3, 4.0), target=(0.0, 0.7, -2.0), fov_y=45.0, near=0.1, far=50.0)
    return s, floor, wall, quad


def coloured_scene():
    """Lit by a white ambient term alone: a matte surface's lit colour is its albedo."""
    u, v = np.array(UVS, float).T
    colours = colour_at(u, v)
    s, floor, wall, quad = base_scene(ssrlab.Material(base_color=(1, 1, 1), roughness=1.0, reflectivity=0.0,
                                                      name="coloured"), colors=colours)
    s.ambient = (1.0, 1.0, 1.0)
    return s, floor, wall, quad


def vertex_alpha_scene():
    """A red quad whose vertex alpha runs 0 (left) to 1 (right), MASK at 0.5: its left half is a
    hole. A light from behind the camera casts its shadow on the wall."""
    u = np.array(UVS, float)[:, 0]
    colours = np.stack([np.full(4, 0.9), np.full(4, 0.1), np.full(4, 0.1), u], axis=-1)
    s, floor, wall, quad = base_scene(ssrlab.Material(base_color=(1, 1, 1), roughness=1.0, reflectivity=0.0,
                                                      double_sided=True, alpha_mode="MASK", alpha_cutoff=0.5,
                                                      name="faded"), colors=colours)
    s.add_light(ssrlab.directional_light(tuple(LIGHT_DIR), intensity=3.0, cast_shadow=True))
    s.ambient = (0.05, 0.05, 0.05)
    return s, floor, wall, quad


def checker_rgba(texels_per_cell=4):
    n = CELLS * texels_per_cell
    c = np.arange(n) // texels_per_cell
    red = (c[:, None] + c[None, :]) % 2 == 0  # rows v, columns u
    img = np.zeros((n, n, 4), np.uint8)
    img[..., 0] = np.where(red, 230, 20)
    img[..., 2] = np.where(red, 20, 230)
    img[..., 3] = 255
    return img


def texcoord_scene(tmp_path, texcoord=1, with_uvs1=True):
    """A quad with a red/blue checkerboard whose TEXCOORD_1 mirrors u (u1 = 1 - u): on 4 cells
    that swaps red and blue. The texture's texCoord is set in the saved file (the Python API has
    none); returns the loaded scene and the file's JSON."""
    uvs1 = [(1 - u, v) for u, v in UVS]
    s, floor, wall, quad = base_scene(ssrlab.Material(base_color=(1, 1, 1), roughness=1.0, reflectivity=0.0,
                                                      name="checker_mat"), uvs1=uvs1)
    tex = s.add_image(checker_rgba(), name="checker")
    m = s.material(quad)
    m.base_color_texture = tex
    s.set_material(quad, m)
    s.ambient = (1.0, 1.0, 1.0)
    path = s.save(tmp_path / f"texcoord{texcoord}.gltf")
    doc = json.loads(path.read_text())
    (mat,) = [m for m in doc["materials"] if m.get("name") == "checker_mat"]
    mat["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = texcoord
    if not with_uvs1:
        for mesh in doc["meshes"]:
            for p in mesh["primitives"]:
                p["attributes"].pop("TEXCOORD_1", None)
    path.write_text(json.dumps(doc))
    return path, (floor, wall, quad)


def checker_red(u, v):
    """Whether the checker is red at texture coordinates (u, v), and whether (u, v) is clear of a
    cell's edge (bilinear filtering blends within half a texel of it)."""
    cu, cv = u * CELLS, v * CELLS
    fu, fv = cu - np.floor(cu), cv - np.floor(cv)
    clear = (fu > 0.2) & (fu < 0.8) & (fv > 0.2) & (fv < 0.8)
    return (np.floor(cu) + np.floor(cv)) % 2 == 0, clear


@pytest.fixture(scope="module")
def renderer():
    return ssrlab.Renderer("auto")


def test_vertex_colours_in_gbuffer_frame_ssr_and_references(renderer):
    scene, floor, wall, quad = coloured_scene()
    f = renderer.render(scene, settings=small(**SIZE))
    cam, d = pixel_rays(f)
    u, v, inside = quad_uv(cam, d)
    g = f.gbuffer
    on_quad = inside & g.coverage[0] & (g.object_id[0] == quad)
    assert on_quad.sum() > 1000
    expect = colour_at(u, v)
    # gbuffer.albedo: 8 bits a channel; the lit colour (ambient 1 x albedo) and frame.color follow it.
    err = np.abs(g.albedo[0][on_quad] - expect[on_quad]).max()
    print(f"quad pixels {on_quad.sum()}: albedo max error {err:.4f}")
    assert err < 0.01
    assert np.abs(f.color[on_quad] - expect[on_quad]).max() < 0.01
    # The mirror floor: SSR's reflection and the converged references (GLSL tracer and the
    # Embree + C++ port) show the colours where the mirrored ray meets the quad.
    p, rd, ahead = floor_mirror_rays(f)
    mu, mv, minside = quad_uv(p, rd)
    mirror = ahead & minside & g.coverage[0] & (g.object_id[0] == floor)
    assert mirror.sum() > 300
    mexpect = colour_at(mu, mv)[mirror]
    for name, refl in [("SSR", f.reflection),
                       ("reference glsl", f.reference("converged", rays=1, tracer="glsl").reflection),
                       ("reference cpu", f.reference("converged", rays=1, tracer="cpu").reflection)]:
        close = (np.abs(refl[mirror] - mexpect).max(axis=-1) < 0.02).mean()
        print(f"{name}: {close:.3f} of {mirror.sum()} mirror pixels within 0.02 of the vertex colour")
        assert close > (0.9 if name == "SSR" else 0.98), name


def test_vertex_alpha_makes_holes_everywhere(renderer):
    scene, floor, wall, quad = vertex_alpha_scene()
    f = renderer.render(scene, settings=small(**SIZE))
    cam, d = pixel_rays(f)
    u, v, inside = quad_uv(cam, d)
    g = f.gbuffer
    holes, solid = inside & (u < 0.45), inside & (u > 0.55)
    assert holes.sum() > 300 and solid.sum() > 300
    # G-buffer coverage: what is behind (the wall, low rays the floor) through the hole, the quad
    # (and the wall behind it) elsewhere.
    assert (g.object_id[0][holes] != quad).mean() > 0.99 and (g.object_id[0][holes] == wall).mean() > 0.9
    assert (g.object_id[0][solid] == quad).mean() > 0.99
    assert (g.coverage[1][solid] & (g.object_id[1][solid] != quad)).mean() > 0.99
    # The shadow map: light through the hole reaches the wall.
    t = (WALL_Z - cam[..., 2]) / d[..., 2]
    pw = cam + d * t[..., None]
    lu, lv, linside = quad_uv(pw, -np.broadcast_to(LIGHT_DIR, pw.shape))
    on_wall = g.coverage[0] & (g.object_id[0] == wall)
    lit_through, shadowed = on_wall & linside & (lu < 0.4), on_wall & linside & (lu > 0.6)
    assert lit_through.sum() > 100 and shadowed.sum() > 100
    lit = g.lit[0][..., 1]
    print(f"wall lit through the hole {np.median(lit[lit_through]):.4f}, shadowed {np.median(lit[shadowed]):.4f}")
    assert (lit[lit_through] > 4 * np.median(lit[shadowed])).mean() > 0.95
    # The BVH's alpha test (per-ray truth) and Embree's masks (converged, tracer "cpu").
    p, rd, ahead = floor_mirror_rays(f)
    mu, mv, minside = quad_uv(p, rd)
    mirror = ahead & minside & g.coverage[0] & (g.object_id[0] == floor)
    mholes, msolid = mirror & (mu < 0.45), mirror & (mu > 0.55)
    assert mholes.sum() > 100 and msolid.sum() > 100
    truth = f.reference("per_ray")
    assert (truth.object[0][mholes] == wall).mean() > 0.99
    assert (truth.object[0][msolid] == quad).mean() > 0.99
    for name, refl in [("SSR", f.reflection),
                       ("reference cpu", f.reference("converged", rays=1, tracer="cpu").reflection)]:
        green = (refl[mholes][:, 1] > refl[mholes][:, 0]).mean()
        red = (refl[msolid][:, 0] > refl[msolid][:, 1]).mean()
        print(f"{name}: the wall through {green:.3f} of the hole's mirror pixels, the quad on {red:.3f}")
        assert green > 0.9 and red > 0.9, name


def test_texcoord_1_samples_the_second_set(renderer, tmp_path):
    path, (floor, wall, quad) = texcoord_scene(tmp_path, texcoord=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ssrlab.SceneWarning)
        scene = ssrlab.Scene.load(path)
    set0 = ssrlab.Scene.load(texcoord_scene(tmp_path, texcoord=0)[0])
    f = renderer.render(scene, settings=small(**SIZE))
    f0 = renderer.render(set0, settings=small(**SIZE))
    cam, d = pixel_rays(f)
    u, v, inside = quad_uv(cam, d)
    red1, clear = checker_red(1 - u, v)  # TEXCOORD_1 = (1 - u, v)
    red0, _ = checker_red(u, v)
    assert ((red1 != red0) | ~clear).all(), "the two sets give opposite cells"
    g = f.gbuffer
    cells = inside & clear & g.coverage[0] & (g.object_id[0] == quad)
    assert cells.sum() > 300
    a1, a0 = g.albedo[0][cells], f0.gbuffer.albedo[0][cells]
    assert ((a1[:, 0] > a1[:, 2]) == red1[cells]).mean() > 0.99, "texCoord 1: TEXCOORD_1's cells"
    assert ((a0[:, 0] > a0[:, 2]) == red0[cells]).mean() > 0.99, "texCoord 0: TEXCOORD_0's cells"
    # Both converged references see TEXCOORD_1's cells in the mirror.
    p, rd, ahead = floor_mirror_rays(f)
    mu, mv, minside = quad_uv(p, rd)
    mred, mclear = checker_red(1 - mu, mv)
    mirror = ahead & minside & mclear & g.coverage[0] & (g.object_id[0] == floor)
    assert mirror.sum() > 100
    for tracer in ("glsl", "cpu"):
        refl = f.reference("converged", rays=1, tracer=tracer).reflection[mirror]
        agree = ((refl[:, 0] > refl[:, 2]) == mred[mirror]).mean()
        print(f"reference {tracer}: {agree:.3f} of {mirror.sum()} mirror pixels show TEXCOORD_1's cell")
        assert agree > 0.98, tracer


def test_a_missing_set_1_warns_once_and_samples_set_0(renderer, tmp_path):
    path, (floor, wall, quad) = texcoord_scene(tmp_path, texcoord=1, with_uvs1=False)
    with pytest.warns(ssrlab.SceneWarning, match="checker_mat.*TEXCOORD_1") as record:
        scene = ssrlab.Scene.load(path)
    assert sum("TEXCOORD_1" in str(w.message) for w in record) == 1
    f = renderer.render(scene, settings=small(**SIZE))
    cam, d = pixel_rays(f)
    u, v, inside = quad_uv(cam, d)
    red0, clear = checker_red(u, v)
    cells = inside & clear & f.gbuffer.coverage[0] & (f.gbuffer.object_id[0] == quad)
    a = f.gbuffer.albedo[0][cells]
    assert ((a[:, 0] > a[:, 2]) == red0[cells]).mean() > 0.99
    # A set beyond 1 is not loaded: a warning, and set 0.
    doc = json.loads(path.read_text())
    (mat,) = [m for m in doc["materials"] if m.get("name") == "checker_mat"]
    mat["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 3
    path.write_text(json.dumps(doc))
    with pytest.warns(ssrlab.SceneWarning, match="texCoord 3"):
        ssrlab.Scene.load(path)


def test_lists_equal_peeling_with_vertex_attributes(renderer, tmp_path):
    for what, scene in [("vertex colours", coloured_scene()[0]), ("vertex alpha", vertex_alpha_scene()[0]),
                        ("texCoord 1", ssrlab.Scene.load(texcoord_scene(tmp_path)[0]))]:
        assert_same_layers(renderer, scene, scene.camera, what, layers=2)


def test_round_trip_and_validation(tmp_path):
    path, (floor, wall, quad) = texcoord_scene(tmp_path, texcoord=1)
    scene = ssrlab.Scene.load(path)
    u, v = np.array(UVS, float).T
    colours = np.concatenate([colour_at(u, v), [[1.0], [0.25], [0.5], [0.75]]], axis=1)
    extra = scene.add_mesh(CORNERS, [(0, 1, 2), (0, 2, 3)], uvs=UVS, colors=colours, name="extra")
    again = ssrlab.Scene.load(scene.save(tmp_path / "again.gltf"))
    doc = json.loads((tmp_path / "again.gltf").read_text())
    (mat,) = [m for m in doc["materials"] if m.get("name") == "checker_mat"]
    assert mat["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] == 1
    assert any("COLOR_0" in p["attributes"] for m in doc["meshes"] for p in m["primitives"])
    np.testing.assert_array_equal(again.object_mesh(quad)["uvs1"], np.array([(1 - a, b) for a, b in UVS], np.float32))
    np.testing.assert_array_equal(again.object_mesh(extra)["colors"], colours.astype(np.float32))
    assert "colors" not in again.object_mesh(floor) and "uvs1" not in again.object_mesh(floor)
    # RGB colours get alpha 1; bad input names the parameter.
    s = ssrlab.Scene()
    i = s.add_mesh(CORNERS, [(0, 1, 2)], colors=colours[:, :3])
    np.testing.assert_array_equal(s.object_mesh(i)["colors"][:, 3], 1.0)
    for kw, match in [(dict(colors=colours[:3]), "colors"), (dict(colors=colours[:, :2]), "colors"),
                      (dict(colors=colours * 2), r"colors must be in \[0, 1\]"),
                      (dict(colors=np.full((4, 4), np.nan)), "colors"), (dict(uvs1=[(0, 0)] * 3), "uvs1"),
                      (dict(uvs1=[(0, np.inf)] * 4), "uvs1")]:
        with pytest.raises(ValueError, match=match):
            s.add_mesh(CORNERS, [(0, 1, 2)], **kw)


def normal_texcoord_scene(tmp_path, texcoord):
    """A quad with a constant normal texture tilted 30 degrees toward its set's +u and no mesh
    tangents: the derivative tangent frame follows the normal texture's set. TEXCOORD_0's u runs
    along +x, TEXCOORD_1's (1 - v) along +y. A light from +x+z lights the +x tilt more."""
    s, floor, wall, quad = base_scene(ssrlab.Material(base_color=(1, 1, 1), roughness=1.0, reflectivity=0.0,
                                                      name="bumped"), uvs1=[(1 - v, u) for u, v in UVS])
    texel = np.array([np.sin(np.pi / 6), 0.0, np.cos(np.pi / 6)]) * 0.5 + 0.5
    img = np.zeros((4, 4, 4), np.uint8)
    img[..., :3] = np.round(texel * 255).astype(np.uint8)
    img[..., 3] = 255
    m = s.material(quad)
    m.normal_texture = s.add_image(img, name="tilt")
    s.set_material(quad, m)
    s.add_light(ssrlab.directional_light((-1.0, 0.0, -1.0), intensity=3.0))
    s.ambient = (0.0, 0.0, 0.0)
    path = s.save(tmp_path / f"normal{texcoord}.gltf")
    doc = json.loads(path.read_text())
    (mat,) = [m for m in doc["materials"] if m.get("name") == "bumped"]
    mat["normalTexture"]["texCoord"] = texcoord
    path.write_text(json.dumps(doc))
    return ssrlab.Scene.load(path), (floor, wall, quad)


def test_normal_texture_frame_follows_its_set(renderer, tmp_path):
    frames = {}
    for k in (0, 1):
        scene, (floor, wall, quad) = normal_texcoord_scene(tmp_path, k)
        frames[k] = renderer.render(scene, settings=small(**SIZE))
    f0, f1 = frames[0], frames[1]
    cam, d = pixel_rays(f0)
    u, v, inside = quad_uv(cam, d)
    on_quad = inside & (f0.gbuffer.object_id[0] == quad) & (f1.gbuffer.object_id[0] == quad)
    assert on_quad.sum() > 1000
    n0, n1 = f0.gbuffer.normal[0][on_quad], f1.gbuffer.normal[0][on_quad]
    # View x is world x (the camera has no roll): set 0 tilts the normal along x, set 1 up (by less
    # than 30 degrees where the cotangent frame's axes differ in length: the quad is not square).
    print(f"median view normal, texCoord 0: {np.median(n0, axis=0)}, texCoord 1: {np.median(n1, axis=0)}")
    assert (n0[:, 0] > 0.3).mean() > 0.99 and (n0[:, 1] < 0.2).mean() > 0.99
    assert (np.abs(n1[:, 0]) < 0.03).mean() > 0.99 and (n1[:, 1] > 0.35).mean() > 0.99
    # The tracers build the frame from the same set: in the mirror, the quad lit by the light from
    # +x+z is brighter with the x tilt by the cosines' ratio, as SSR's (the G-buffer's) is.
    p, rd, ahead = floor_mirror_rays(f0)
    mu, mv, minside = quad_uv(p, rd)
    g = f0.gbuffer
    mirror = ahead & minside & g.coverage[0] & (g.object_id[0] == floor)
    assert mirror.sum() > 300
    ratios = {}
    for name, get in [("SSR", lambda f: f.reflection),
                      ("reference glsl", lambda f: f.reference("converged", rays=1, tracer="glsl").reflection),
                      ("reference cpu", lambda f: f.reference("converged", rays=1, tracer="cpu").reflection)]:
        ratios[name] = np.median(get(f0)[mirror][:, 1] / np.maximum(get(f1)[mirror][:, 1], 1e-6))
    print("set 0 / set 1 brightness in the mirror:", {k: round(float(r), 3) for k, r in ratios.items()})
    assert ratios["SSR"] > 1.3
    for name in ("reference glsl", "reference cpu"):
        assert abs(ratios[name] / ratios["SSR"] - 1) < 0.05, name


@pytest.mark.parametrize("component, normalized, columns", [(5121, True, 3), (5123, True, 4), (5121, False, 4)])
def test_colour_accessor_kinds(tmp_path, component, normalized, columns):
    """COLOR_0 as normalised unsigned bytes (VEC3: alpha 1) or shorts (VEC4) loads as values / 255
    or / 65535; an integer accessor that is not normalised is a SceneError naming COLOR_0."""
    import base64
    s = ssrlab.Scene()
    s.add_mesh(CORNERS, [(0, 1, 2), (0, 2, 3)], name="quad")
    path = s.save(tmp_path / "colours.gltf")
    doc = json.loads(path.read_text())
    top = 255 if component == 5121 else 65535
    values = (np.arange(4 * columns).reshape(4, columns) * (top // 16)).astype(np.uint8 if component == 5121 else np.uint16)
    stride = (values.itemsize * columns + 3) // 4 * 4  # glTF: vertex attribute strides are multiples of 4
    raw = np.zeros((4, stride), np.uint8)
    raw[:, :values.itemsize * columns] = values.view(np.uint8).reshape(4, -1)
    doc["buffers"].append({"byteLength": raw.size,
                           "uri": "data:application/octet-stream;base64," + base64.b64encode(raw.tobytes()).decode()})
    doc["bufferViews"].append({"buffer": len(doc["buffers"]) - 1, "byteOffset": 0, "byteLength": raw.size,
                               "byteStride": stride, "target": 34962})
    doc["accessors"].append({"bufferView": len(doc["bufferViews"]) - 1, "componentType": component,
                             "normalized": normalized, "count": 4, "type": f"VEC{columns}"})
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = len(doc["accessors"]) - 1
    path.write_text(json.dumps(doc))
    if not normalized:
        with pytest.raises(ssrlab.SceneError, match="COLOR_0.*normalized"):
            ssrlab.Scene.load(path)
        return
    colours = ssrlab.Scene.load(path).object_mesh(0)["colors"]
    expect = np.ones((4, 4), np.float32)
    expect[:, :columns] = values / np.float32(top)
    np.testing.assert_allclose(colours, expect, rtol=1e-6)


@pytest.mark.parametrize("construction", ["visibility", "visibility_lists"])
def test_vertex_colours_in_the_visibility_constructions(renderer, construction):
    """The attribute pass reads the vertex colours only where some vertex is not white: here it
    must, and the albedo follows them as peeling's does."""
    scene, floor, wall, quad = coloured_scene()
    f = renderer.render(scene, settings=small(deep_gbuffer=construction, **SIZE))
    cam, d = pixel_rays(f)
    u, v, inside = quad_uv(cam, d)
    g = f.gbuffer
    on_quad = inside & g.coverage[0] & (g.object_id[0] == quad)
    assert on_quad.sum() > 1000
    assert np.abs(g.albedo[0][on_quad] - colour_at(u, v)[on_quad]).max() < 0.01
