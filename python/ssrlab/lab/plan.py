"""Planning a sweep: the grid of settings, the scene and view specs, the sweep files.

Nothing here renders: plan_sweep checks every argument of a sweep and lists its configurations
(ssrlab.lab.run runs them, ssrlab.lab.report writes and plots the rows).
"""

from __future__ import annotations

import itertools
import json
import math
import os
import sys
from dataclasses import fields
from pathlib import Path
from typing import Any, Iterable

from ..settings import Settings

SETTINGS_PREFIX = "s_"
VIEW_KEYS = ("name", "position", "target", "up", "fov_y", "near", "far")
SWEEP_FILE_KEYS = ("description", "scenes", "views", "base", "grid", "repeats", "warmup", "reference",
                   "reference_rays", "device", "frames", "sequence", "user_modules", "user_passes")
SETTINGS_FIELDS = tuple(f.name for f in fields(Settings))


# -- grid ---------------------------------------------------------------------------------------
def expand_grid(grid: dict[str, list]) -> list[dict]:
    """Every combination of the grid's values (cartesian product), as a list of dicts.

    The order is stable: keys in the grid's order, the last key varying fastest, values in
    their listed order. Every key must be a Settings field and every value valid for it
    (ValueError naming the key otherwise). An empty grid gives one empty point.
    """
    if not isinstance(grid, dict):
        raise ValueError(f"grid must be a dict of Settings field -> list of values, got {type(grid).__name__}")
    axes = {}
    for key, values in grid.items():
        if key not in SETTINGS_FIELDS and "." not in key:  # '<pass>.<param>': a user pass's parameter
            from ..settings import _suggestion

            raise ValueError(f"grid key {key!r} is not a Settings field{_suggestion(key)}; "
                             f"fields: {', '.join(SETTINGS_FIELDS)}")
        if isinstance(values, (str, bytes, dict)) or not isinstance(values, Iterable):
            raise ValueError(f"grid[{key!r}] must be a non-empty list of values, got {values!r}")
        axes[key] = list(values)
        if not axes[key]:
            raise ValueError(f"grid[{key!r}] must be a non-empty list of values, got an empty one")
        for v in axes[key]:
            try:
                Settings().replace(**{key: v})
            except ValueError as e:
                raise ValueError(f"grid[{key!r}]: {e}") from None
    return [dict(zip(axes, combo)) for combo in itertools.product(*axes.values())]


# -- scene and view specs ----------------------------------------------------------------------------
def _check_scene_spec(spec, where: str = "scenes") -> Any:
    """Validates a scene spec; returns it with a glTF path made absolute (so workers with
    another working folder find it)."""
    from .. import scenes

    if isinstance(spec, (str, os.PathLike)):
        name, kwargs = str(spec), {}
    elif isinstance(spec, dict):
        if "name" not in spec or not isinstance(spec["name"], str):
            raise ValueError(f"{where}: a scene dict needs a 'name' (a procedural scene), got {spec!r}")
        name, kwargs = spec["name"], {k: v for k, v in spec.items() if k != "name"}
    else:
        raise ValueError(f"{where}: a scene spec is a scene name, a .gltf/.glb path or a dict "
                         f"{{'name': ..., **builder options}}, got {type(spec).__name__} {spec!r}")
    if name in scenes.SCENES:
        import inspect

        params = inspect.signature(scenes.SCENES[name]).parameters
        unknown = sorted(set(kwargs) - set(params))
        if unknown:
            raise ValueError(f"{where}: scene {name!r} has no option(s) {', '.join(unknown)}; "
                             f"options: {', '.join(params)}")
        try:
            json.dumps(kwargs)
        except TypeError as e:
            raise ValueError(f"{where}: options of scene {name!r} must be plain numbers, strings and "
                             f"lists: {e}") from None
        return spec
    if Path(name).suffix.lower() in (".gltf", ".glb"):
        if kwargs:
            raise ValueError(f"{where}: options {sorted(kwargs)} apply to procedural scenes only, not {name}")
        path = Path(name).expanduser()
        if not path.is_file():
            raise FileNotFoundError(f"{where}: scene file {path} not found")
        return str(path.resolve())
    raise ValueError(f"{where}: unknown scene {name!r}: expected one of {', '.join(scenes.SCENES)}, "
                     f"a .gltf/.glb file or a dict {{'name': ..., **options}}")


def scene_label(spec) -> str:
    """A short readable name of a scene spec: ``box_stack``, ``hall(floor_roughness=0.3)``,
    or a glTF file's stem."""
    if isinstance(spec, dict):
        options = ", ".join(f"{k}={v!r}" for k, v in spec.items() if k != "name")
        return f"{spec['name']}({options})" if options else spec["name"]
    name = str(spec)
    return Path(name).stem if Path(name).suffix.lower() in (".gltf", ".glb") else name


