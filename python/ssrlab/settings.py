"""Render settings: one validated object with documented units and defaults.

Every field is declared once, with its unit, range and meaning, in
cpp/render/settings_fields.def; this module reads that table from the native module
(``_core.settings_schema()``), so the validation here, the generated documentation
(``help(ssrlab.Settings)``, ``Settings.describe()``), the native validation and the shaders'
uniform block all come from the one declaration. An invalid value raises ``ValueError`` naming the
field, at construction and on assignment. The rules between fields (cpp/render/settings_rules.def),
the names of each choice and what every 'auto' becomes (cpp/render/auto_choice.h) are the native
module's: this module asks it and raises its words.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import json
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from . import _core


def _setting(default, doc: str, unit: str = "", lo=None, hi=None, choices=None, group: str = "", off=None,
             place: str = "pass", reference: bool = False):
    """A field: `lo`..`hi` inclusive range, or one of `choices`; `off` is an extra allowed
    value outside the range that switches the feature off; `place` where the renderer reads it
    ('uniform': the shaders' SsrSettings block, 'pass': the C++ passes); `reference`: it changes
    a converged reference image."""
    return field(
        default=default,
        metadata={"doc": doc, "unit": unit, "lo": lo, "hi": hi, "choices": choices, "group": group, "off": off,
                  "place": place, "reference": reference},
    )


# Every field as cpp/render/settings_fields.def declares it (name, type, default, range, unit,
# group, meaning): the one declaration the native validation, the bindings, the shaders' uniform
# block and this class are all made from. The fields are added to Settings below, in this order.
SCHEMA = tuple(_core.settings_schema())


class Settings:
    """Render settings: every field validated, at construction and on assignment.

    The fields, their defaults, units, ranges and meanings come from
    cpp/render/settings_fields.def (SCHEMA); `Settings.describe()`, `help(ssrlab.Settings)`
    and the generated settings reference list them all.
    """

    def __post_init__(self) -> None:
        # Construction, replace() and from_dict() end here: the fields are checked one by one
        # by __setattr__, the constraints between fields here (see CONSTRAINTS).
        self.check_constraints()

    def check_constraints(self) -> None:
        """Raises ValueError naming the fields, their values, the rule and why when a constraint
        between fields (CONSTRAINTS) fails: the native RenderSettings.check_rules()'s message, the
        one check there is. Checked when Settings is built or replaced and again before every
        render (single assignments are checked per field only, so that related fields can be set
        in turn)."""
        self._native_fields().check_rules()

    def _native_fields(self) -> "_core.RenderSettings":
        """The native settings holding every field the native side has, but those still 'auto'
        (which no rule names), at their native defaults."""
        native = _core.RenderSettings()
        for name in _NATIVE_FIELDS:
            value = getattr(self, name)
            if not (isinstance(value, str) and value == "auto" and name in _AUTO_FIELDS):
                setattr(native, name, value)
        return native

    def __setattr__(self, name: str, value: Any) -> None:
        # Every assignment, the dataclass __init__'s included, goes through the field's check.
        spec = _FIELDS.get(name)
        if spec is None:
            raise AttributeError(f"Settings has no field {name!r}{_suggestion(name)}; fields: {', '.join(_FIELDS)}")
        object.__setattr__(self, name, _check(spec, value))

    def replace(self, **changes) -> "Settings":
        """A copy with some fields changed (validated)."""
        changes = _user_param_keys(changes, self.user_params)
        _check_names(changes)
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Settings":
        _check_names(d)
        return cls(**d)

    def key(self) -> str:
        """A stable text key of every field (for caches and result rows)."""
        return json.dumps(self.to_dict(), sort_keys=True)

    def changed(self) -> dict:
        """The fields whose value differs from the default, in field order."""
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) != _default(f)}

    def __repr__(self) -> str:
        # Only what differs from the defaults, so that a repr stays readable and evaluates back.
        return "Settings(" + ", ".join(f"{k}={v!r}" for k, v in self.changed().items()) + ")"


    def resolved(self, device: str) -> "Settings":
        """A copy with every 'auto' value decided for `device` ('cpu': llvmpipe, 'gpu'), and what a
        technique overrides written as it runs (glossy 'cone' and 'blur_mips' trace one mirror ray per
        pixel: rays_per_pixel 1, sampling 'mirror'): what a Renderer on that device renders with
        (Frame.settings, a sweep's rows). 'auto' is decided natively (_core.decide_auto,
        cpp/render/auto_choice.h); deep_gbuffer 'auto' peels here, where no renderer has measured
        the constructions on a scene (Renderer.render does: docs/deep_gbuffer.md)."""
        decided = {name: _core.decide_auto(name, device) for name in _AUTO_FIELDS}  # refuses another device
        s = self.replace(**{name: v for name, v in decided.items() if getattr(self, name) == "auto"})
        return s.as_run()

    def as_run(self) -> "Settings":
        """A copy with what a technique overrides written as the chain runs it (glossy 'cone' and
        'blur_mips' trace one mirror ray per pixel: rays_per_pixel 1, sampling 'mirror'), decided
        natively (RenderSettings::as_run); 'auto' values stay 'auto'. A sweep's rows report these."""
        native = self._native_fields()
        ran = native.as_run()
        overridden = {n: getattr(ran, n) for n in _NATIVE_FIELDS if getattr(ran, n) != getattr(native, n)}
        return self.replace(**overridden) if overridden else self

    def to_native(self, device: str = "cpu") -> "_core.RenderSettings":
        """The native renderer's settings; 'auto' values decided for `device` (see resolved())."""
        self.check_constraints()
        native = self.resolved(device)._native_fields()
        native.user_params = {k: float(v) for k, v in self.user_params.items()}
        native.validate()
        return native

    @staticmethod
    def describe() -> str:
        """A table of every field: default, unit, range and meaning."""
        lines, group = [], None
        for f in fields(Settings):
            m = f.metadata
            if m["group"] != group:
                group = m["group"]
                lines.append(f"\n[{group}]")
            rng = ""
            if m["choices"]:
                rng = " | ".join(("True", "False", *m["choices"]) if f.type == "bool | str" else m["choices"])
            elif m["lo"] is not None:
                rng = f"[{m['lo']}, {m['hi']}]" + (f" or {m['off']} (off)" if m["off"] is not None else "")
            unit = f" {m['unit']}" if m["unit"] else ""
            lines.append(f"  {f.name} = {_default(f)!r}{unit}  {rng}\n      {m['doc']}")
        from .user_pass import declared

        if declared():
            lines.append("\n[user pass parameters] (Settings.user_params keys; the passes registered in this process)")
            lines += [p.describe() for p in declared().values()]
        lines.append("\n[constraints] (between fields; checked when Settings is built or replaced, and at render)")
        for c in CONSTRAINTS:
            lines.append(f"  {c.rule}\n      {c.why}")
        lines.append("  (allowed) fade_camera_end <= fade_camera_start\n      switches the fade toward the camera off")
        return "\n".join(lines).lstrip("\n")


def fields_markdown() -> str:
    """Every field as Markdown tables, one per group: default, unit, range, where the renderer
    reads it and meaning (the docs' generated settings reference, docs/gen_pages.py)."""
    def cell(text) -> str:
        return str(text).replace("|", "\\|")

    lines, group = [], None
    for f in fields(Settings):
        m = f.metadata
        if m["group"] != group:
            group = m["group"]
            lines += ["", f"## {group}", "", "| field | default | unit | range | read by | meaning |",
                      "|---|---|---|---|---|---|"]
        if m["choices"]:
            rng = ("`True`, `False`, " if f.type == "bool | str" else "") + ", ".join(f"`{c!r}`" for c in m["choices"])
        elif m["lo"] is not None:
            rng = f"[{m['lo']}, {m['hi']}]" + (f" or {m['off']} (off)" if m["off"] is not None else "")
        else:
            rng = "`True`, `False`"
        where = "shaders (`ssr.{}`)".format(f.name) if m["place"] == "uniform" else "passes"
        lines.append(f"| `{f.name}` | `{f.default!r}` | {cell(m['unit'])} | {cell(rng)} | {where} | {cell(m['doc'])} |")
    return "\n".join(lines).lstrip("\n") + "\n"


def _user_param_keys(changes: dict, current: dict) -> dict:
    """Keys '<pass>.<param>' (a user pass's parameter) moved into user_params."""
    dotted = {k: v for k, v in changes.items() if isinstance(k, str) and "." in k}
    if not dotted:
        return changes
    out = {k: v for k, v in changes.items() if k not in dotted}
    out["user_params"] = {**out.get("user_params", current), **dotted}
    return out


def _default(f: dataclasses.Field) -> Any:
    return f.default_factory() if f.default is dataclasses.MISSING else f.default


def _suggestion(name: str) -> str:
    """' (did you mean 'x'?)' for the field nearest to a misspelled name, or ''."""
    close = difflib.get_close_matches(str(name), list(_FIELDS), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _check_names(names) -> None:
    """ValueError naming every unknown field, with the nearest field for each."""
    unknown = sorted(set(names) - set(_FIELDS), key=str)
    if unknown:
        raise ValueError("unknown Settings field(s): " + ", ".join(f"{n!r}{_suggestion(n)}" for n in unknown)
                         + f"; fields: {', '.join(_FIELDS)}")


def _check(f: dataclasses.Field, value: Any) -> Any:
    m, name, typ = f.metadata, f"Settings.{f.name}", f.type
    if f.name == "user_modules":
        if isinstance(value, str):
            value = (value,)
        if not isinstance(value, (tuple, list)):
            raise ValueError(f"{name} must be a tuple of module names or .py paths, got {value!r}")
        from .user_pass import load_module, module_spec

        specs = []
        for v in value:
            try:
                spec = module_spec(v)
            except (ValueError, FileNotFoundError) as e:
                raise type(e)(f"{name}: {e}") from None
            load_module(spec)  # declares its passes here: user_params and user_passes may name them
            if spec not in specs:
                specs.append(spec)
        return tuple(specs)
    if f.name == "user_passes":
        if isinstance(value, str):
            value = (value,)
        if not isinstance(value, (tuple, list)) or not all(isinstance(v, str) and v for v in value):
            raise ValueError(f"{name} must be a tuple of user pass names, got {value!r}")
        if len(set(value)) != len(value):
            raise ValueError(f"{name} names a pass twice: {value!r}")
        return tuple(value)
    if f.name == "user_params":
        from .user_pass import check_params

        return check_params(value)
    if typ == "bool | str":  # True, False, or one of the named choices ('auto')
        if isinstance(value, str) and value in m["choices"]:
            return value
        if isinstance(value, np.bool_):
            value = bool(value)
        if not isinstance(value, bool):
            raise ValueError(f"{name} must be True, False or one of {', '.join(map(repr, m['choices']))}, "
                             f"got {value!r}")
        return value
    if typ in ("bool", bool):
        if isinstance(value, np.bool_):
            value = bool(value)
        if not isinstance(value, bool):
            raise ValueError(f"{name} must be True or False, got {value!r}")
        return value
    if typ in ("int", int):
        if isinstance(value, bool):
            raise ValueError(f"{name} must be an integer, got {value!r}")
        if isinstance(value, (int, np.integer)) or (isinstance(value, float) and value.is_integer()):
            value = int(value)
        else:
            raise ValueError(f"{name} must be an integer, got {value!r}")
    elif typ in ("float", float):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise ValueError(f"{name} must be a number, got {value!r}")
        value = float(value)
        if value != value or value in (float("inf"), float("-inf")):
            raise ValueError(f"{name} must be finite, got {value!r}")
    elif typ in ("str", str):
        if not isinstance(value, str):
            raise ValueError(f"{name} must be a string, got {value!r}")
        if m["choices"]:
            _core.check_setting_choice(f.name, value)  # the native enum's names, 'auto' where it takes one
        return value
    _core.check_setting_value(f.name, value)  # the declared range (and downscale's 1, 2, 4), natively
    return value


@dataclass(frozen=True)
class Constraint:
    """A rule between fields as cpp/render/settings_rules.def declares it: the `fields` it ties,
    the `rule` as users read it and `why` what breaks otherwise (tested natively:
    Settings.check_constraints)."""
    fields: tuple
    rule: str
    why: str


# Every cross-field rule, read from the native table that RenderSettings::check_rules() tests.
CONSTRAINTS = tuple(Constraint(tuple(r["fields"]), r["rule"], r["why"]) for r in _core.settings_rules())
# Documented, not an error: fade_camera_end <= fade_camera_start switches the camera fade off.

def _declare_fields(cls):
    """Adds every SCHEMA field to `cls`, annotated with its type, before dataclass() reads them."""
    cls.__annotations__ = {}
    for e in SCHEMA:
        cls.__annotations__[e["name"]] = e["type"]
        setattr(cls, e["name"], _setting(e["default"], e["doc"], e["unit"], e["lo"], e["hi"], e["choices"],
                                         e["group"], e["off"], e["place"], e["reference"]))
    # The user passes a render runs and their parameters: not settings of ssrlab's own chain, so
    # not in the schema (their names and ranges are declared by each ssrlab.UserPass). The modules
    # come first: checking them declares their passes, which user_params is checked against.
    cls.__annotations__["user_modules"] = tuple
    cls.user_modules = field(default=(), metadata=dict(
        doc="modules that declare user passes, each imported (once per process) wherever these settings are "
            "used, a sweep's workers included, and its passes registered on the renderer: 'package.module' "
            "(importable there) or a .py path (made absolute), optionally ':attribute' (ssrlab.user_pass."
            "load_module)", unit="", lo=None, hi=None, choices=None, group="user passes", off=None, place="pass",
        reference=False))
    cls.__annotations__["user_passes"] = tuple
    cls.user_passes = field(default=(), metadata=dict(
        doc="user passes this render runs, by name (registered with Renderer.register_pass or declared by "
            "user_modules); each takes its stage's place (a 'trace' replaces the screen-space trace, a "
            "'reflection_filter' follows the resolve) or, without a stage, the place its resources give it", unit="", lo=None, hi=None, choices=None, group="user passes", off=None, place="pass",
        reference=False))
    cls.__annotations__["user_params"] = dict
    cls.user_params = field(default_factory=dict, metadata=dict(
        doc="parameters of user passes, '<pass>.<param>' -> value (absent: the declared default); a sweep or "
            "replace() may name a key directly: replace(**{'<pass>.<param>': value})", unit="", lo=None,
        hi=None, choices=None, group="user passes", off=None, place="pass", reference=False))
    return cls


Settings = dataclass(_declare_fields(Settings))

_FIELDS = {f.name: f for f in fields(Settings)}

_dataclass_init = Settings.__init__


@functools.wraps(_dataclass_init)
def _init(self, *args, **kwargs):
    kwargs = _user_param_keys(kwargs, {})
    _check_names(kwargs)  # a misspelled keyword names the nearest field, not just "unexpected keyword"
    _dataclass_init(self, *args, **kwargs)


Settings.__init__ = _init
_NATIVE_FIELDS = [n for n in _FIELDS if hasattr(_core.RenderSettings(), n)]
# The fields that take 'auto' (decided by resolved()).
_AUTO_FIELDS = tuple(e["name"] for e in SCHEMA if e["choices"] and "auto" in e["choices"])


Settings.__doc__ = "Render settings (every field validated; units in brackets).\n\n" + Settings.describe()
