"""User passes: a technique of your own, written as one GLSL compute shader and declared here.

A ``UserPass`` names its shader file, the stage of the chain it fills, the resources it reads and
writes (by the names the chain uses: ``Renderer.chain()`` lists them), the textures it creates,
its dispatch and its parameters. Registered on a Renderer (``Renderer.register_pass``), it is
checked against the renderer's passes (a pass may only read what an earlier pass writes and
write what its stage lets it); chosen per render by ``Settings(user_passes=("name",))``; its
parameters are set as ``Settings(user_params={"name.param": value})`` (or, as a sweep axis,
``"name.param"``), validated against the declared range, and reach the shader as uniforms
``u_<param>``. The GLSL side (bindings, includes, how a trace writes its rays) is
docs/guide/glsl-contract.md; a tutorial is docs/guide/your-first-technique.md.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path
from typing import Any

STAGES = {
    "trace": "takes the place of the screen-space trace (trace_linear / trace_hiz): writes rays.hit, "
             "rays.sample and rays.direction for every (trace pixel, ray); Settings.method ('linear' or 'hiz') "
             "still chooses the passes around it ('hiz' builds the Hi-Z pyramid hiz_trace)",
    "reflection_filter": "runs right after the resolve and rewrites `reflection` in place (reading a copy "
                         "taken just before it runs)",
}
STAGE_WRITES = {"trace": ("rays.hit", "rays.sample", "rays.direction"), "reflection_filter": ("reflection",)}
DISPATCHES = {"trace": ("ray", "list"), "reflection_filter": ("pixel", "ray")}
FORMATS = ("rgba8", "rgba16f", "rgba32f", "rg16f", "rg32f", "r16f", "r32f")
SIZES = ("image", "trace", "rays")
PARAM_TYPES = ("float", "int", "bool")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclasses.dataclass(frozen=True)
class Param:
    """A parameter of a user pass: a uniform ``u_<name>`` of `type` ('float', 'int' or 'bool'),
    `default` when Settings.user_params does not set it, allowed range [lo, hi] (inclusive)."""

    name: str
    type: str = "float"
    default: float | int | bool = 0.0
    lo: float | None = None
    hi: float | None = None
    doc: str = ""

    def check(self, value: Any, where: str) -> float | int | bool:
        """`value` converted to the parameter's type; ValueError naming `where` otherwise."""
        if self.type == "bool":
            if not isinstance(value, bool):
                raise ValueError(f"{where} must be True or False, got {value!r}")
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"{where} must be a number, got {value!r}")
        if self.type == "int":
            if isinstance(value, float) and not value.is_integer():
                raise ValueError(f"{where} must be an integer, got {value!r}")
            value = int(value)
        else:
            value = float(value)
            if not math.isfinite(value):
                raise ValueError(f"{where} must be finite, got {value!r}")
        if (self.lo is not None and value < self.lo) or (self.hi is not None and value > self.hi):
            raise ValueError(f"{where} must be in [{self.lo}, {self.hi}], got {value!r}")
        return value


@dataclasses.dataclass(frozen=True)
class Texture:
    """A texture a user pass creates: `format` one of FORMATS; `size` 'image' (width x height),
    'trace' (the trace resolution) or 'rays' (the trace resolution, one layer per traced ray)."""

    name: str
    format: str = "rgba16f"
    size: str = "image"


