"""Procedural scenes named after the thesis's experiments (seed 000, section 3.1.1).

Each builder returns a Scene with a default camera, lights and an environment:

spheres_and_boxes  random spheres and boxes above a reflective floor (seeded); with
                   ``with_suzanne=True`` Blender's Suzanne stands in for the thesis's elephant
                   (Fig. 3.2), occluding part of the scene.
box_stack          floating boxes in rows one behind another above a reflective floor, so
                   that reflections need surfaces hidden behind several others: many
                   G-buffer layers matter (like Fig. 3.5).
hall               a floor, walls and two rows of columns: our stand-in for the Sibenik
                   cathedral of Figs. 2.7-2.9.
mirror_test        a perfect mirror floor and a checkerboard wall of flat tiles, for
                   analytic checks (the wall's mirror image is known in closed form).
gallery            strips of mixed roughness before a checkered wall: adaptive ray counts
                   (not in SCENES: its options are tuples, which sweep files do not hold).
"""

from __future__ import annotations

import colorsys

import numpy as np

from . import models
from .scene import Camera, Environment, Material, Scene, directional_light


def _sky() -> Environment:
    return Environment.sky(zenith=(0.22, 0.42, 0.85), horizon=(0.75, 0.8, 0.88), ground=(0.25, 0.23, 0.2))


def _colour(rng: np.random.Generator) -> tuple[float, float, float]:
    h, s, v = rng.uniform(0, 1), rng.uniform(0.45, 0.85), rng.uniform(0.55, 0.9)
    return colorsys.hsv_to_rgb(h, s, v)


def spheres_and_boxes(seed: int = 0, count: int = 18, *, with_suzanne: bool = False,
                      floor_roughness: float = 0.1, floor_reflectivity: float = 0.7) -> Scene:
    """Random spheres and boxes, some resting on and some floating above a reflective floor."""
    rng = np.random.default_rng(seed)
    s = Scene()
    s.name = "spheres_and_boxes" + ("_suzanne" if with_suzanne else "")
    s.add_plane((0, 0, -3), (26, 26), uv_tiles=8, name="floor", material=Material(
        base_color=(0.5, 0.5, 0.53), roughness=floor_roughness, metallic=0.0, reflectivity=floor_reflectivity))
    placed: list[tuple[float, float, float]] = []  # (x, z, footprint radius)
    if with_suzanne:
        placed.append((0.0, -2.0, 1.5))
    attempts = 0
    while len(placed) - int(with_suzanne) < count and attempts < 10000:
        attempts += 1
        x, z = rng.uniform(-6.0, 6.0), rng.uniform(-10.0, 1.5)
        is_sphere = rng.uniform() < 0.5
        size = rng.uniform(0.35, 0.85) if is_sphere else rng.uniform(0.5, 1.4)
        r = size if is_sphere else size * 0.75
        if any((x - px) ** 2 + (z - pz) ** 2 < (r + pr + 0.15) ** 2 for px, pz, pr in placed):
            continue
        placed.append((x, z, r))
        lift = 0.0 if rng.uniform() < 0.5 else rng.uniform(0.3, 1.2)  # half of them float
        mat = Material(base_color=_colour(rng), roughness=float(rng.uniform(0.2, 0.7)),
                       metallic=float(rng.uniform() < 0.2))
        if is_sphere:
            s.add_sphere((x, size + lift, z), size, material=mat, name=f"sphere{len(placed)}")
        else:
            h = rng.uniform(0.5, 1.4)
            s.add_box((x, h / 2 + lift, z), (size, h, size), rotation_y=float(rng.uniform(0, 90)), material=mat,
                      name=f"box{len(placed)}")
    if with_suzanne:
        from . import transforms as T

        s.add_gltf(models.find("Suzanne"), T.translate((0, 1.3, -2.0)) @ T.scale(1.3))
    s.add_light(directional_light((-0.45, -1.0, -0.35), intensity=3.0))
    s.ambient = (0.08, 0.08, 0.09)
    s.environment = _sky()
    s.camera = Camera(position=(0.0, 3.0, 7.5), target=(0.0, 0.7, -2.5), fov_y=55.0, near=0.1, far=60.0)
    return s