def _check_vector(view: dict, key: str, where: str) -> list[float]:
    v = view[key]
    try:
        out = [float(x) for x in v]
    except (TypeError, ValueError):
        out = []
    if len(out) != 3 or not all(math.isfinite(x) for x in out):
        raise ValueError(f"{where}: {key} must be 3 finite numbers, got {v!r}")
    return out


def _check_view(view, index: int) -> Any:
    """Validates a view spec: "default", a dict (see sweep) or an ssrlab.Camera."""
    from .._core import Camera

    where = f"views[{index}]"
    if isinstance(view, Camera) or view == "default":
        return view
    if not isinstance(view, dict):
        raise ValueError(f"{where}: a view is 'default', a dict {{name, position, target[, up, fov_y, near, "
                         f"far]}} or an ssrlab.Camera, got {view!r}")
    unknown = sorted(set(view) - set(VIEW_KEYS))
    if unknown:
        raise ValueError(f"{where}: unknown view key(s) {', '.join(unknown)}; keys: {', '.join(VIEW_KEYS)}")
    for key in ("name", "position", "target"):
        if key not in view:
            raise ValueError(f"{where}: a view dict needs {key!r}")
    if not isinstance(view["name"], str) or not view["name"]:
        raise ValueError(f"{where}: name must be a non-empty string, got {view['name']!r}")
    out = dict(view)
    for key in ("position", "target", "up"):
        if key in view:
            out[key] = _check_vector(view, key, where)
    for key in ("fov_y", "near", "far"):
        if key in view:
            v = view[key]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
                raise ValueError(f"{where}: {key} must be a positive number, got {v!r}")
            out[key] = float(v)
    if "fov_y" in out and not out["fov_y"] < 180.0:
        raise ValueError(f"{where}: fov_y must be below 180 degrees, got {out['fov_y']!r}")
    return out


def view_name(view, index: int) -> str:
    """The name a row records for a view: "default", a dict's name, or camera<index>."""
    if isinstance(view, dict):
        return view["name"]
    return "default" if view == "default" else f"camera{index}"


def view_camera(view, scene):
    """The Camera of a view spec for `scene`. A dict's missing up, fov_y, near and far come
    from the scene's own camera (or ssrlab.Camera's defaults when it has none)."""
    from .._core import Camera

    if isinstance(view, Camera):
        return view
    own = scene.camera
    if view == "default":
        if own is None:
            raise ValueError(f"view 'default': scene {scene.name!r} has no camera")
        return own
    base = own if own is not None else Camera()
    return Camera(position=tuple(view["position"]), target=tuple(view["target"]),
                  up=tuple(view.get("up", base.up)), fov_y=view.get("fov_y", base.fov_y),
                  near=view.get("near", base.near), far=view.get("far", base.far))


