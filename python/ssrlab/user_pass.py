"""User passes: a technique of your own, written as one GLSL compute shader and declared here.

A ``UserPass`` names its shader file, where it runs (a stage it fills, or no stage: placed by
the resources it reads and rewrites, optionally right after or before a named pass), the
resources it reads and writes (by the names the chain uses: ``Renderer.chain()`` lists them), the
textures it creates, its dispatch and its parameters. Registered on a Renderer
(``Renderer.register_pass``), it is checked against the renderer's passes (a pass may only read
what an earlier pass writes, and a place where that is impossible is refused naming the input);
chosen per render by ``Settings(user_passes=("name",))``; its parameters are set as
``Settings(user_params={"name.param": value})`` (or, as a sweep axis, ``"name.param"``),
validated against the declared range, and reach the shader as uniforms ``u_<param>``.

Passes that travel: a module that declares passes (``UserPass`` objects at module level, or a
function ``register(registry)`` that calls ``registry.register_pass(p)``) named in
``Settings(user_modules=("my_lab.techniques",))`` is imported wherever those settings are used:
every Renderer that renders with them registers its passes, and so do the workers of a sweep,
local or on a cluster (load_module). The GLSL side (bindings, includes, how a trace writes its
rays) is docs/guide/glsl-contract.md; a tutorial is docs/guide/your-first-technique.md.
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
    None: "no stage: placed by its resources, right after the last pass that declares a texture it reads or "
          "rewrites, or right after / before the pass it names (after=, before=); it may rewrite any declared "
          "texture an image store can write (reading a copy where it also reads it)",
}
# The native name of a placed pass's kind (stage None).
PLACED = "placed"
STAGE_WRITES = {"trace": ("rays.hit", "rays.sample", "rays.direction"), "reflection_filter": ("reflection",),
                None: ()}
DISPATCHES = {"trace": ("ray", "list"), "reflection_filter": ("pixel", "ray"), None: ("pixel", "ray")}
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
    stage     'trace', 'reflection_filter' or None (STAGES): None places it by its resources
    reads     resources it reads, by their chain names (texture units 0, 1, ... for a filter or a
              placed pass; a trace's beyond the G-buffer at units 4, 5, ...: docs/guide/glsl-contract.md)
    writes    resources it rewrites; default (and, for a trace, the only choice) its stage's
              (STAGE_WRITES); a placed pass may rewrite any declared texture an image store can write
    creates   Texture declarations of its own outputs
    dispatch  'ray' (every trace pixel and ray, or classify's list with Settings.skip), 'list' (classify's
              list: needs Settings.skip) or 'pixel' (every image pixel); default 'ray' for a trace,
              'pixel' otherwise
    params    Param declarations
    doc       one line on what it does (describe() shows it)
    after, before   a placed pass only: the pass (built-in or user) it runs right after or right
              before, e.g. after="resolve", before="composite"; without either it runs right after the
              last pass that declares a texture it reads or rewrites. A place where something it reads
              is not written yet is refused, naming it (at registration where no chain could hold it,
              else at render)
    """

    def __init__(self, name: str, shader, stage: str | None = None, reads=(), writes=None, creates=(),
                 dispatch: str | None = None, params=(), doc: str = "", *, after: str | None = None,
                 before: str | None = None):
        if not isinstance(name, str) or not _NAME.match(name):
            raise ValueError(f"UserPass.name must be an identifier (letters, digits, _), got {name!r}")
        where = f"UserPass {name!r}"
        if stage not in STAGES:
            raise ValueError(f"{where}: stage must be one of {', '.join(map(repr, STAGES))}, got {stage!r}")
        for key, anchor in (("after", after), ("before", before)):
            if anchor is not None and (not isinstance(anchor, str) or not anchor):
                raise ValueError(f"{where}: {key} must be the name of a pass, got {anchor!r}")
            if anchor is not None and stage is not None:
                raise ValueError(f"{where}: {key}={anchor!r} places a pass without a stage; a {stage} pass "
                                 f"has its stage's place (leave stage out to place it by its resources)")
        if after is not None and before is not None:
            raise ValueError(f"{where}: name one pass to run after or before, not both (after={after!r}, "
                             f"before={before!r})")
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
        self.after, self.before = after, before

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        raise ValueError(f"user pass {self.name!r} has no parameter {name!r} "
                         f"(it has: {', '.join(p.name for p in self.params) or 'none'})")

    def native_args(self) -> tuple:
        """The arguments of the native Renderer.register_user_pass."""
        return (self.name, str(self.shader), self.stage or PLACED, self.dispatch, list(self.reads), list(self.writes),
                [(c.name, c.format, c.size) for c in self.creates],
                [(p.name, p.type, float(p.default)) for p in self.params], self.after or "", self.before or "")

    @property
    def place(self) -> str:
        """Where it runs, in words: its stage, or how it is placed."""
        if self.stage is not None:
            return f"stage {self.stage}"
        if self.after or self.before:
            return f"placed {'after' if self.after else 'before'} {self.after or self.before}"
        return "placed by its resources"

    def describe(self) -> str:
        lines = [f"  {self.name}  ({self.place}, dispatch {self.dispatch}; {self.shader})"]
        if self.doc:
            lines.append(f"      {self.doc}")
        for p in self.params:
            rng = f"  [{p.lo}, {p.hi}]" if p.lo is not None or p.hi is not None else ""
            lines.append(f"  {self.name}.{p.name} = {p.default!r} ({p.type}){rng}\n      {p.doc}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        where = f"stage={self.stage!r}" if self.stage is not None else (
            f"after={self.after!r}" if self.after else f"before={self.before!r}" if self.before else "placed")
        return f"UserPass({self.name!r}, {where}, shader={str(self.shader)!r})"


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


