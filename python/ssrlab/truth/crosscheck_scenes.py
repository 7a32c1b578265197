"""The cross-check's scenes: ssrlab scenes that a path tracer lights as ssrlab does (no ambient,
a black environment; see :func:`ssrlab.truth.crosscheck.check_comparable`), each built to test
one part of the model against Mitsuba, and the objects a moved frame moves."""

from __future__ import annotations

import numpy as np


def crosscheck_scene(floor_roughness: float = 0.0, floor_color=(1.0, 1.0, 1.0), *, sun_irradiance: float = 3.0,
                     shadows: bool = True):
    """The cross-check's scene: a metallic floor (reflectivity 1, `floor_roughness`, F0 =
    `floor_color`) with a back wall, boxes and spheres of ssrlab's dielectric material on it,
    lit by a shadow-casting sun; no ambient, black environment. Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = f"crosscheck_floor_r{floor_roughness:g}"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=tuple(floor_color), metallic=1.0, roughness=floor_roughness, reflectivity=1.0))
    s.add_box((0, 1.5, -6.0), (10, 3, 0.2), name="wall", material=Material(
        base_color=(0.75, 0.72, 0.65), roughness=0.8, reflectivity=0.0))
    s.add_box((-1.6, 0.5, -2.5), (1.0, 1.0, 1.0), rotation_y=25.0, name="red_box", material=Material(
        base_color=(0.8, 0.15, 0.1), roughness=0.5, reflectivity=0.0))
    s.add_box((1.8, 0.75, -3.4), (0.8, 1.5, 0.8), rotation_y=-15.0, name="blue_box", material=Material(
        base_color=(0.15, 0.3, 0.8), roughness=0.6, reflectivity=0.0))
    s.add_sphere((0.3, 0.6, -1.6), 0.6, segments=64, name="green_sphere", material=Material(
        base_color=(0.2, 0.7, 0.25), roughness=0.4, reflectivity=0.0))
    s.add_sphere((-0.2, 0.35, -4.2), 0.35, segments=48, name="yellow_sphere", material=Material(
        base_color=(0.85, 0.75, 0.2), roughness=0.3, reflectivity=0.0))
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=sun_irradiance, cast_shadow=shadows))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.35, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def masked_crosscheck_scene(cells: int = 4, texels_per_cell: int = 4):
    """glTF alphaMode MASK: a mirror floor, a sun-lit matte wall and between them a red quad
    whose alpha mask is a `cells` x `cells` checkerboard (even cells opaque), casting a holed
    shadow on the wall. No surface sees another diffuse one that the sun lights (the quad's
    front faces away from the wall, the floor is a mirror), so the one bounce ``volpath`` adds
    for stepping through a hole brings no light that ssrlab leaves out. Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_masked"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    s.add_plane((0, 2.0, -5.0), (12, 4), normal=(0, 0, 1), name="wall", material=Material(
        base_color=(0.2, 0.6, 0.25), roughness=0.9, reflectivity=0.0))
    n = cells * texels_per_cell
    c = np.arange(n) // texels_per_cell
    img = np.zeros((n, n, 4), np.uint8)
    img[..., :3] = (200, 40, 30)
    img[..., 3] = np.where((c[:, None] + c[None, :]) % 2 == 0, 255, 0)
    tex = s.add_image(img, name="checker_mask")
    y0, y1, z = 0.4, 2.0, -2.5
    s.add_mesh([(-1.2, y0, z), (1.2, y0, z), (1.2, y1, z), (-1.2, y1, z)], [(0, 1, 2), (0, 2, 3)],
               uvs=[(0, 1), (1, 1), (1, 0), (0, 0)], name="masked_quad", material=Material(
                   base_color=(1.0, 1.0, 1.0), roughness=0.7, reflectivity=0.0, base_color_texture=tex,
                   double_sided=True, alpha_mode="MASK", alpha_cutoff=0.5))
    s.add_light(directional_light((0.3, -0.55, -0.8), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.5, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def emissive_crosscheck_scene(emission=(4.0, 2.0, 0.8)):
    """Emission: a mirror floor and an emissive box (black base colour, so what it shows is its
    emission plus the sun's highlight on its dielectric specular) lit by the sun. Mitsuba makes the
    box an area emitter; the floor, an ideal metallic mirror, receives from it only what it
    reflects, as in ssrlab (whose emission lights nothing). Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_emissive"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    lamp = Material(base_color=(0.0, 0.0, 0.0), roughness=0.6, reflectivity=0.0)
    lamp.emissive = tuple(float(e) for e in emission)
    s.add_box((0.2, 0.8, -3.0), (1.6, 1.6, 1.2), rotation_y=20.0, name="lamp", material=lamp)
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.35, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def emissive_texture_crosscheck_scene(factor=(4.0, 2.0, 1.0), cells: int = 4, texels_per_cell: int = 8):
    """glTF emissiveTexture: a mirror floor and a black quad facing the camera whose emission is
    `factor` x a `cells` x `cells` checkerboard (sRGB 255 and 64), lit by the sun. Mitsuba makes
    the quad an area emitter with that bitmap radiance; the floor, an ideal metallic mirror,
    receives from it only what it reflects, as in ssrlab. Object 0 is the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_emissive_texture"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    n = cells * texels_per_cell
    c = np.arange(n) // texels_per_cell
    img = np.zeros((n, n, 3), np.uint8)
    img[...] = np.where((c[:, None] + c[None, :]) % 2 == 0, 255, 64)[..., None]
    tex = s.add_image(img, name="checker_emission")
    lamp = Material(base_color=(0.0, 0.0, 0.0), roughness=0.6, reflectivity=0.0, emissive_texture=tex)
    lamp.emissive = tuple(float(e) for e in factor)
    y0, y1, z = 0.3, 1.9, -3.0
    s.add_mesh([(-1.2, y0, z), (1.2, y0, z), (1.2, y1, z), (-1.2, y1, z)], [(0, 1, 2), (0, 2, 3)],
               uvs=[(0, 1), (1, 1), (1, 0), (0, 0)], name="emissive_quad", material=lamp)
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.5, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


def point_shadow_crosscheck_scene(intensity: float = 6.0):
    """Point-light shadows: crosscheck_scene's mirror floor, wall, boxes and spheres lit by a
    shadow-casting point light between them and the wall instead of the sun (ssrlab's shadow
    cube; traced shadows in the reference), so that the floor reflects the objects' shadows on
    the wall and on one another, cast in several directions from the light. Object 0 is the floor;
    object 1 the wall."""
    from ..scene import point_light

    s = crosscheck_scene(0.0)
    s.name = "crosscheck_point_shadow"
    s.clear_lights()
    s.add_light(point_light((0.0, 1.2, -0.9), intensity=intensity, cast_shadow=True))
    return s


def vertex_color_crosscheck_scene():
    """glTF COLOR_0: a mirror floor and a matte quad facing the camera whose vertex colours run
    red to green across it and dark to bright up it, lit by the sun. Mitsuba's quad carries them
    as its "vertex_color" attribute, which SsrlabBSDF multiplies into the base colour. Object 0 is
    the floor."""
    from ..scene import Camera, Environment, Material, Scene, directional_light

    s = Scene()
    s.name = "crosscheck_vertex_colors"
    s.add_plane((0, 0, -2.0), (14, 14), name="floor", material=Material(
        base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0, reflectivity=1.0))
    y0, y1, z = 0.3, 1.9, -3.0
    colors = [(0.9, 0.1, 0.1), (0.1, 0.9, 0.1), (0.3, 0.9, 0.9), (0.9, 0.3, 0.9)]
    s.add_mesh([(-1.2, y0, z), (1.2, y0, z), (1.2, y1, z), (-1.2, y1, z)], [(0, 1, 2), (0, 2, 3)],
               colors=colors, name="coloured_quad", material=Material(
                   base_color=(1.0, 1.0, 1.0), roughness=0.7, reflectivity=0.0))
    s.add_light(directional_light((0.45, -0.75, -0.5), intensity=3.0, cast_shadow=True))
    s.ambient = (0.0, 0.0, 0.0)
    s.environment = Environment.constant((0.0, 0.0, 0.0))
    s.camera = Camera(position=(0.0, 1.3, 3.2), target=(0.0, 0.5, -2.5), fov_y=45.0, near=0.1, far=50.0)
    return s


FLOOR = 0  # crosscheck_scene's floor object

# The moved-frame case: between two frames of a sequence, objects of crosscheck_scene move (by name:
# a translation, a turn about +y and a lift), so that the second frame's converged reference is made
# from the scene's new transforms: the objects' GPU entries, their BVH trees and the shadow maps
# updated per object, not rebuilt (docs/guide/scenes.md). Mitsuba renders the moved scene afresh.
MOVES = {
    "green_sphere": ((0.6, 0.0, -0.4), 0.0),
    "red_box": ((0.3, 0.0, 0.5), 35.0),
    "yellow_sphere": ((-0.5, 0.25, 0.0), 0.0),
}


def move_objects(scene, moves=None) -> list[int]:
    """Moves crosscheck_scene's objects named in `moves` ({name: (translation, degrees about +y
    through the object's centre)}, MOVES by default) from where they are; returns their indices."""
    from .. import transforms as T

    names = [scene.object_name(i) for i in range(scene.object_count)]
    moved = []
    for name, (offset, degrees) in (moves or MOVES).items():
        if name not in names:
            raise KeyError(f"move_objects: the scene has no object named {name!r} (it has {', '.join(names)})")
        i = names.index(name)
        m = np.asarray(scene.object_transform(i), np.float64)
        centre = m[:3, 3].copy()
        turn = T.translate(tuple(centre)) @ T.rotate((0.0, 1.0, 0.0), degrees) @ T.translate(tuple(-centre))
        scene.set_object_transform(i, T.translate(offset) @ turn @ m)
        moved.append(i)
    return moved