def box_stack(seed: int = 0, rows: int = 6, columns: int = 5, *, floor_roughness: float = 0.05) -> Scene:
    """Rows of floating boxes one behind another, seen from low above a reflective floor."""
    rng = np.random.default_rng(seed)
    s = Scene()
    s.name = "box_stack"
    s.add_plane((0, 0, -4), (30, 30), name="floor", material=Material(
        base_color=(0.45, 0.45, 0.5), roughness=floor_roughness, reflectivity=0.8))
    for r in range(rows):
        for c in range(columns):
            x = (c - (columns - 1) / 2) * 1.5 + (0.75 if r % 2 else 0.0)
            z = -1.0 - 1.6 * r
            size = rng.uniform(0.7, 1.0)
            y = size / 2 + rng.uniform(0.35, 0.9)
            s.add_box((x, y, z), (size, size, size), rotation_y=float(rng.uniform(0, 45)),
                      material=Material(base_color=_colour(rng), roughness=0.5), name=f"box{r}_{c}")
    s.add_light(directional_light((0.35, -1.0, -0.5), intensity=3.0))
    s.ambient = (0.1, 0.1, 0.11)
    s.environment = _sky()
    s.camera = Camera(position=(0.0, 1.4, 4.5), target=(0.0, 0.6, -6.0), fov_y=55.0, near=0.1, far=60.0)
    return s


def hall(*, columns_per_side: int = 7, floor_roughness: float = 0.15) -> Scene:
    """A nave: polished floor, side and end walls, two rows of columns with beams, pews."""
    s = Scene()
    s.name = "hall"
    length, width, height = 32.0, 10.0, 8.0
    z0 = -length / 2 + 2.0
    stone = Material(base_color=(0.72, 0.66, 0.56), roughness=0.7)
    s.add_plane((0, 0, z0), (width, length), uv_tiles=16, name="floor", material=Material(
        base_color=(0.42, 0.38, 0.34), roughness=floor_roughness, reflectivity=0.6))
    s.add_box((-width / 2 - 0.25, height / 2, z0), (0.5, height, length), material=stone, name="wall_left")
    s.add_box((width / 2 + 0.25, height / 2, z0), (0.5, height, length), material=stone, name="wall_right")
    s.add_box((0, height / 2, z0 - length / 2 - 0.25), (width + 1.0, height, 0.5),
              material=Material(base_color=(0.55, 0.5, 0.62), roughness=0.6), name="wall_end")
    column = Material(base_color=(0.82, 0.78, 0.7), roughness=0.5)
    spacing = (length - 6.0) / columns_per_side
    for side in (-1, 1):
        for i in range(columns_per_side):
            z = -1.0 - i * spacing
            s.add_box((side * 2.8, 3.0, z), (0.7, 6.0, 0.7), material=column, name=f"column{side:+d}_{i}")
            s.add_box((side * 2.8, 6.1, z), (1.1, 0.2, 1.1), material=column, name=f"capital{side:+d}_{i}")
        s.add_box((side * 2.8, 6.5, -1.0 - (columns_per_side - 1) * spacing / 2),
                  (0.8, 0.6, (columns_per_side - 1) * spacing + 1.1), material=column, name=f"beam{side:+d}")
    wood = Material(base_color=(0.35, 0.2, 0.1), roughness=0.45)
    for i in range(5):
        for side in (-1, 1):
            s.add_box((side * 1.3, 0.45, -4.0 - 2.2 * i), (1.8, 0.9, 0.5), material=wood, name=f"pew{side:+d}_{i}")
    s.add_light(directional_light((0.5, -1.0, -0.6), intensity=3.5))
    s.ambient = (0.12, 0.11, 0.1)
    s.environment = _sky()
    s.camera = Camera(position=(0.0, 1.8, 3.0), target=(0.0, 2.0, -20.0), fov_y=60.0, near=0.1, far=80.0)
    return s


# Geometry of mirror_test, for analytic checks: the mirror is the plane y = 0, the wall the
# plane z = MIRROR_WALL_Z facing +z, its tiles MIRROR_TILE wide from x = -4, y = 0.
MIRROR_WALL_Z = -8.0
MIRROR_TILE = 1.0
MIRROR_TILES = 8
MIRROR_COLORS = ((0.9, 0.9, 0.9), (0.1, 0.25, 0.6))


def mirror_test() -> Scene:
    """A perfect mirror floor (y = 0) and a checkerboard wall of flat tiles (z = -8)."""
    return _mirror_scene(cast_shadow=False)