class UserPass:
    """The declaration of a user pass (see the module documentation).

    name      the pass's name: its timer (frame.timings[name]), its place in frame.passes, its stats
              (frame.stats[name + '.invocations']) and the prefix of its parameters
    shader    path of its compute shader (.comp, starting with ``#version 450 core``); it may
              ``#include "lib/<file>.glsl"`` from ssrlab's shader library
    stage     'trace' or 'reflection_filter' (STAGES)
    reads     resources it reads, by their chain names (texture units 0, 1, ... for a filter; a
              trace's beyond the G-buffer at units 4, 5, ...: docs/guide/glsl-contract.md)
    writes    resources it rewrites; default (and, for a trace, the only choice) its stage's (STAGE_WRITES)
    creates   Texture declarations of its own outputs
    dispatch  'ray' (every trace pixel and ray, or classify's list with Settings.skip), 'list' (classify's
              list: needs Settings.skip) or 'pixel' (every image pixel); default 'ray' for a trace,
              'pixel' for a filter
    params    Param declarations
    doc       one line on what it does (describe() shows it)
    """

    def __init__(self, name: str, shader, stage: str, reads=(), writes=None, creates=(), dispatch: str | None = None,
                 params=(), doc: str = ""):
        if not isinstance(name, str) or not _NAME.match(name):
            raise ValueError(f"UserPass.name must be an identifier (letters, digits, _), got {name!r}")
        where = f"UserPass {name!r}"
        if stage not in STAGES:
            raise ValueError(f"{where}: stage must be one of {', '.join(map(repr, STAGES))}, got {stage!r}")
        path = Path(shader).expanduser().resolve()
        if not path.is_file():
            raise FileNotFoundError(f"{where}: shader file {str(shader)!r} not found")
        if path.suffix != ".comp":
            raise ValueError(f"{where}: shader must be a compute shader (.comp), got {str(shader)!r}")
        dispatch = dispatch or DISPATCHES[stage][0]
        if dispatch not in DISPATCHES[stage]:
            raise ValueError(f"{where}: dispatch for stage {stage!r} must be one of "
                             f"{', '.join(map(repr, DISPATCHES[stage]))}, got {dispatch!r}")
        reads = _names(reads, f"{where}: reads")
        writes = STAGE_WRITES[stage] if writes is None else _names(writes, f"{where}: writes")
        creates = tuple(creates)
        for c in creates:
            if not isinstance(c, Texture):
                raise TypeError(f"{where}: creates must hold ssrlab.user_pass.Texture, got {c!r}")
            if c.format not in FORMATS:
                raise ValueError(f"{where}: texture {c.name!r} has format {c.format!r}; formats: {', '.join(FORMATS)}")
            if c.size not in SIZES:
                raise ValueError(f"{where}: texture {c.name!r} has size {c.size!r}; sizes: {', '.join(SIZES)}")
        params = tuple(params)
        seen = set()
        for p in params:
            if not isinstance(p, Param):
                raise TypeError(f"{where}: params must hold ssrlab.user_pass.Param, got {p!r}")
            if not _NAME.match(p.name):
                raise ValueError(f"{where}: parameter name {p.name!r} is not an identifier (it becomes u_{p.name})")
            if p.name in seen:
                raise ValueError(f"{where}: parameter {p.name!r} is declared twice")
            seen.add(p.name)
            if p.type not in PARAM_TYPES:
                raise ValueError(f"{where}: parameter {p.name!r} has type {p.type!r}; types: {', '.join(PARAM_TYPES)}")
            if p.lo is not None and p.hi is not None and p.lo > p.hi:
                raise ValueError(f"{where}: parameter {p.name!r} has lo {p.lo} > hi {p.hi}")
            p.check(p.default, f"{where}: the default of parameter {p.name!r}")
        self.name, self.shader, self.stage, self.dispatch = name, path, stage, dispatch
        self.reads, self.writes, self.creates, self.params, self.doc = reads, writes, creates, params, doc

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        raise ValueError(f"user pass {self.name!r} has no parameter {name!r} "
                         f"(it has: {', '.join(p.name for p in self.params) or 'none'})")

    def native_args(self) -> tuple:
        """The arguments of the native Renderer.register_user_pass."""
        return (self.name, str(self.shader), self.stage, self.dispatch, list(self.reads), list(self.writes),
                [(c.name, c.format, c.size) for c in self.creates],
                [(p.name, p.type, float(p.default)) for p in self.params])

    def describe(self) -> str:
        lines = [f"  {self.name}  (stage {self.stage}, dispatch {self.dispatch}; {self.shader})"]
        if self.doc:
            lines.append(f"      {self.doc}")
        for p in self.params:
            rng = f"  [{p.lo}, {p.hi}]" if p.lo is not None or p.hi is not None else ""
            lines.append(f"  {self.name}.{p.name} = {p.default!r} ({p.type}){rng}\n      {p.doc}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"UserPass({self.name!r}, stage={self.stage!r}, shader={str(self.shader)!r})"


def _names(values, where: str) -> tuple:
    if isinstance(values, str):
        values = (values,)
    out = tuple(values)
    for v in out:
        if not isinstance(v, str) or not v:
            raise ValueError(f"{where} must be resource names (strings), got {v!r}")
    return out


# The user passes registered on any Renderer of this process, by name: Settings validates
# user_params against them, describe() lists them, and the sweeps' renderers register them.
_DECLARED: dict[str, UserPass] = {}


def declare(p: UserPass, check_only: bool = False) -> None:
    old = _DECLARED.get(p.name)
    if old is not None and old.native_args() != p.native_args():
        raise ValueError(f"user pass {p.name!r}: a different user pass of this name was registered in this "
                         f"process already ({old!r}); give this one another name")
    if not check_only:
        _DECLARED[p.name] = p


def declared() -> dict[str, UserPass]:
    """The user passes registered on a Renderer of this process, by name."""
    return dict(_DECLARED)


def check_params(params: dict) -> dict:
    """Settings.user_params checked against the declared passes: each key '<pass>.<param>' of a
    registered pass, each value in its range; returns the values converted to their types."""
    if not isinstance(params, dict):
        raise ValueError(f"Settings.user_params must be a dict of '<pass>.<param>' -> value, got {params!r}")
    out = {}
    for key, value in params.items():
        if not isinstance(key, str) or "." not in key:
            raise ValueError(f"Settings.user_params key {key!r} must be '<pass>.<param>'")
        pass_name, _, name = key.rpartition(".")
        p = _DECLARED.get(pass_name)
        if p is None:
            raise ValueError(f"Settings.user_params[{key!r}]: no user pass {pass_name!r} is registered "
                             f"(Renderer.register_pass; registered: {', '.join(_DECLARED) or 'none'})")
        out[key] = p.param(name).check(value, f"Settings.user_params[{key!r}]")
    return dict(sorted(out.items()))


def load(spec: str, folder: Path | None = None) -> UserPass:
    """The UserPass that "<file.py>:<function>" returns (a path relative to `folder` first), declared
    in this process (so that Settings and the sweeps' renderers know it): how sweep files name
    user passes (ssrlab.bench.load_sweep's key user_passes)."""
    import importlib.util

    if not isinstance(spec, str) or ":" not in spec:
        raise ValueError(f"a user pass is named '<file.py>:<function>', got {spec!r}")
    file, _, func = spec.rpartition(":")
    path = Path(file)
    if folder is not None and not path.is_absolute() and (Path(folder) / path).is_file():
        path = Path(folder) / path
    if not path.is_file():
        raise FileNotFoundError(f"user pass {spec!r}: {file} not found")
    module_spec = importlib.util.spec_from_file_location(f"ssrlab_user_pass_{path.stem}", path)
    module = importlib.util.module_from_spec(module_spec)
    module_spec.loader.exec_module(module)
    make = getattr(module, func, None)
    if make is None:
        raise ValueError(f"user pass {spec!r}: {path} has no function {func!r}")
    p = make()
    if not isinstance(p, UserPass):
        raise TypeError(f"user pass {spec!r}: {func}() returned {type(p).__name__}, not an ssrlab.UserPass")
    declare(p)
    return p