# The passes of each user module loaded in this process, by its spec (module_spec's form).
_MODULES: dict[str, tuple[UserPass, ...]] = {}


def module_spec(spec: str, folder=None) -> str:
    """A user module spec in the form every process can load: ``"package.module"`` (imported by
    name: it must be importable where the settings are used, installed or on sys.path) or the path
    of a ``.py`` file (made absolute, relative to `folder` or else the working folder: on a cluster,
    a path every worker sees), either optionally followed by ``":attribute"`` (one UserPass, a
    function returning one or several, or a register function). ValueError naming a bad spec."""
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"a user module is 'package.module', 'file.py' or either with ':attribute', got {spec!r}")
    base, sep, attr = spec.rpartition(":")
    if not sep or not _NAME.match(attr):
        base, attr = spec, ""
    if base.endswith(".py") or "/" in base or "\\" in base:
        path = Path(base).expanduser()
        if not path.is_absolute():
            near = Path(folder) / path if folder is not None else None
            path = near if near is not None and near.is_file() else Path.cwd() / path
        if not path.is_file():
            raise FileNotFoundError(f"user module {spec!r}: {path} not found")
        base = str(path.resolve())
    elif not all(_NAME.match(part) for part in base.split(".")):
        raise ValueError(f"user module {spec!r}: {base!r} is neither a module name (package.module) nor a .py file")
    return base + (f":{attr}" if attr else "")


class _Registry:
    """What a module's register(registry) function registers its passes on (load_module)."""

    def __init__(self, spec: str):
        self.spec, self.passes = spec, []

    def register_pass(self, user_pass) -> None:
        if not isinstance(user_pass, UserPass):
            raise TypeError(f"user module {self.spec!r}: register_pass takes an ssrlab.UserPass, "
                            f"got {type(user_pass).__name__}")
        self.passes.append(user_pass)


