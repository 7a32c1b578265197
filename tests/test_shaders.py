"""GLSL errors become exceptions that name the shader file and line."""

import shutil

import pytest

import ssrlab
from conftest import small


@pytest.fixture
def shader_copy(tmp_path):
    dst = tmp_path / "shaders"
    shutil.copytree(ssrlab.shader_dir(), dst)
    return dst


def test_compile_error_names_file_and_line(shader_copy):
    lib = shader_copy / "lib" / "brdf.glsl"
    lines = lib.read_text().splitlines()
    target = next(i for i, l in enumerate(lines) if l.startswith("float ggx_D("))
    lines.insert(target + 1, "    this is not glsl;")
    lib.write_text("\n".join(lines) + "\n")
    r = ssrlab.Renderer(shader_dir=shader_copy)
    with pytest.raises(ssrlab.ShaderError) as e:
        r.render(ssrlab.scenes.mirror_test(), settings=small())
    assert e.value.file == "shaders/lib/brdf.glsl"
    assert e.value.line == target + 2  # 1-based line of the inserted text
    assert f"lib/brdf.glsl:{target + 2}" in str(e.value)


def test_missing_include(shader_copy):
    p = shader_copy / "passes" / "composite.comp"
    p.write_text(p.read_text().replace('#include "../lib/environment.glsl"', '#include "../lib/nowhere.glsl"'))
    r = ssrlab.Renderer(shader_dir=shader_copy)
    with pytest.raises(ssrlab.ShaderError, match=r"composite.comp:\d+: #include \"../lib/nowhere.glsl\" not found"):
        r.render(ssrlab.scenes.mirror_test(), settings=small())


def test_compile_every_stage(renderer):
    # The units a pass gives its shader by name (passes/compute.h, NamedUnits), as the passes do.
    peel_units = {"TEXTURE_MATERIAL_BASE_COLOR": 0, "TEXTURE_MATERIAL_METALLIC_ROUGHNESS": 1,
                  "TEXTURE_MATERIAL_NORMAL_MAP": 2, "TEXTURE_DEPTH_PEEL_PREVIOUS_DEPTH": 3,
                  "TEXTURE_SPECULAR_ALBEDO": 13}
    lighting_units = {"TEXTURE_GBUFFER_DEPTH": 0, "TEXTURE_GBUFFER_ALBEDO": 1, "TEXTURE_GBUFFER_NORMAL": 2,
                      "TEXTURE_GBUFFER_MATERIAL": 3, "IMAGE_LIT": 0, "IMAGE_LINEAR_DEPTH": 1}
    for stages, defines in [
        (("passes/depth_peel.vert", "passes/depth_peel.frag"), {"DEPTH_REVERSED_Z": 1, **peel_units}),
        (("passes/lighting.comp",), {"DEPTH_REVERSED_Z": 0, "SHADOWS": 0, **lighting_units}),
    ]:
        assert renderer.compile(*stages, defines=defines) > 0


def test_missing_shader_folder(tmp_path):
    with pytest.raises(ssrlab.ShaderError, match="shader folder not found"):
        ssrlab.Renderer(shader_dir=tmp_path / "nothing")


def test_two_samplers_on_one_texture_unit_are_refused(shader_copy):
    # A pass whose samplers share a unit would silently read one texture for both (or fail at
    # dispatch when their types differ): the program is refused when it is linked, by name.
    p = shader_copy / "passes" / "composite.comp"
    text = p.read_text()
    declared = "layout(binding = TEXTURE_GBUFFER_ALBEDO) uniform sampler2DArray u_albedo;"
    assert text.count(declared) == 1
    p.write_text(text.replace(declared, declared.replace("TEXTURE_GBUFFER_ALBEDO", "TEXTURE_GBUFFER_MATERIAL")))
    r = ssrlab.Renderer(shader_dir=shader_copy)
    with pytest.raises(ssrlab.ShaderError, match=r"composite.comp.*u_(material|albedo) and u_(material|albedo) are "
                                                 r"both bound to texture unit 1"):
        r.render(ssrlab.scenes.mirror_test(), settings=small(composite="pbr"))