def _mirror_scene(cast_shadow: bool) -> Scene:
    s = Scene()
    s.name = "mirror_test"
    s.add_plane((0, 0, -2), (16, 16), name="mirror", material=Material(
        base_color=(1, 1, 1), roughness=0.0, metallic=1.0, reflectivity=1.0))
    # One mesh per tile colour, every vertex on the exact tile grid: adjacent tiles share
    # bit-identical edges, so the wall rasterises without cracks.
    half = MIRROR_TILES * MIRROR_TILE / 2
    for colour_index, colour in enumerate(MIRROR_COLORS):
        positions, indices = [], []
        for i in range(MIRROR_TILES):
            for j in range(MIRROR_TILES):
                if (i + j) % 2 != colour_index:
                    continue
                x0, y0 = -half + i * MIRROR_TILE, j * MIRROR_TILE
                x1, y1 = x0 + MIRROR_TILE, y0 + MIRROR_TILE
                base = len(positions)
                positions += [(x0, y0, MIRROR_WALL_Z), (x1, y0, MIRROR_WALL_Z), (x1, y1, MIRROR_WALL_Z),
                              (x0, y1, MIRROR_WALL_Z)]
                indices += [(base, base + 1, base + 2), (base, base + 2, base + 3)]  # CCW seen from +z
        s.add_mesh(np.array(positions, dtype=np.float32), np.array(indices), name=f"wall{colour_index}",
                   normals=np.tile(np.float32([0, 0, 1]), (len(positions), 1)),
                   material=Material(base_color=colour, roughness=0.9))
    s.add_light(directional_light((0.2, -0.4, -1.0), intensity=2.5, cast_shadow=cast_shadow))
    s.ambient = (0.05, 0.05, 0.05)
    s.environment = Environment.constant((0.02, 0.02, 0.03))
    s.camera = Camera(position=(0.0, 2.0, 5.0), target=(0.0, 1.0, -8.0), fov_y=50.0, near=0.1, far=50.0)
    return s


def stand_in() -> Scene:
    """The scene Renderer.chain and Renderer.prepare use without one: mirror_test's mirror floor
    and checkerboard wall, a box on the floor, and its sun casting the box's shadow, so that a
    render of it runs every pass the settings choose, the shadow map's included."""
    s = _mirror_scene(cast_shadow=True)
    s.name = "stand_in"
    s.add_box((1.5, 0.5, -4.0), (1.0, 1.0, 1.0), rotation_y=30.0, name="box",
              material=Material(base_color=(0.8, 0.3, 0.2), roughness=0.5))
    return s


# The floor strips' roughness of gallery(): every step from a mirror to 0.6.
GALLERY_ROUGHNESS = (0.0, 0.1, 0.2, 0.4, 0.6)


