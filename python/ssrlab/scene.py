"""Scenes: glTF 2.0 files, numpy meshes and primitives, with materials, lights, an
ambient term, an environment and an optional default camera."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np

from . import _core
from . import transforms as T
from ._core import Camera, Environment, Light, Material


def _matrix(transform) -> np.ndarray:
    m = T.identity() if transform is None else np.asarray(transform, dtype=np.float32)
    if m.shape != (4, 4):
        raise ValueError(f"transform must be a 4x4 matrix, got shape {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError("transform contains NaN or Inf")
    return m


class SceneWarning(UserWarning):
    """Something in a scene file was skipped (points, lines, skins, morph targets, spot cones,
    orthographic cameras) or the file gave nothing to draw; the message names the file and object."""


class Scene(_core.Scene):
    """A scene. Objects are meshes with a transform and a material; ``add_*`` return the new
    object's index (``add_gltf`` a list of them)."""

    @classmethod
    def load(cls, path: str | Path, *, allow_external_files: bool = False) -> "Scene":
        """Loads a glTF 2.0 file (.gltf or .glb) with its node hierarchy, materials, textures,
        KHR_lights_punctual lights and first perspective camera.

        Files the model refers to (buffers, images, an environment map) must lie inside the
        model's folder unless `allow_external_files` is true; devices, FIFOs and folders are
        never read. A malformed file raises SceneError naming the file and the object; what is
        skipped is reported as a SceneWarning."""
        scene = cls()
        scene.add_gltf(path, allow_external_files=allow_external_files)
        scene.name = Path(path).stem
        return scene

    def add_gltf(self, path: str | Path, transform=None, *, allow_external_files: bool = False) -> list[int]:
        """Adds the default scene of a glTF file, every node's transform premultiplied by `transform`
        (see `load` for `allow_external_files`, errors and warnings)."""
        # The path as the OS spells it (bytes): a name that is not valid UTF-8 still opens.
        ids, messages = self._add_gltf(os.fsencode(os.fspath(path)), _matrix(transform), bool(allow_external_files))
        for message in messages:
            warnings.warn(message, SceneWarning, stacklevel=2)
        return list(ids)

    def add_mesh(self, positions, indices=None, *, normals=None, uvs=None, tangents=None,
                 material: Material | None = None, transform=None, name: str = "mesh") -> int:
        """Adds a triangle mesh from arrays: positions (n, 3); indices (m, 3) or (3m,) — or None
        for a non-indexed list; optional normals (n, 3, computed when absent), uvs (n, 2),
        tangents (n, 4)."""
        return self._add_mesh(positions, indices, normals, uvs, tangents, material or Material(),
                              _matrix(transform), name)

    def add_plane(self, center=(0.0, 0.0, 0.0), size=(1.0, 1.0), *, normal=(0.0, 1.0, 0.0),
                  material: Material | None = None, uv_tiles: float = 1.0, name: str = "plane",
                  transform=None) -> int:
        """A rectangle of `size` (width along x, depth along z before rotation) facing `normal`."""
        sx, sz = (size, size) if np.isscalar(size) else size
        m = T.translate(center) @ T.align_y(normal) @ T.scale((sx, 1.0, sz))
        if transform is not None:
            m = _matrix(transform) @ m
        return self._add_primitive("plane", material or Material(), m, name, uv_tiles=uv_tiles)

    def add_box(self, center=(0.0, 0.0, 0.0), size=(1.0, 1.0, 1.0), *, rotation_y: float = 0.0,
                material: Material | None = None, name: str = "box", transform=None) -> int:
        """An axis-aligned box of `size`, rotated by `rotation_y` degrees about +y."""
        m = T.translate(center) @ T.rotate((0, 1, 0), rotation_y) @ T.scale(size)
        if transform is not None:
            m = _matrix(transform) @ m
        return self._add_primitive("box", material or Material(), m, name)

    def add_sphere(self, center=(0.0, 0.0, 0.0), radius: float = 1.0, *, material: Material | None = None,
                   segments: int = 48, name: str = "sphere") -> int:
        if not radius > 0:
            raise ValueError(f"add_sphere: radius must be > 0, got {radius}")
        m = T.translate(center) @ T.scale(radius)
        return self._add_primitive("sphere", material or Material(), m, name, segments=segments)

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Writes the scene as glTF 2.0 (.gltf + .bin, or .glb). Refuses to replace an existing
        file unless overwrite=True."""
        path = Path(path)
        targets = [path] + ([path.with_suffix(".bin")] if path.suffix == ".gltf" else [])
        existing = [p for p in targets if p.exists()]
        if existing and not overwrite:
            raise FileExistsError(f"{existing[0]} exists; pass overwrite=True to replace it")
        self._save(str(path))
        return path

    def copy(self) -> "Scene":
        out = Scene()
        out._assign(self)
        return out

    def __repr__(self) -> str:
        return (f"Scene({self.name!r}: {self.object_count} objects, {self.triangle_count} triangles, "
                f"{len(self.lights)} lights)")


def directional_light(direction, color=(1.0, 1.0, 1.0), intensity: float = 3.0, cast_shadow: bool = True,
                      name: str = "sun") -> Light:
    """A directional light; `direction` is where the light travels, `intensity` the
    irradiance (W/m^2) on a surface facing it."""
    return Light.directional(direction, color, intensity, cast_shadow, name)


def point_light(position, color=(1.0, 1.0, 1.0), intensity: float = 10.0, name: str = "point") -> Light:
    """A point light of radiant intensity `intensity` (W/sr)."""
    return Light.point(position, color, intensity, name)


__all__ = ["Scene", "SceneWarning", "Material", "Light", "Environment", "Camera", "directional_light", "point_light"]