def _check_count(value, name: str, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < lo:
        raise ValueError(f"{name} must be an integer >= {lo}, got {value!r}")
    return value


def plan_sweep(grid: dict[str, list], scenes: list, views: list | None = None,
               base: dict | Settings | None = None) -> list[dict]:
    """The configurations of a sweep, in sweep order (scenes outermost, then views, then grid
    points), without rendering anything: dicts with scene_spec, view, view_name and
    settings (a dict of every Settings field). Checks every argument (see sweep) and raises
    ValueError (FileNotFoundError for a missing glTF file) naming the bad one.
    """
    points = expand_grid(grid)
    if isinstance(scenes, (str, dict)) or not isinstance(scenes, (list, tuple)) or not scenes:
        raise ValueError(f"scenes must be a non-empty list of scene specs, got {scenes!r}")
    scene_specs = [_check_scene_spec(s, f"scenes[{i}]") for i, s in enumerate(scenes)]
    if views is None:
        views = ["default"]
    if isinstance(views, (str, dict)) or not isinstance(views, (list, tuple)) or not views:
        raise ValueError(f"views must be None or a non-empty list of views, got {views!r}")
    view_specs = [_check_view(v, i) for i, v in enumerate(views)]
    names = [view_name(v, i) for i, v in enumerate(view_specs)]
    if len(set(names)) != len(names):
        raise ValueError(f"views must have distinct names, got {names}")
    if base is None:
        base_settings = Settings()
    elif isinstance(base, Settings):
        base_settings = base
    elif isinstance(base, dict):
        try:
            base_settings = Settings().replace(**base)
        except ValueError as e:
            raise ValueError(f"base: {e}") from None
    else:
        raise ValueError(f"base must be a Settings, a dict of Settings fields or None, got {type(base).__name__}")
    settings = []
    for point in points:
        try:
            settings.append(base_settings.replace(**point).to_dict())
        except ValueError as e:
            raise ValueError(f"grid point {point}: {e}") from None
    return [{"scene_spec": spec, "view": view, "view_name": name, "settings": dict(point_settings)}
            for spec in scene_specs for view, name in zip(view_specs, names) for point_settings in settings]


# -- sweep files -------------------------------------------------------------------------------------------
def load_sweep(path) -> dict:
    """Reads a sweep file (TOML, or JSON for a .json file) into keyword arguments of sweep().

    Top-level keys: scenes (required), views, repeats, warmup, reference, reference_rays,
    device, frames (N > 1: render N frames of a static camera, score the last), sequence (true:
    one sequence of warmup + repeats frames, see sweep), description (free text, not passed on),
    user_modules (modules that declare user passes, Settings.user_modules: 'package.module' or a
    .py path, relative to the sweep file, optionally ':attribute'; user_passes, a list of
    '<file.py>:<function>', is the same), and the tables base (Settings fields of every run) and
    grid (Settings field -> list of values). The modules join base's user_modules, so that every
    worker of the sweep loads them. Other keys raise ValueError naming them. A relative glTF path
    is looked up beside the sweep file first.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"sweep file {path} not found")
    try:
        if path.suffix.lower() == ".json":
            data = json.loads(path.read_text())
        else:
            if sys.version_info >= (3, 11):
                import tomllib
            else:
                import tomli as tomllib
            data = tomllib.loads(path.read_text())
    except ValueError as e:  # json.JSONDecodeError and tomllib.TOMLDecodeError are ValueErrors
        raise ValueError(f"sweep file {path}: {e}") from None
    if not isinstance(data, dict):
        raise ValueError(f"sweep file {path}: expected a table of keys at the top level")
    unknown = sorted(set(data) - set(SWEEP_FILE_KEYS))
    if unknown:
        raise ValueError(f"sweep file {path}: unknown key(s) {', '.join(unknown)}; keys: {', '.join(SWEEP_FILE_KEYS)}")
    if "scenes" not in data:
        raise ValueError(f"sweep file {path}: 'scenes' is required")
    for table in ("base", "grid"):
        if table in data and not isinstance(data[table], dict):
            raise ValueError(f"sweep file {path}: '{table}' must be a table of Settings fields")
    scenes = data["scenes"]
    if isinstance(scenes, list):
        resolved = []
        for spec in scenes:
            if isinstance(spec, str) and Path(spec).suffix.lower() in (".gltf", ".glb") \
                    and not Path(spec).is_absolute() and (path.parent / spec).is_file():
                spec = str((path.parent / spec).resolve())
            resolved.append(spec)
        scenes = resolved
    # user_modules (and user_passes, '<file.py>:<function>'): modules that declare user passes,
    # paths relative to the sweep file; loaded here so that base and grid may name their passes and
    # parameters ("<pass>.<param>", quoted), and put into base.user_modules so that every worker
    # of the sweep, in this process or on a cluster, loads them too (Settings.user_modules).
    from ..user_pass import load_module, module_spec

    specs = []
    for key in ("user_modules", "user_passes"):
        listed = data.get(key, [])
        if not isinstance(listed, list) or not all(isinstance(v, str) for v in listed):
            raise ValueError(f"sweep file {path}: '{key}' must be a list of modules ('package.module', 'file.py', "
                             f"either with ':attribute')")
        specs += listed
    base = data.get("base", {})
    listed = base.get("user_modules", [])
    specs += [listed] if isinstance(listed, str) else list(listed) if isinstance(listed, list) else []
    modules = []
    for spec in specs:
        try:
            spec = module_spec(spec, path.parent)
        except (ValueError, FileNotFoundError) as e:
            raise type(e)(f"sweep file {path}: {e}") from None
        load_module(spec)
        if spec not in modules:
            modules.append(spec)
    if modules:
        data["base"] = {**base, "user_modules": modules}
    kwargs = {k: v for k, v in data.items() if k not in ("description", "user_modules", "user_passes")}
    kwargs["scenes"] = scenes
    kwargs.setdefault("grid", {})
    return kwargs


__all__ = ["SETTINGS_PREFIX", "VIEW_KEYS", "SWEEP_FILE_KEYS", "SETTINGS_FIELDS", "expand_grid", "scene_label",
           "view_name", "view_camera", "plan_sweep", "load_sweep"]