def gallery(roughness=GALLERY_ROUGHNESS, strips: int = 20, wall: str = "checker") -> Scene:
    """A mixed-roughness floor in front of a checkered wall that stands in view: the scene of
    adaptive ray counts (benchmarks/studies/skip.py). The floor's strips (1 unit wide, running away from the camera) cycle through
    `roughness`; the wall (matte tiles, bright and dark, so that a glossy lobe averages contrast
    and the ray count shows in the noise) is narrower than the view and lower than its top edge,
    and nothing else is in the scene, so what a floor ray does not hit on the wall's visible face
    is the environment, which a screen-space miss returns too: screen space's bias stays small
    and the error against the converged reference is mostly the rays' noise. wall="smooth": the
    same wall with its colour varying slowly across it instead (low-frequency content: a narrow
    lobe sees nearly one colour, a wide one a range of them)."""
    if wall not in ("checker", "smooth"):
        raise ValueError(f"gallery: wall must be 'checker' or 'smooth', got {wall!r}")
    s = Scene()
    s.name = "adaptive_gallery"
    half = strips / 2
    for i in range(strips):
        x0 = -half + i
        p = np.float32([(x0, 0, 5), (x0 + 1, 0, 5), (x0 + 1, 0, -8), (x0, 0, -8)])
        s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name=f"strip{i}",
                   normals=np.tile(np.float32([0, 1, 0]), (4, 1)),
                   material=Material(base_color=(0.9, 0.9, 0.9), roughness=roughness[i % len(roughness)],
                                     metallic=1.0, reflectivity=1.0))
    bright = [Material(base_color=c, roughness=0.9, reflectivity=0.0)
              for c in ((0.95, 0.85, 0.6), (0.6, 0.85, 0.95), (0.95, 0.6, 0.6))]
    dark = Material(base_color=(0.04, 0.04, 0.05), roughness=0.9, reflectivity=0.0)
    tile = 0.75
    for j in range(6):
        for i in range(16):
            x0, y0 = -6 + i * tile, j * tile
            p = np.float32([(x0, y0, -8), (x0 + tile, y0, -8), (x0 + tile, y0 + tile, -8), (x0, y0 + tile, -8)])
            if wall == "checker":
                m = bright[(i // 2 + j) % 3] if (i + j) % 2 == 0 else dark
            else:  # a slow ramp over the wall: neighbouring tiles differ by a few percent
                u, v = i / 15, j / 5
                m = Material(base_color=(0.2 + 0.7 * u, 0.3 + 0.4 * v, 0.9 - 0.6 * u), roughness=0.9, reflectivity=0.0)
            s.add_mesh(p, np.array([(0, 1, 2), (0, 2, 3)]), name=f"tile{j}_{i}",
                       normals=np.tile(np.float32([0, 0, 1]), (4, 1)), material=m)
    s.add_light(directional_light((0.2, -0.6, -1.0), intensity=3.0, cast_shadow=False))
    s.environment = Environment.constant((0.2, 0.25, 0.3))
    s.camera = Camera(position=(0.0, 1.6, 5.0), target=(0.0, 1.2, -8.0), fov_y=60.0, near=0.1, far=60.0)
    return s


SCENES = {
    "spheres_and_boxes": spheres_and_boxes,
    "box_stack": box_stack,
    "hall": hall,
    "mirror_test": mirror_test,
}


STAGES = ("mirror", "glossy")
GLOSSY_STAGE_ROUGHNESS = 0.25


def load(name_or_path: str, *, stage: str | None = None, stage_roughness: float | None = None, **kwargs) -> Scene:
    """A procedural scene by name (keyword arguments go to its builder), or a glTF file; a file
    without a camera, lights or an environment gets a camera that frames it, a sun and a sky.

    `stage` ("mirror" or "glossy", glTF files only) puts a reflective metal floor under the
    model's bounds, so that any model has something to be reflected in; `stage_roughness` is the
    glossy floor's perceptual roughness (default 0.25; a mirror's is 0)."""
    if stage is not None and stage not in STAGES:
        raise ValueError(f"stage must be one of {', '.join(STAGES)} or None, got {stage!r}")
    if stage_roughness is not None:
        if stage != "glossy":
            raise ValueError("stage_roughness applies to stage='glossy' only (a mirror's roughness is 0)")
        if not 0.0 <= float(stage_roughness) <= 1.0:
            raise ValueError(f"stage_roughness must be in [0, 1], got {stage_roughness}")
    if name_or_path in SCENES:
        if stage is not None:
            raise ValueError("stage applies to glTF files only (the procedural scenes have their floors)")
        return SCENES[name_or_path](**kwargs)
    from pathlib import Path

    if Path(name_or_path).suffix.lower() in (".gltf", ".glb"):
        if kwargs:
            raise ValueError(f"scene options {sorted(kwargs)} apply to procedural scenes only")
        scene = Scene.load(name_or_path)
        if stage is not None:
            model_bounds = tuple(np.asarray(b, dtype=float) for b in scene.bounds)
            add_stage(scene, model_bounds, 0.0 if stage == "mirror" else
                      float(GLOSSY_STAGE_ROUGHNESS if stage_roughness is None else stage_roughness))
        if scene.camera is None:
            scene.camera = frame_camera(scene, bounds=model_bounds if stage is not None else None,
                                        stage=stage is not None)
        if not scene.lights:
            scene.add_light(directional_light((-0.4, -1.0, -0.5), intensity=3.0))
        env = scene.environment
        if env.type == "constant" and not any(env.color):
            # glTF has no environment: a file that sets none (and ssrlab's extras set none)
            # gets the procedural scenes' sky, so what its surfaces reflect is not black.
            scene.environment = _sky()
        return scene
    raise ValueError(f"unknown scene {name_or_path!r}: expected one of {', '.join(SCENES)} or a .gltf/.glb file")


def add_stage(scene: Scene, bounds, roughness: float) -> int:
    """A square metal floor of perceptual `roughness` just under `bounds` (the model's (lo, hi)),
    reaching four half-diagonals from its centre each way, reflectivity 1; returns its object index."""
    lo, hi = (np.asarray(b, dtype=float) for b in bounds)
    center = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
    # A hair below the model: a flat base lying on the floor would otherwise fight it for depth.
    y = lo[1] - 1e-3 * radius
    return scene.add_plane((float(center[0]), float(y), float(center[2])), (8 * radius, 8 * radius),
                           name="stage", material=Material(base_color=(0.95, 0.95, 0.95), metallic=1.0,
                                                           roughness=roughness, reflectivity=1.0))


def frame_camera(scene: Scene, fov_y: float = 45.0, *, bounds=None, stage: bool = False) -> Camera:
    """A camera that sees the whole scene (or `bounds`, (lo, hi)) from the front and a little
    above; with `stage`, its near and far planes also take in add_stage's floor."""
    lo, hi = (np.asarray(b) for b in (scene.bounds if bounds is None else bounds))
    if scene.object_count == 0:
        lo, hi = np.zeros(3), np.ones(3)
    center = (lo + hi) / 2
    radius = max(float(np.linalg.norm(hi - lo)) / 2, 1e-3)
    distance = radius / np.sin(np.radians(fov_y) / 2) * 1.05
    eye = center + distance * np.array([0.35, 0.45, 0.82]) / np.linalg.norm([0.35, 0.45, 0.82])
    if stage:  # the floor reaches 4 radii from the centre, toward the camera and away
        return Camera(position=tuple(eye), target=tuple(center), fov_y=fov_y, near=distance * 0.01,
                      far=distance + radius * 6)
    return Camera(position=tuple(eye), target=tuple(center), fov_y=fov_y,
                  near=max(distance - radius * 1.5, distance * 0.01), far=distance + radius * 2)
