"""Every light that casts a shadow gets a map (passes/shadow_map.h): a directional and a spot light
each a layer of the 2D array, a point light a cube. Each light's shadow removes that light's
share of a pixel, in frame.color and in the references (shadows="map" reads the same maps,
shadows="traced" traces a ray to every casting light), whatever light comes first."""

import numpy as np
import pytest

import ssrlab
from ssrlab.analytic import pixel_rays
from conftest import small

pytestmark = pytest.mark.filterwarnings("ignore::ssrlab.NoReflectionWarning")  # matte floors: nothing reflects

SUN_DIR = np.array([1.0, -0.9, 0.6])
SPOT_POS = np.array([-2.0, 3.0, 1.0])
# Boxes (lo, hi): one in the sun's light only (outside the spot's cone), one under the spot.
SUN_BOX = (np.array([0.9, 0.0, -2.4]), np.array([2.1, 1.4, -1.2]))
SPOT_BOX = (np.array([-2.4, 0.0, 1.5]), np.array([-1.6, 1.5, 2.1]))
POINT_POS = np.array([0.0, 1.2, 0.0])
# Around the point light: boxes whose shadows fall on the floor in the cube's +X, -X, +Z, -Z
# faces (farther from the light's foot than it is high) and one in its -Y face (nearer).
POINT_BOXES = [(np.array(c) - np.array(h), np.array(c) + np.array(h)) for c, h in [
    ((1.6, 0.25, 0.0), (0.25, 0.25, 0.25)), ((-1.6, 0.25, 0.0), (0.25, 0.25, 0.25)),
    ((0.0, 0.25, 1.6), (0.25, 0.25, 0.25)), ((0.0, 0.25, -1.6), (0.25, 0.25, 0.25)),
    ((-0.5, 0.25, 0.5), (0.22, 0.25, 0.22))]]
SETTINGS = small(width=128, height=96, shadow_map_size=1024)


def matte_floor_scene(lights, boxes):
    s = ssrlab.Scene()
    s.add_plane((0, 0, 0), (14, 14), material=ssrlab.Material(
        base_color=(0.8, 0.8, 0.8), roughness=1.0, metallic=0.0, reflectivity=0.0))
    for lo, hi in boxes:
        s.add_box(tuple((lo + hi) / 2), tuple(hi - lo), material=ssrlab.Material(
            base_color=(0.5, 0.5, 0.5), roughness=1.0, reflectivity=0.0))
    for light in lights:
        s.add_light(light)
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = ssrlab.Environment.constant((0.0, 0.0, 0.0))
    s.camera = ssrlab.Camera(position=(0.0, 6.5, 3.5), target=(0.0, 0.0, -0.3), fov_y=55.0, near=0.1, far=50.0)
    return s


def sun(cast=True):
    return ssrlab.directional_light(tuple(SUN_DIR), intensity=2.0, cast_shadow=cast)


def spot(cast=True):
    return ssrlab.spot_light(tuple(SPOT_POS), (0.0, -1.0, -0.1), inner_cone=0.5, outer_cone=0.75, intensity=25.0,
                             cast_shadow=cast)


def point(cast=True):
    return ssrlab.point_light(tuple(POINT_POS), intensity=6.0, cast_shadow=cast)


def floor_points(f):
    cam, d = pixel_rays(f)
    return cam + d * (-cam[1] / d[..., 1])[..., None]


def crosses(p, direction, box, t_max=np.inf, grow=0.0):
    """Whether the rays p + t direction, 0 < t < t_max, cross the box grown by `grow` on every side
    (negative: shrunk)."""
    lo, hi = box[0] - grow, box[1] + grow
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (lo - p) / direction, (hi - p) / direction
    return np.maximum(np.minimum(t0, t1).max(-1), 0.0) < np.minimum(np.maximum(t0, t1).min(-1), t_max)


def masks(f, lights_and_boxes, margin=0.08):
    """Per light, the floor pixels in its shadow and out of it, each by `margin` (world units) clear
    of the shadow's edge (boxes shrunk or grown): the maps' filtering blurs the edges."""
    p = floor_points(f)
    g = f.gbuffer
    floor = g.coverage[0] & (g.object_id[0] == 0)
    out = []
    for kind, where, boxes in lights_and_boxes:
        direction, t_max = (-where, np.inf) if kind == "sun" else (where - p, 1.0)
        inside = np.any([crosses(p, direction, b, t_max, -margin) for b in boxes], axis=0)
        outside = ~np.any([crosses(p, direction, b, t_max, margin) for b in boxes], axis=0)
        out.append((floor & inside, floor & outside))
    return out


