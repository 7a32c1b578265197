"""Render settings: one validated object with documented units and defaults.

Every field is declared once below with its unit, range and meaning; validation, the
generated documentation (``help(ssrlab.Settings)``) and the conversion to the native
renderer all read that one declaration. An invalid value raises ``ValueError`` naming the
field, at construction and on assignment.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from . import _core


def _setting(default, doc: str, unit: str = "", lo=None, hi=None, choices=None, group: str = "", off=None):
    """A field: `lo`..`hi` inclusive range, or one of `choices`; `off` is an extra allowed
    value outside the range that switches the feature off."""
    return field(
        default=default,
        metadata={"doc": doc, "unit": unit, "lo": lo, "hi": hi, "choices": choices, "group": group, "off": off},
    )


@dataclass
class Settings:
    # -- image -----------------------------------------------------------------------------
    width: int = _setting(640, "image width", "pixels", 1, 16384, group="image")
    height: int = _setting(360, "image height", "pixels", 1, 16384, group="image")

    # -- deep G-buffer (seed 000, 1.5.1 and 2.2) ---------------------------------------------
    layers: int = _setting(
        1, "depth-peeled G-buffer layers; layer i+1 holds the nearest surface strictly behind layer i",
        "layers", 1, 16, group="deep G-buffer")
    backface_culling: bool = _setting(
        False, "cull back faces; off as in the thesis, so back faces populate deeper layers",
        group="deep G-buffer")
    depth_mode: str = _setting(
        "standard", "depth convention: 'standard' (GL, near->0, far->1) or 'reversed_z' (float, near->1, far->0)",
        choices=("standard", "reversed_z"), group="deep G-buffer")

    # -- direct lighting -------------------------------------------------------------------------
    shadow_map_size: int = _setting(
        2048, "shadow-map resolution of the shadow-casting directional light; 0 turns shadows off",
        "texels", 16, 16384, group="lighting", off=0)
    shadow_normal_offset: float = _setting(
        1.5, "receiver offset along its normal against shadow acne", "shadow texels", 0.0, 64.0, group="lighting")
    shadow_pcf_radius: int = _setting(
        1, "percentage-closer filtering kernel radius r: (2r+1)^2 hardware-filtered taps", "taps", 0, 4,
        group="lighting")

    # ---------------------------------------------------------------------------------------------
    def __setattr__(self, name: str, value: Any) -> None:
        # Every assignment, the dataclass __init__'s included, goes through the field's check.
        spec = _FIELDS.get(name)
        if spec is None:
            raise AttributeError(f"Settings has no field {name!r}; fields: {', '.join(_FIELDS)}")
        object.__setattr__(self, name, _check(spec, value))

    def replace(self, **changes) -> "Settings":
        """A copy with some fields changed (validated)."""
        unknown = sorted(set(changes) - set(_FIELDS))
        if unknown:
            raise ValueError(f"unknown Settings field(s): {', '.join(unknown)}; fields: {', '.join(_FIELDS)}")
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "Settings":
        unknown = sorted(set(d) - set(_FIELDS))
        if unknown:
            raise ValueError(f"unknown Settings field(s): {', '.join(unknown)}")
        return cls(**d)

    def key(self) -> str:
        """A stable text key of every field (for caches and result rows)."""
        return json.dumps(self.to_dict(), sort_keys=True)

    def to_native(self) -> "_core.RenderSettings":
        native = _core.RenderSettings()
        for name in _NATIVE_FIELDS:
            setattr(native, name, getattr(self, name))
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
                rng = " | ".join(m["choices"])
            elif m["lo"] is not None:
                rng = f"[{m['lo']}, {m['hi']}]" + (f" or {m['off']} (off)" if m["off"] is not None else "")
            unit = f" {m['unit']}" if m["unit"] else ""
            lines.append(f"  {f.name} = {f.default!r}{unit}  {rng}\n      {m['doc']}")
        return "\n".join(lines).lstrip("\n")


def _check(f: dataclasses.Field, value: Any) -> Any:
    m, name, typ = f.metadata, f"Settings.{f.name}", f.type
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
        if m["choices"] and value not in m["choices"]:
            raise ValueError(f"{name} must be one of {', '.join(map(repr, m['choices']))}, got {value!r}")
        return value
    lo, hi = m["lo"], m["hi"]
    if m["off"] is not None and value == m["off"]:
        return value
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        unit = f" {m['unit']}" if m["unit"] else ""
        off = f" (or {m['off']}: off)" if m["off"] is not None else ""
        raise ValueError(f"{name} must be in [{lo}, {hi}]{unit}{off}, got {value!r}")
    return value


_FIELDS = {f.name: f for f in fields(Settings)}
_NATIVE_FIELDS = [n for n in _FIELDS if hasattr(_core.RenderSettings(), n)]

Settings.__doc__ = "Render settings (every field validated; units in brackets).\n\n" + Settings.describe()
