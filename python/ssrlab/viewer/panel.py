"""The settings panel, generated from the settings schema (cpp/render/settings_fields.def through
ssrlab.Settings): one folder per group, one control per field with its unit, range and default in
its hint, enums as choices; and the registered user passes with their parameters.

The panel holds what the page asks for; the viewer applies it only when ssrlab.Settings accepts
the whole combination (the field checks and the constraints between fields), and shows the
ValueError's words otherwise, keeping the last settings it rendered with.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable

from ..settings import Settings

# Fields the page itself decides: the image follows the page's canvas (and the progressive scale).
PAGE_FIELDS = ("width", "height")
# Fields not shown as controls: the user passes are their own folder.
PASS_FIELDS = ("user_modules", "user_passes", "user_params")


def _hint(f: dataclasses.Field) -> str:
    m = f.metadata
    rng = ""
    if m["choices"]:
        rng = "one of " + ", ".join(map(str, (("True", "False") if f.type == "bool | str" else ()) + tuple(m["choices"])))
    elif m["lo"] is not None:
        rng = f"[{m['lo']}, {m['hi']}]" + (f" or {m['off']} (off)" if m["off"] is not None else "")
    unit = f" {m['unit']}" if m["unit"] else ""
    return f"{m['doc']} (default {f.default!r}{unit}{'; ' + rng if rng else ''})"


_BOOL_CHOICES = ("True", "False")


def _to_widget(f: dataclasses.Field, value: Any) -> Any:
    if f.type == "bool | str":
        return value if isinstance(value, str) else str(bool(value))
    return value


def _from_widget(f: dataclasses.Field, value: Any) -> Any:
    if f.type == "bool | str":
        return {"True": True, "False": False}.get(value, value)
    if f.type in ("int", int) and isinstance(value, float) and value.is_integer():
        return int(value)
    return value


class SettingsPanel:
    """Controls for every Settings field, under `parent` (a viser GuiApi); `changed()` is called
    after any control changes, with the settings the panel asks for (or the ValueError saying why
    they are refused)."""

    def __init__(self, gui, settings: Settings, user_passes: dict, changed: Callable[[Settings | None, str], None]):
        self._gui = gui
        self._changed = changed
        self._syncing = False
        self._controls: dict[str, Any] = {}
        self._fields = {f.name: f for f in dataclasses.fields(Settings)}
        self._pass_controls: dict[str, Any] = {}
        self._param_controls: dict[str, Any] = {}
        group, folder = None, None
        for f in dataclasses.fields(Settings):
            if f.name in PAGE_FIELDS or f.name in PASS_FIELDS:
                continue
            m = f.metadata
            if m["group"] != group:
                group = m["group"]
                folder = gui.add_folder(f"settings: {group}", expand_by_default=False)
            with folder:
                self._controls[f.name] = self._control(f, getattr(settings, f.name))
        if user_passes:
            with gui.add_folder("user passes", expand_by_default=True):
                for name, p in user_passes.items():
                    c = gui.add_checkbox(f"run {name}", initial_value=name in settings.user_passes, hint=p.doc or p.place)
                    c.on_update(self._on_update)
                    self._pass_controls[name] = c
                    for param in p.params:
                        key = f"{name}.{param.name}"
                        value = settings.user_params.get(key, param.default)
                        rng = f" [{param.lo}, {param.hi}]" if param.lo is not None or param.hi is not None else ""
                        hint = f"{param.doc} (default {param.default!r}{rng})"
                        if param.type == "bool":
                            pc = gui.add_checkbox(key, initial_value=bool(value), hint=hint)
                        else:
                            step = 1 if param.type == "int" else None
                            pc = gui.add_number(key, initial_value=value, min=param.lo, max=param.hi, step=step, hint=hint)
                        pc.on_update(self._on_update)
                        self._param_controls[key] = pc

    def _control(self, f: dataclasses.Field, value):
        m, gui = f.metadata, self._gui
        hint = _hint(f)
        if f.type == "bool | str":
            c = gui.add_dropdown(f.name, _BOOL_CHOICES + tuple(m["choices"]), initial_value=_to_widget(f, value),
                                 hint=hint)
        elif f.type in ("bool", bool):
            c = gui.add_checkbox(f.name, initial_value=bool(value), hint=hint)
        elif m["choices"]:
            c = gui.add_dropdown(f.name, tuple(m["choices"]), initial_value=value, hint=hint)
        elif f.type in ("int", int):
            # The range goes into the hint, not the control: a value outside it is the settings'
            # to refuse, with its own words, not the browser's to clamp silently.
            c = gui.add_number(f.name, initial_value=int(value), step=1, hint=hint)
        else:
            c = gui.add_number(f.name, initial_value=float(value), step=_step(m), hint=hint)
        c.on_update(self._on_update)
        return c

    def values(self) -> dict:
        """What the controls ask for, as Settings fields."""
        out = {name: _from_widget(self._fields[name], c.value) for name, c in self._controls.items()}
        if self._pass_controls:
            out["user_passes"] = tuple(n for n, c in self._pass_controls.items() if c.value)
            out["user_params"] = {k: c.value for k, c in self._param_controls.items()}
        return out

    def _on_update(self, _event) -> None:
        if self._syncing:
            return
        self._changed(self.values())

    def show(self, settings: Settings) -> None:
        """Sets every control to `settings` without asking for a render."""
        self._syncing = True
        try:
            for name, c in self._controls.items():
                c.value = _to_widget(self._fields[name], getattr(settings, name))
            for name, c in self._pass_controls.items():
                c.value = name in settings.user_passes
            for key, c in self._param_controls.items():
                if key in settings.user_params:
                    c.value = settings.user_params[key]
        finally:
            self._syncing = False


def _step(m) -> float:
    lo, hi = m["lo"], m["hi"]
    if lo is None or hi is None:
        return 0.01
    span = float(hi) - float(lo)
    return 0.001 if span <= 1.0 else 0.01 if span <= 10.0 else 0.1