@pytest.fixture(scope="module")
def two_lights(renderer):
    boxes = [SUN_BOX, SPOT_BOX]
    both = renderer.render(matte_floor_scene([sun(), spot()], boxes), settings=SETTINGS)
    sun_only = renderer.render(matte_floor_scene([sun(False)], boxes), settings=SETTINGS).color
    spot_only = renderer.render(matte_floor_scene([spot(False)], boxes), settings=SETTINGS).color
    return both, sun_only, spot_only


def test_directional_and_spot_each_cast_their_shadow(two_lights):
    """A pixel in one light's shadow loses exactly that light's share (the unshadowed render of
    the light alone), keeps the other's; out of both shadows it keeps both."""
    f, sun_only, spot_only = two_lights
    assert f.passes.index("shadow_map") < f.passes.index("lighting")
    (in_sun, out_sun), (in_spot, out_spot) = masks(f, [("sun", SUN_DIR, [SUN_BOX, SPOT_BOX]),
                                                       ("spot", SPOT_POS, [SUN_BOX, SPOT_BOX])])
    c = f.color[..., 1]
    a, b = sun_only[..., 1], spot_only[..., 1]
    # Where the light's share is a visible part of the pixel (the spot lights its cone only).
    sun_matters, spot_matters = a > 0.2 * (a + b), b > 0.2 * (a + b)
    for name, mask, expect, lost in [("sun shadow", in_sun & out_spot & sun_matters, b, a),
                                     ("spot shadow", in_spot & out_sun & spot_matters, a, b),
                                     ("no shadow", out_sun & out_spot, a + b, 0 * a)]:
        share = np.median(lost[mask] / np.maximum(a + b, 1e-6)[mask])
        err = np.abs(c[mask] - expect[mask]) / np.maximum(a + b, 1e-6)[mask]
        print(f"{name}: {mask.sum()} px, the light's share {share:.3f}, |colour - rest| / unshadowed: "
              f"median {np.median(err):.4f}, 99th {np.quantile(err, 0.99):.4f}")
        assert mask.sum() > 60
        assert np.quantile(err, 0.99) < 0.02


def test_point_light_casts_a_cube_shadow_in_every_direction(renderer):
    """Boxes around a point light: the floor behind each is dark, on the cube's four side faces and
    its bottom face; out of the shadows the floor is lit as without the shadow."""
    scene = matte_floor_scene([point()], POINT_BOXES)
    chain = renderer.chain(SETTINGS, scene)
    shadow = chain[chain.names.index("shadow_map")]
    assert shadow.outputs == ("shadow_cubes",)
    assert "shadow_cubes" in [p for c in chain if c.name == "lighting" for p in c.inputs]
    f = renderer.render(scene, settings=SETTINGS)
    unshadowed = renderer.render(matte_floor_scene([point(False)], POINT_BOXES), settings=SETTINGS).color[..., 1]
    c = f.color[..., 1]
    p = floor_points(f)
    g = f.gbuffer
    floor = g.coverage[0] & (g.object_id[0] == 0)
    to_light = POINT_POS - p
    lit_everywhere = floor.copy()
    faces = []
    for box in POINT_BOXES:
        shadowed = floor & crosses(p, to_light, box, 1.0, -0.05)
        lit_everywhere &= ~crosses(p, to_light, box, 1.0, 0.05)
        # The cube face the light sees these floor points in: the major axis of point - light.
        d = -to_light[shadowed]
        axis = np.abs(d).argmax(-1)
        face = "+-"[int(np.median(d[np.arange(len(d)), axis]) < 0)] + "XYZ"[int(np.median(axis))]
        dark = c[shadowed] < 0.03 * unshadowed[shadowed]
        print(f"box at {np.round((box[0] + box[1]) / 2, 2)}: {shadowed.sum()} px on face {face}, "
              f"{dark.mean():.4f} dark")
        assert shadowed.sum() > 15 and dark.mean() > 0.97
        faces.append(face)
    assert sorted(faces) == ["+X", "+Z", "-X", "-Y", "-Z"]
    ratio = c[lit_everywhere] / unshadowed[lit_everywhere]
    print(f"lit floor: {lit_everywhere.sum()} px, colour / unshadowed min {ratio.min():.4f}")
    assert lit_everywhere.sum() > 2000 and np.quantile(ratio, 0.001) > 0.98


@pytest.fixture(scope="module")
def three_lights(renderer):
    """A directional, a spot and a point light, each casting."""
    scene = matte_floor_scene([sun(), spot(), point()], [SUN_BOX, SPOT_BOX] + POINT_BOXES)
    return scene, renderer.render(scene, settings=SETTINGS)