def _passes_of(value, spec: str, what: str) -> list[UserPass]:
    """The passes an attribute gives: a UserPass, a register(registry) function, or a function
    returning a UserPass or several."""
    import inspect

    if isinstance(value, UserPass):
        return [value]
    if not callable(value):
        raise TypeError(f"user module {spec!r}: {what} is neither an ssrlab.UserPass nor a function")
    try:
        required = [p for p in inspect.signature(value).parameters.values()
                    if p.default is p.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    except (TypeError, ValueError):
        required = []
    if len(required) == 1:  # register(registry)
        registry = _Registry(spec)
        value(registry)
        return registry.passes
    made = value()
    passes = [made] if isinstance(made, UserPass) else list(made) if isinstance(made, (list, tuple)) else None
    if passes is None or not all(isinstance(p, UserPass) for p in passes):
        raise TypeError(f"user module {spec!r}: {what}() returned {type(made).__name__}, not an ssrlab.UserPass "
                        f"(or a list of them)")
    return passes


def load_module(spec: str, folder=None) -> tuple[UserPass, ...]:
    """The user passes of a user module (module_spec), each declared in this process so that
    Settings validates their parameters and every Renderer rendering with them registers them;
    loaded once per process. Without an attribute: every UserPass at the module's top level (in
    definition order) and those its ``register(registry)`` function registers; with one: that
    attribute's. ValueError where the module declares none; an ImportError of the module names it."""
    import importlib
    import importlib.util
    import sys

    spec = module_spec(spec, folder)
    if spec in _MODULES:
        return _MODULES[spec]
    base, sep, attr = spec.rpartition(":")
    if not sep or not _NAME.match(attr):
        base, attr = spec, ""
    if base.endswith(".py") or "/" in base:
        import hashlib

        name = f"ssrlab_user_module_{Path(base).stem}_{hashlib.sha1(base.encode()).hexdigest()[:8]}"
        module = sys.modules.get(name)
        if module is None:
            module_spec_ = importlib.util.spec_from_file_location(name, base)
            module = importlib.util.module_from_spec(module_spec_)
            sys.modules[name] = module
            try:
                module_spec_.loader.exec_module(module)
            except BaseException:
                del sys.modules[name]
                raise
    else:
        try:
            module = importlib.import_module(base)
        except ImportError as e:
            raise ImportError(f"user module {spec!r}: cannot import {base!r} here ({e}); a module named in "
                              f"Settings.user_modules must be importable wherever the settings are used (installed, "
                              f"or on PYTHONPATH of every worker), or be given as a .py path they all see") from e
    if attr:
        if not hasattr(module, attr):
            raise ValueError(f"user module {spec!r}: {base} has no attribute {attr!r}")
        passes = _passes_of(getattr(module, attr), spec, attr)
    else:
        passes = [v for v in vars(module).values() if isinstance(v, UserPass)]
        register = getattr(module, "register", None)
        if callable(register):
            passes += _passes_of(register, spec, "register")
    unique = list({id(p): p for p in passes}.values())
    if not unique:
        raise ValueError(f"user module {spec!r} declares no user pass: give it ssrlab.UserPass objects at the top "
                         f"level or a function register(registry) that calls registry.register_pass(p)")
    for p in unique:
        declare(p)
    _MODULES[spec] = tuple(unique)
    return _MODULES[spec]


def load(spec: str, folder: Path | None = None) -> UserPass:
    """The UserPass that "<file.py>:<function>" returns (a path relative to `folder` first),
    declared in this process (so that Settings and the sweeps' renderers know it). A module of
    several passes, or one every worker of a sweep must load too: load_module and
    Settings.user_modules."""
    if not isinstance(spec, str) or ":" not in spec:
        raise ValueError(f"a user pass is named '<file.py>:<function>', got {spec!r}")
    passes = load_module(spec, folder)
    if len(passes) != 1:
        raise ValueError(f"user pass {spec!r} gives {len(passes)} passes ({', '.join(p.name for p in passes)}); "
                         f"load_module returns them all")
    return passes[0]
