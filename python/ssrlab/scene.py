"""Scenes: glTF 2.0 files, numpy meshes and primitives, with materials, lights, an
ambient term, an environment and an optional default camera."""

from __future__ import annotations

import os
import shutil
import tempfile
import warnings
from pathlib import Path

import numpy as np

from . import _core
from . import transforms as T
from ._core import Camera, Environment, Light, Material
from .animation import AnimationState, Motion, _seconds, pose, resolve_animations


def _matrix(transform) -> np.ndarray:
    m = T.identity() if transform is None else np.asarray(transform, dtype=np.float32)
    if m.shape != (4, 4):
        raise ValueError(f"transform must be a 4x4 matrix, got shape {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError("transform contains NaN or Inf")
    return m


_REAL_KINDS = "iuf"  # numpy dtype kinds that are real numbers; bool, complex, text, objects and dates are not


def _as_array(value, what: str) -> np.ndarray:
    try:
        a = np.asarray(value)
    except (ValueError, TypeError) as e:  # ragged nested lists and the like
        raise ValueError(f"{what} is not a rectangular array: {e}") from None
    if a.dtype.kind not in _REAL_KINDS:
        kind = {"b": "bool", "c": "complex", "U": "string", "S": "bytes", "O": "object", "M": "datetime",
                "m": "timedelta", "V": "structured"}.get(a.dtype.kind, str(a.dtype))
        raise TypeError(f"{what} must hold real numbers (integer or float), got a {kind} array (dtype {a.dtype})")
    return a


def _vertex_rows(value, what: str, columns: int, vertices: int | None = None) -> np.ndarray:
    """A float32 (n, columns) array of finite values, or an error naming `what`."""
    a = _as_array(value, what)
    if a.ndim != 2 or a.shape[1] != columns:
        raise ValueError(f"{what} must be an array of shape (n, {columns}), got shape {a.shape}")
    if vertices is not None and a.shape[0] != vertices:
        raise ValueError(f"{what} has {a.shape[0]} rows, expected {vertices} (one per vertex)")
    with np.errstate(over="ignore", invalid="ignore"):
        f = np.ascontiguousarray(a, dtype=np.float32)  # values beyond float32's range become inf: caught next
    bad = ~np.isfinite(f)
    if bad.any():
        row, col = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"{what} must be finite (no NaN or Inf, within float32's range): row {row}, component {col} is "
                         f"{a[row, col].item()!r} ({int(bad.any(axis=1).sum())} rows affected)")
    return f


def _vertex_colors(value, vertices: int) -> np.ndarray:
    """Vertex colours as a float32 (n, 4) array in [0, 1] (RGB rows get alpha 1), or an error naming `colors`."""
    a = _as_array(value, "colors")
    if a.ndim != 2 or a.shape[1] not in (3, 4):
        raise ValueError(f"colors must be an array of shape (n, 3) or (n, 4), got shape {a.shape}")
    columns = a.shape[1]
    c = _vertex_rows(a, "colors", columns, vertices)
    bad = (c < 0) | (c > 1)
    if bad.any():
        row, col = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(f"colors must be in [0, 1] (linear RGB(A), glTF COLOR_0): row {row}, component {col} is "
                         f"{c[row, col].item()!r}")
    if columns == 3:
        c = np.ascontiguousarray(np.concatenate([c, np.ones((c.shape[0], 1), np.float32)], axis=1))
    return c


def _index_array(value, vertices: int) -> np.ndarray:
    """A uint32 index array of shape (m, 3) or (3m,), every value an existing vertex."""
    a = _as_array(value, "indices")
    if a.size == 0:
        raise ValueError("indices is an empty array; pass indices=None for a non-indexed triangle list")
    if not (a.ndim == 1 or (a.ndim == 2 and a.shape[1] == 3)):
        raise ValueError(f"indices must have shape (m, 3) or (3m,), got shape {a.shape}")
    if a.ndim == 1 and a.size % 3:
        raise ValueError(f"indices has {a.size} values, not a multiple of 3 (one triangle per 3)")
    flat = a.reshape(-1)

    def where(i: int) -> str:
        return f"at position {i} (triangle {i // 3}, corner {i % 3})"

    if a.dtype.kind == "f":
        bad = ~np.isfinite(flat) | (flat != np.floor(flat))
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(f"indices must be whole numbers: {flat[i].item()!r} {where(i)}")
    neg = flat < 0
    if neg.any():
        i = int(np.argmax(neg))
        raise ValueError(f"indices must be >= 0: {flat[i].item()!r} {where(i)}")
    big = flat >= vertices
    if big.any():
        i = int(np.argmax(big))
        raise ValueError(f"index {flat[i].item()!r} {where(i)} is out of range ({vertices} vertices)")
    return np.ascontiguousarray(flat, dtype=np.uint32).reshape(a.shape)


class SceneWarning(UserWarning):
    """Something in a scene file was skipped (points, lines, skins, morph targets and their animated
    weights, orthographic cameras) or the file gave nothing to draw; the message names the file and object."""