def shadow_masks(f):
    boxes = [SUN_BOX, SPOT_BOX] + POINT_BOXES
    return masks(f, [("sun", SUN_DIR, boxes), ("spot", SPOT_POS, boxes), ("point", POINT_POS, boxes)])


def test_map_reference_matches_the_frame_after_another_frame(renderer, three_lights):
    """The GLSL reference with shadows="map" reads the same maps (rendered again when a later
    frame took the renderer's scratch textures): its image equals the frame's in every shadow."""
    scene, f = three_lights
    renderer.render(matte_floor_scene([sun()], [SUN_BOX]), settings=SETTINGS)  # takes the maps over
    ref = f.reference("converged", rays=1, shadows="map", tracer="glsl").color[..., 1]
    c = f.color[..., 1]
    m = shadow_masks(f)
    floor = f.gbuffer.coverage[0] & (f.gbuffer.object_id[0] == 0)
    shadowed = m[0][0] | m[1][0] | m[2][0]
    err = np.abs(ref - c)[floor] / np.maximum(c[floor], 1e-3)
    print(f"map reference vs frame: {shadowed.sum()} shadowed px; floor relative error median "
          f"{np.median(err):.2e}, 99th {np.quantile(err, 0.99):.2e}")
    assert shadowed.sum() > 300
    assert np.quantile(np.abs(ref - c)[shadowed], 0.99) < 1e-3 + 0.01 * np.median(c[floor])
    assert np.quantile(err, 0.99) < 0.01


@pytest.mark.parametrize("tracer", ["cpu", "glsl"])
def test_traced_reference_agrees_within_the_filtering(three_lights, tracer):
    """Traced shadows (a ray to each casting light) agree with the maps wherever a pixel is clear
    of a shadow's edge (the maps' PCF blurs the edges by a few texels)."""
    scene, f = three_lights
    ref = f.reference("converged", rays=1, shadows="traced", tracer=tracer).color[..., 1]
    c = f.color[..., 1]
    m = shadow_masks(f)
    clear = m[0][0] | m[0][1]
    for inside, outside in m:
        clear &= inside | outside
    shadowed = clear & (m[0][0] | m[1][0] | m[2][0])
    err = np.abs(ref - c)[clear] / np.maximum(ref[clear], 1e-3)
    print(f"{tracer} traced reference vs frame: {clear.sum()} px clear of edges ({shadowed.sum()} shadowed); "
          f"relative error median {np.median(err):.2e}, 99th {np.quantile(err, 0.99):.2e}")
    assert shadowed.sum() > 300 and clear.sum() > 2000
    assert np.quantile(err, 0.99) < 0.02


def test_more_cube_faces_than_the_device_holds_are_refused(renderer):
    """Each casting point light takes six layers of the cube-map array: more than the device's
    array layers is refused before anything is allocated, naming the texture and what to change."""
    limit = int(renderer.info["max_array_layers"])
    s = matte_floor_scene([point() for _ in range(limit // 6 + 1)], [])
    with pytest.raises(ValueError, match=r"'shadow_cubes' needs \d+ layers \(6 per point light that casts a shadow\)"
                                         r".*GL_MAX_ARRAY_TEXTURE_LAYERS.*cast_shadow=False"):
        renderer.render(s, settings=small(width=32, height=16, shadow_map_size=16))
    assert renderer.render(s, settings=small(width=32, height=16, shadow_map_size=0)).color.shape == (16, 32, 3)


def test_shadow_cubes_read_back_as_six_faces(renderer):
    """frame.read("shadow_cubes") gives each cube's six faces in GL's order (+X, -X, +Y, -Y, +Z,
    -Z): under a point light above a floor, the -Y face holds the floor everywhere (depth < 1) and
    the +Y face, facing the empty sky, nothing (the cleared depth 1)."""
    f = renderer.render(matte_floor_scene([point()], POINT_BOXES), settings=small(width=32, height=16, shadow_map_size=32))
    cubes = f.read("shadow_cubes")
    assert cubes.shape == (6, 32, 32, 4)
    depth = cubes[..., 0]
    assert np.all(depth[3] < 1.0) and np.all(depth[2] == 1.0)
    # The side faces see the floor below their horizon (and past the floor's edge, 10 degrees
    # below it, nothing): the same half in each, whichever end readback puts first.
    floor_first = [bool(np.all(depth[face][:10] < 1.0) and np.all(depth[face][-14:] == 1.0)) for face in (0, 1, 4, 5)]
    floor_last = [bool(np.all(depth[face][-10:] < 1.0) and np.all(depth[face][:14] == 1.0)) for face in (0, 1, 4, 5)]
    assert all(floor_first) or all(floor_last), (floor_first, floor_last)
