"""Every setting is declared once, in cpp/render/settings_fields.def. ssrlab.Settings, its
describe() and docs page, the native validation and the shaders' uniform block are all made from
that table (read here through _core.settings_schema()), so they cannot disagree; and no other file
declares a setting again, so adding one touches the table, the shader that reads it and a test
(docs/howto/add-a-setting.md)."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import ssrlab
from ssrlab import _core
from ssrlab.settings import fields_markdown

REPO = Path(__file__).resolve().parents[1]
SCHEMA = _core.settings_schema()
BY_NAME = {e["name"]: e for e in SCHEMA}
NUMERIC = [e["name"] for e in SCHEMA if e["lo"] is not None]
ENUMS = [e["name"] for e in SCHEMA if e["type"] == "str"]


def test_the_schema_is_whole():
    assert len(SCHEMA) >= 70 and len(BY_NAME) == len(SCHEMA)  # no field declared twice
    for e in SCHEMA:
        assert e["type"] in ("int", "float", "bool", "str", "bool | str"), e
        assert e["doc"].strip() and e["group"].strip(), e["name"]
        assert e["place"] in ("uniform", "pass"), e["name"]
        if e["type"] in ("int", "float"):
            assert e["lo"] <= e["hi"] and type(e["lo"]) is type(e["hi"]) is type(e["default"]), e["name"]
            assert e["lo"] <= e["default"] <= e["hi"] or e["default"] == e["off"], e["name"]
        else:
            assert e["lo"] is None and e["hi"] is None, e["name"]
        if e["type"] in ("str", "bool | str"):
            assert e["default"] in e["choices"], e["name"]


def test_settings_fields_are_the_schema_fields():
    fields = dataclasses.fields(ssrlab.Settings)
    # the user passes' three fields come last: not settings of ssrlab's own chain (ssrlab.UserPass)
    assert [f.name for f in fields[-3:]] == ["user_modules", "user_passes", "user_params"]
    fields = fields[:-3]
    assert [f.name for f in fields] == [e["name"] for e in SCHEMA]
    native = _core.RenderSettings()
    for f, e in zip(fields, SCHEMA):
        assert f.type == e["type"] and f.default == e["default"] and type(f.default) is type(e["default"]), f.name
        for key in ("doc", "unit", "lo", "hi", "choices", "group", "off", "place", "reference"):
            assert f.metadata[key] == e[key], (f.name, key)
        assert getattr(native, f.name) == pytest.approx(e["native_default"], rel=1e-7), f.name
    # 'auto' values resolve to choices the native side knows.
    for device in ("cpu", "gpu"):
        ssrlab.Settings().to_native(device)
    # The converged reference keys on the fields the schema flags.
    assert set(ssrlab.reference._CONVERGED_KEY_FIELDS) == {e["name"] for e in SCHEMA if e["reference"]}
    assert {"width", "height", "max_distance", "origin_bias"} <= set(ssrlab.reference._CONVERGED_KEY_FIELDS)


def test_every_field_is_in_describe_help_the_docs_and_the_native_docstrings():
    text, help_text, page = ssrlab.Settings.describe(), ssrlab.Settings.__doc__, fields_markdown()
    for e in SCHEMA:
        name = e["name"]
        assert re.search(rf"^  {name} = {re.escape(repr(e['default']))}", text, re.M), name
        assert e["doc"] in text and e["doc"] in help_text, name
        assert f"| `{name}` | `{e['default']!r}` |" in page, name
        doc = getattr(_core.RenderSettings, name).__doc__
        assert doc.startswith(f"ssrlab.Settings.{name}") and e["doc"] in doc, name
        if e["unit"]:
            assert f"[{e['unit']}]" in doc, name
    # The docs build writes the page from the same function.
    assert "fields_markdown()" in (REPO / "docs" / "gen_pages.py").read_text()
    assert "api/settings-fields.md" in (REPO / "mkdocs.yml").read_text()


def _with_partners(name: str, value) -> dict:
    """`name` = value, with the fields a constraint ties to it moved out of the way."""
    kw = {name: value}
    if name in ("hiz_start_level", "hiz_stop_level") and value > 12:
        kw["hiz_max_level"] = 15
    if name == "hiz_max_level" and value < 1:
        kw["hiz_start_level"] = 0
    if name == "fade_distance_start" and value > 0:
        kw["fade_distance_end"] = 1e7 if value < 1e7 else None
    if name == "fade_distance_end" and value > 0:
        kw["fade_distance_start"] = value / 2
    if kw.get("fade_distance_end", 0) is None:
        pytest.skip("fade_distance_start at 1e7 leaves no room for an end > start")
    return kw


def _outside(e: dict, end: str):
    """The nearest value beyond the declared bound `end` ('lo' or 'hi') that is not 'off'."""
    v, sign = e[end], -1 if end == "lo" else 1
    if e["type"] == "int":
        out = v + sign
        return out + sign if out == e["off"] else out
    return v + sign * max(abs(v), 1e-3) * 1e-3


@pytest.mark.parametrize("end", ["lo", "hi"])
@pytest.mark.parametrize("name", NUMERIC)
def test_numeric_fields_are_validated_at_their_declared_bounds(name, end):
    e = BY_NAME[name]
    # The bound itself: accepted by Settings and by the native validation.
    kw = _with_partners(name, e[end])
    ssrlab.Settings(**kw).to_native()
    # Just outside: a ValueError naming the field, its range and unit, in Python and natively.
    bad = _outside(e, end)
    unit = f" {e['unit']}" if e["unit"] else ""
    message = (rf"Settings\.{name} must be in \[{re.escape(str(e['lo']))}, {re.escape(str(e['hi']))}\]"
               rf"{re.escape(unit)}")
    if name == "downscale":  # 1, 2 or 4: said before the range
        message = r"Settings\.downscale must be 1, 2 or 4"
    with pytest.raises(ValueError, match=message):
        ssrlab.Settings(**{name: bad})
    native = ssrlab.Settings(**kw).to_native()
    try:
        setattr(native, name, bad)
    except TypeError:  # a negative value for an unsigned field is refused by the binding itself
        assert e["lo"] == 0 and end == "lo"
        return
    with pytest.raises(ValueError, match=message):  # the same words: Settings forwards the native check
        native.validate()
    if e["off"] is not None:  # the 'off' value outside the range is allowed
        ssrlab.Settings(**{name: e["off"]}).to_native()


@pytest.mark.parametrize("name", ENUMS)
def test_enum_fields_refuse_other_names_in_python_and_natively(name):
    for choice in BY_NAME[name]["choices"]:
        ssrlab.Settings(**_with_partners(name, choice))
    with pytest.raises(ValueError, match=rf"Settings\.{name} must be one of"):
        ssrlab.Settings(**{name: "no_such_choice"})
    with pytest.raises(ValueError, match=rf"Settings\.{name} must be one of"):
        setattr(_core.RenderSettings(), name, "no_such_choice")


def _glsl_members() -> list[tuple[str, str]]:
    glsl = _core.ssr_settings_glsl()
    block = glsl[glsl.index("uniform SsrSettings {"):glsl.index("} ssr;")]
    return re.findall(r"^\s+(int|uint|float) (\w+);", block, re.M)


def test_uniform_fields_and_only_they_are_in_the_glsl_block():
    members = _glsl_members()
    uniform = [e for e in SCHEMA if e["place"] == "uniform"]
    # The derived members (the ray grid's size) first, then the settings in schema order.
    assert [n for _, n in members[:2]] == ["trace_width", "trace_height"]
    assert [n for _, n in members[2:]] == [e["name"] for e in uniform]
    for (glsl_type, name), e in zip(members[2:], uniform):
        expected = "float" if e["type"] == "float" else "uint" if name == "seed" else "int"
        assert glsl_type == expected, name
    names = {n for _, n in members}
    assert not names & {e["name"] for e in SCHEMA if e["place"] == "pass"}
    # Members no shader reads are gone from the block.
    assert not names & {"composite_mode", "glossy", "composite"}
    # Each enum setting in the block brings a constant per choice, valued as the C++ enum.
    glsl = _core.ssr_settings_glsl()
    for e in uniform:
        if e["type"] == "str":
            for choice in e["choices"]:
                assert re.search(rf"^const int {name_constant(e['name'], choice)} = \d+;$", glsl, re.M), choice
    assert "const int SAMPLING_VNDF = 2;" in glsl  # the value the tracers' sampler switches on
    assert '#include "generated/ssr_settings_block.glsl"' in (REPO / "shaders/lib/ssr_settings.glsl").read_text()


def name_constant(field: str, choice: str) -> str:
    return f"{field}_{choice}".upper()


def test_every_uniform_member_is_read_by_a_shader():
    """A member no shader reads is an upload for nothing: each one of the block is named as
    ssr.<name> by some shader (or, for the enum switches the tracers compile in, by the pass)."""
    sources = "\n".join(p.read_text() for p in (REPO / "shaders").rglob("*") if p.suffix in (".glsl", ".comp",
                                                                                              ".vert", ".frag"))
    compiled_in = {"sampling", "noise", "hammersley"}  # RAY_SAMPLING etc., cpp/passes/trace_pass.cpp
    unread = [n for _, n in _glsl_members() if f"ssr.{n}" not in sources and n not in compiled_in]
    assert not unread, unread


# -- the recipe: one declaration, no second place -----------------------------------------------

def _source(path: str) -> str:
    return (REPO / path).read_text()


def test_no_other_file_declares_a_setting_again():
    """The files a setting used to be written into (struct, ranges, bindings, uniform struct and
    upload, GLSL block, Python declarations, the reference's key fields, the stubs) name no
    setting's declaration any more: adding one is a row of settings_fields.def."""
    header = _source("cpp/render/settings.h")
    uniforms_h = _source("cpp/render/ssr_uniforms.h")
    uniforms_cpp = _source("cpp/render/ssr_uniforms.cpp")
    validation = _source("cpp/render/settings.cpp")
    bindings = _source("cpp/bindings/bind_render.cpp")
    glsl = _source("shaders/lib/ssr_settings.glsl")
    python = _source("python/ssrlab/settings.py")
    reference = _source("python/ssrlab/truth/reference.py")
    key_fields = reference[reference.index("_CONVERGED_KEY_FIELDS ="):]
    key_fields = key_fields[:key_fields.index("\n\n")]
    stubs = _source("python/ssrlab/_core.pyi")
    stub_class = stubs[stubs.index("class RenderSettings:"):]
    stub_class = stub_class[:stub_class.index("\nclass ", 1)]
    for name in BY_NAME:
        assert not re.search(rf"^\s+[\w:]+ {name}\s*(=|;|,)", header, re.M), f"settings.h declares {name}"
        assert not re.search(rf"\b{name}\b", uniforms_h), f"ssr_uniforms.h names {name}"
        assert not re.search(rf"su\.{name}\b", uniforms_cpp), f"ssr_uniforms.cpp copies {name} by hand"
        assert not re.search(rf"range\(\s*{name}\b|check_range\(\s*\w*\(?{name}\b", validation), name
        assert not re.search(rf'def_(readwrite|property)\(\s*"{name}"', bindings), f"bind_render.cpp binds {name}"
        assert not re.search(rf"\b{name}\b", glsl), f"lib/ssr_settings.glsl declares {name}"
        assert not re.search(rf"^\s+{name}\s*:", python, re.M), f"settings.py declares {name}"
        assert f'"{name}"' not in key_fields, f"reference.py lists {name} among the converged key fields"
        assert not re.search(rf"def {name}\(", stub_class), f"the stubs list RenderSettings.{name}"
    # The Python ranges are the schema's: no bound is written in settings.py.
    assert python.count("_setting(") == 2  # its definition and the one call that reads SCHEMA


@pytest.mark.parametrize("glossy", ["cone", "blur_mips"])
def test_frame_settings_say_the_one_mirror_ray_cone_and_blurred_mips_trace(glossy):
    r = ssrlab.Renderer("cpu")
    asked = ssrlab.Settings(width=64, height=36, method="hiz", glossy=glossy, rays_per_pixel=4, sampling="vndf")
    frame = r.render(ssrlab.scenes.box_stack(floor_roughness=0.3), settings=asked)
    assert frame.settings.rays_per_pixel == 1 and frame.settings.sampling == "mirror"
    assert frame.rays.hit_layer.shape[0] == 1  # the rays the frame holds are the rays its settings say
    same = r.render(ssrlab.scenes.box_stack(floor_roughness=0.3), settings=frame.settings)
    assert np.array_equal(same.color, frame.color)
