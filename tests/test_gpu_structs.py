"""The records the host uploads and the shaders read (frame constants, objects, materials, lights,
the BVH's nodes and triangles)
are generated from one table, cpp/render/gpu_structs.def: the GLSL the shaders include must lay
each member where the C++ struct has it, as the GL driver itself reports."""

import re
import shutil

import pytest

import ssrlab
from ssrlab import _core

LAYOUTS = {s["cpp"]: s for s in _core.gpu_struct_layouts()}


def test_every_shared_record_is_in_the_table():
    assert {s: (LAYOUTS[s]["block"], LAYOUTS[s]["binding"], LAYOUTS[s]["layout"]) for s in LAYOUTS} == {
        "FrameUniforms": ("FrameUniforms", 0, "std140"),
        "GpuObject": ("Objects", 1, "std430"),
        "GpuMaterial": ("Materials", 2, "std430"),
        "GpuLight": ("Lights", 3, "std430"),
        "BvhNode": ("BvhNodes", 5, "std430"),
        "BvhTriangle": ("BvhTriangles", 6, "std430"),
    }


def test_generated_glsl_declares_the_members_in_table_order():
    glsl = _core.gpu_struct_glsl()
    for s in LAYOUTS.values():
        text = glsl[f"generated/{s['block']}.glsl"]
        declared = re.findall(r"^    (\w+) (\w+)(?:\[(\d+)\])?;$", text, re.M)
        assert declared == [(m["type"], m["name"], str(m["count"]) if m["count"] else "") for m in s["members"]]
        assert f"binding = {s['binding']})" in text


def test_no_shader_declares_a_generated_record_by_hand():
    # The libraries include the generated files; no hand-written copy is left to drift.
    root = ssrlab.shader_dir()
    by_hand = []
    for f in sorted(p for p in root.rglob("*") if p.suffix in (".glsl", ".comp", ".vert", ".frag")):
        text = f.read_text()
        for s in LAYOUTS.values():
            if re.search(rf"\b(uniform|buffer) {s['block']}\b", text) or (
                    s["glsl_struct"] and re.search(rf"\bstruct {s['glsl_struct']}\b", text)):
                by_hand.append((f.relative_to(root).as_posix(), s["block"]))
    assert by_hand == []
    lib = root / "lib"
    assert '#include "generated/FrameUniforms.glsl"' in (lib / "frame_uniforms.glsl").read_text()
    assert '#include "generated/Lights.glsl"' in (lib / "lights.glsl").read_text()
    assert '#include "generated/Objects.glsl"' in (lib / "scene_data.glsl").read_text()
    assert '#include "generated/Materials.glsl"' in (lib / "scene_data.glsl").read_text()
    assert '#include "generated/BvhNodes.glsl"' in (lib / "bvh.glsl").read_text()
    assert '#include "generated/BvhTriangles.glsl"' in (lib / "bvh.glsl").read_text()


PROBE = """#version 450 core
layout(local_size_x = 1) in;
#include "../lib/frame_uniforms.glsl"
#include "../lib/lights.glsl"
#include "../lib/scene_data.glsl"
#include "../lib/bvh.glsl"
layout(std430, binding = BUFFER_TEXELS) writeonly buffer Texels { vec4 texels[]; };  // the read-back's block
void main() {
    texels[0] = frame.viewport + lights[0].radiance + materials[0].base_color + vec4(objects[0].material) +
                bvh_nodes[0].hi + bvh_triangles[0].v2;
}
"""


@pytest.fixture
def probe(tmp_path):
    root = tmp_path / "shaders"
    shutil.copytree(ssrlab.shader_dir(), root)
    (root / "tools" / "struct_probe.comp").write_text(PROBE)
    r = ssrlab.Renderer(shader_dir=root)
    return r, r.compile("tools/struct_probe.comp")


def member_name(driver_name: str) -> str:
    # "FrameUniforms.view", "lights[0].shadow", "materials[0].uv_transform[0]" -> the member's name.
    return re.sub(r"\[0\]$", "", driver_name.rsplit(".", 1)[-1])


@pytest.mark.parametrize("cpp", sorted(LAYOUTS))
def test_driver_lays_out_the_generated_glsl_as_the_cpp_struct(probe, cpp):
    r, program = probe
    s = LAYOUTS[cpp]
    got = r.block_layout(program, s["block"])
    members = {member_name(n): v for n, v in got["members"].items()}
    assert {m["name"]: m["offset"] for m in s["members"]} == {n: v["offset"] for n, v in members.items()}
    if got["storage"]:  # an array of records steps by the C++ struct's size
        assert {v["top_level_stride"] for v in members.values()} == {s["size"]}
    else:
        assert got["data_size"] == s["size"]
