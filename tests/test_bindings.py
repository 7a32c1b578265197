"""Units and binding points by name: no hand-written shader writes a binding number (samplers and
images take TEXTURE_<NAME> / IMAGE_<NAME> from their pass, blocks BUFFER_<NAME> from
cpp/render/buffer_bindings.def, tests/test_buffer_bindings.py), and a linked
program whose active sampler or image sits at a unit its pass did not bind by name is an error
that names the shader, the uniform and the unit (passes/compute.h, NamedUnits)."""

import re
import sys
from pathlib import Path

import pytest

import ssrlab
from ssrlab import scenes

ROOT = Path(__file__).resolve().parents[1]
SHADERS = ROOT / "shaders"

# Declarations allowed a literal unit, as "path:line" under shaders/ (none).
ALLOWED: set = set()

LITERAL_BINDING = re.compile(r"binding\s*=\s*\d")
# lib/input_fetch.glsl's INPUT_ARRAY / INPUT_2D (name, texture unit, image unit, format).
LITERAL_INPUT = re.compile(r"\bINPUT_(ARRAY|2D)\s*\(\s*\w+\s*,\s*(\d|\w+\s*,\s*\d)")


def literal_units():
    found = []
    for path in sorted(SHADERS.rglob("*")):
        if not path.is_file() or path.suffix not in {".glsl", ".comp", ".frag", ".vert", ".geom"}:
            continue
        rel = path.relative_to(SHADERS).as_posix()
        for n, line in enumerate(path.read_text().splitlines(), 1):
            code = line.split("//", 1)[0]
            if f"{rel}:{n}" in ALLOWED:
                continue
            if LITERAL_BINDING.search(code):
                found.append(f"{rel}:{n}: {line.strip()}")
            elif LITERAL_INPUT.search(code) and "#define" not in code:
                found.append(f"{rel}:{n}: {line.strip()}")
    return found


def test_no_hand_written_shader_writes_a_binding_number():
    found = literal_units()
    assert not found, "units and binding points by name (TEXTURE_<NAME>, IMAGE_<NAME>, BUFFER_<NAME>), not numbers:\n" + "\n".join(found)


def test_the_scan_sees_a_literal_unit(tmp_path, monkeypatch):
    (tmp_path / "passes").mkdir()
    (tmp_path / "passes" / "x.comp").write_text(
        "layout(binding = 3) uniform sampler2D u_a;\n"
        "INPUT_ARRAY(u_b, 0, 1, r32f);\n"
        "layout(binding = TEXTURE_C) uniform sampler2D u_c;\n"
        "layout(std430, binding = 4) buffer B { uint b[]; };\n")
    monkeypatch.setattr(sys.modules[__name__], "SHADERS", tmp_path)
    assert [f.split(": ")[0] for f in literal_units()] == ["passes/x.comp:1", "passes/x.comp:2", "passes/x.comp:4"]


STRAY = """#version 450
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_reflection;
layout(binding = 9) uniform sampler2D u_stray;  // no read is bound there
layout(rgba16f, binding = 0) writeonly uniform image2D o_reflection;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(o_reflection)))) return;
    imageStore(o_reflection, p, texelFetch(u_reflection, p, 0) + texelFetch(u_stray, p, 0));
}
"""


def test_a_sampler_at_a_unit_its_pass_does_not_bind_is_an_error_naming_it(tmp_path):
    shader = tmp_path / "stray.comp"
    shader.write_text(STRAY)
    r = ssrlab.Renderer()
    r.register_pass(ssrlab.UserPass("stray", shader, stage="reflection_filter", reads=("reflection",)))
    s = ssrlab.Settings(width=32, height=32, method="hiz", sampling="vndf", user_passes=("stray",))
    with pytest.raises(ssrlab.ShaderError, match=r"stray\.comp.*'u_stray'.*texture unit 9"):
        r.render(scenes.box_stack(), settings=s)
    # Without it, the same pass renders.
    shader.write_text(STRAY.replace("layout(binding = 9) uniform sampler2D u_stray;", "")
                      .replace(" + texelFetch(u_stray, p, 0)", ""))
    r2 = ssrlab.Renderer()
    r2.register_pass(ssrlab.UserPass("stray", shader, stage="reflection_filter", reads=("reflection",)))
    assert r2.render(scenes.box_stack(), settings=s).color.shape[:2] == (32, 32)