class Scene(_core.Scene):
    """A scene. Objects are meshes with a transform and a material; ``add_*`` return the new
    object's index (``add_gltf`` a list of them)."""

    @classmethod
    def load(cls, path: str | Path, *, allow_external_files: bool = False) -> "Scene":
        """Loads a glTF 2.0 file (.gltf or .glb) with its node hierarchy, materials, textures,
        KHR_lights_punctual lights, first perspective camera and animations (Scene.animations;
        Scene.play plays them, Scene.set_time poses them; the file loads in its rest pose).

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

    def add_light(self, light) -> int:
        """Adds a copy of a light; returns its index. Every light with cast_shadow=True casts a
        shadow (a point light's is a cube map)."""
        return super().add_light(light)

    def add_mesh(self, positions, indices=None, *, normals=None, uvs=None, tangents=None,
                 material: Material | None = None, transform=None, name: str = "mesh",
                 colors=None, uvs1=None) -> int:
        """Adds a triangle mesh from arrays: positions (n, 3); indices (m, 3) or (3m,) — or None
        for a non-indexed list; optional normals (n, 3, computed when absent), uvs (n, 2),
        tangents (n, 4), colors (n, 3) or (n, 4), linear RGB(A) in [0, 1] (glTF COLOR_0: they
        multiply the material's base colour and alpha), uvs1 (n, 2: glTF TEXCOORD_1, what a
        texture whose texCoord is 1 samples; such a texture samples uvs without it).

        Every array must hold real numbers (TypeError for bool, complex, text, object or date
        arrays) and be finite (ValueError naming the array and the first bad row); indices must
        be whole numbers of existing vertices, and an empty index array is an error (None means
        non-indexed). Normals may be zero (they are replaced by +y) but not NaN.
        """
        p = _vertex_rows(positions, "positions", 3)
        n = p.shape[0]
        if n == 0:
            raise ValueError("positions is empty: a mesh needs vertices")
        idx = None if indices is None else _index_array(indices, n)
        nrm = None if normals is None else _vertex_rows(normals, "normals", 3, n)
        uv = None if uvs is None else _vertex_rows(uvs, "uvs", 2, n)
        tan = None if tangents is None else _vertex_rows(tangents, "tangents", 4, n)
        col = None if colors is None else _vertex_colors(colors, n)
        uv1 = None if uvs1 is None else _vertex_rows(uvs1, "uvs1", 2, n)
        return self._add_mesh(p, idx, nrm, uv, tan, material or Material(), _matrix(transform), name,
                              colors=col, uvs1=uv1)

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

    @property
    def probes(self) -> list:
        """Reflection-probe positions (world space) for Settings.fallback 'probes'
        (seed 004's local cube maps), as (x, y, z) tuples; empty (the default): placed by
        Settings.probe_grid. Each probe must lie strictly inside the scene bounds (its
        box-projection proxy), checked at render."""
        return list(_core.Scene.probes.fget(self))

    @probes.setter
    def probes(self, value) -> None:
        if value is None or (hasattr(value, "__len__") and len(value) == 0):
            _core.Scene.probes.fset(self, [])
            return
        rows = _vertex_rows(value, "Scene.probes", 3)
        if len(rows) > 64:
            raise ValueError(f"Scene.probes: at most 64 probes, got {len(rows)}")
        _core.Scene.probes.fset(self, [tuple(float(c) for c in r) for r in rows])

    # -- things that move (ssrlab.animation) ---------------------------------------------------
    def _animation_state(self) -> AnimationState:
        state = self.__dict__.get("_animation")
        if state is None:
            state = self.__dict__["_animation"] = AnimationState()
        return state

    @property
    def time(self) -> float:
        """The time (seconds) the scene's moving things were last posed at by set_time (0 at first)."""
        return self._animation_state().time

    def set_time(self, t: float) -> None:
        """Poses everything that moves at `t` seconds: the glTF animations being played (play)
        and the motions given with animate, in that order (a motion given for an object that an
        animation also moves wins). Objects move through set_object_transform, lights through
        set_light, as if set by hand. See ssrlab.animation for sampling and time outside clips."""
        pose(self, self._animation_state(), _seconds(t, "Scene.set_time: t"))

    def play(self, *animations: int | str, loop: bool = False) -> None:
        """Plays glTF animations (Scene.animations), each given by name or index; with none, all
        of the scene's. Replaces what was played before, and poses the scene at its current time
        (Scene.time). Channels hold their first and last values outside their keyframes unless
        `loop` repeats each clip over its own duration (ssrlab.animation). An animated parent
        moves its children; several animations on one node apply in the order given."""
        state = self._animation_state()
        before = state.playing
        state.playing = [(i, bool(loop)) for i in resolve_animations(self, animations)]
        try:
            pose(self, state, state.time)
        except Exception:
            state.playing = before  # a pose that fails leaves the scene playing what it played
            raise

    def stop(self) -> None:
        """Plays no glTF animation any more; objects and lights stay where they are."""
        self._animation_state().playing = []

    def animate(self, object: int | None = None, motion=None, *, light: int | None = None,
                loop: bool = False) -> None:
        """Moves an object or a light over time: ``animate(object, motion)`` or
        ``animate(light=index, motion=...)``.

        motion: ssrlab.Keyframes, or a function of time t (seconds) returning an object's 4x4
        transform (object to world), or for a light an ssrlab.Light or a dict of the fields it
        changes (position, direction, color, intensity, inner_cone, outer_cone, range,
        cast_shadow); None removes the target's motion. `loop` repeats Keyframes over their
        duration. The scene is posed at its current time (Scene.time) at once."""
        if (object is None) == (light is None):
            raise ValueError("Scene.animate: give an object index or light=index (one of them)")
        kind, index = ("object", object) if light is None else ("light", light)
        count = self.object_count if kind == "object" else len(self.lights)
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
            raise TypeError(f"Scene.animate: the {kind} is an index, got {type(index).__name__}")
        if not 0 <= int(index) < count:
            raise IndexError(f"Scene.animate: {kind} index {int(index)} is out of range (the scene has {count})")
        state = self._animation_state()
        key = (kind, int(index))
        if motion is None:
            state.motions.pop(key, None)
            return
        before = state.motions.get(key)
        state.motions[key] = Motion(kind, int(index), motion, loop)
        try:
            pose(self, state, state.time)
        except Exception:  # a motion that fails at once is not kept
            if before is None:
                del state.motions[key]
            else:
                state.motions[key] = before
            raise

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Writes the scene as glTF 2.0 (.gltf + .bin, or .glb). Refuses to replace an existing
        file unless overwrite=True. The node trees of animated files are written in their current
        pose with their glTF animations, which play the same after loading; motions given from
        Python (Scene.animate: functions and Keyframes) and what is playing are not saved."""
        path = Path(path)
        targets = [path] + ([path.with_suffix(".bin")] if path.suffix == ".gltf" else [])
        existing = [p for p in targets if p.exists()]
        if existing and not overwrite:
            raise FileExistsError(f"{existing[0]} exists; pass overwrite=True to replace it")
        # Written into a temporary folder beside the target, then renamed into place (the .bin
        # first, so a .gltf never names a buffer that is not there): a failure leaves no partial
        # file and raises an OutputError (an OSError) naming the file.
        from .io import output_error

        try:
            staging = Path(tempfile.mkdtemp(prefix=".ssrlab-save-", dir=path.parent))
        except OSError as exc:
            raise output_error(exc, path) from exc
        try:
            self._save(str(staging / path.name), str(path.parent.resolve()))
            for t in reversed(targets):
                os.replace(staging / t.name, t)
        except OSError as exc:
            raise output_error(exc, path) from exc
        finally:
            shutil.rmtree(staging, ignore_errors=True)
        return path

    def copy(self) -> "Scene":
        """A deep copy (another scene for GPU caches), with what it plays and its motions."""
        out = Scene()
        out._assign(self)
        if "_animation" in self.__dict__:
            out.__dict__["_animation"] = self._animation_state().copy()
        return out

    def __repr__(self) -> str:
        return (f"Scene({self.name!r}: {self.object_count} objects, {self.triangle_count} triangles, "
                f"{len(self.lights)} lights)")


def directional_light(direction, color=(1.0, 1.0, 1.0), intensity: float = 3.0, cast_shadow: bool = True,
                      name: str = "sun") -> Light:
    """A directional light; `direction` is where the light travels, `intensity` the
    irradiance (W/m^2) on a surface facing it."""
    return Light.directional(direction, color, intensity, cast_shadow, name)


def point_light(position, color=(1.0, 1.0, 1.0), intensity: float = 10.0, name: str = "point", *,
                cast_shadow: bool = False) -> Light:
    """A point light of radiant intensity `intensity` (W/sr); with `cast_shadow` it casts a
    shadow in every direction (a cube shadow map: six faces, six draws of the scene)."""
    light = Light.point(position, color, intensity, name)
    light.cast_shadow = bool(cast_shadow)
    return light


def spot_light(position, direction, inner_cone: float = 0.0, outer_cone: float = 0.7853982, color=(1.0, 1.0, 1.0),
               intensity: float = 10.0, range: float = 0.0, name: str = "spot", *, cast_shadow: bool = False) -> Light:
    """A KHR_lights_punctual spot light at `position` shining down `direction`: radiant intensity
    `intensity` (W/sr) within `inner_cone` of the axis, none beyond `outer_cone` (radians), the
    extension's smooth falloff between; `range` > 0 ends it with the extension's window. With
    `cast_shadow` it casts a shadow (a perspective shadow map over its outer cone)."""
    light = Light.spot(position, direction, inner_cone, outer_cone, color, intensity, range, name)
    light.cast_shadow = bool(cast_shadow)
    return light


__all__ = ["Scene", "SceneWarning", "Material", "Light", "Environment", "Camera", "directional_light", "point_light",
           "spot_light"]
