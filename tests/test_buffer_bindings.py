"""Every uniform and storage block's binding point comes from one table, cpp/render/buffer_bindings.def:
the host binds with its k<Block>Binding, the shaders declare with its BUFFER_<NAME> defines (never a
number), and a linked program whose block is elsewhere, or has no row, is refused by name."""

import re
import shutil

import pytest

import ssrlab
from ssrlab import _core

TABLE = _core.buffer_bindings()
BY_BLOCK = {b["block"]: b for b in TABLE}
BY_DEFINE = {b["define"]: b for b in TABLE}
SHADER_SUFFIXES = (".glsl", ".comp", ".vert", ".frag", ".geom")
# A line that declares a uniform or storage block (not a sampler or an image: those name units).
BLOCK_LINE = re.compile(r"\blayout\s*\(.*\b(std430|std140)\b|\bbuffer\s+[A-Z]\w*\s*(\{|$)|\buniform\s+[A-Z]\w*\s*(\{|$)")


def shader_files():
    root = ssrlab.shader_dir()
    return root, sorted(p for p in root.rglob("*") if p.is_file() and p.suffix in SHADER_SUFFIXES)


def test_no_hand_written_shader_writes_a_block_binding_as_a_number():
    root, files = shader_files()
    literal = []
    for f in files:
        for i, line in enumerate(f.read_text().splitlines(), 1):
            code = line.split("//", 1)[0]
            if BLOCK_LINE.search(code) and re.search(r"\bbinding\s*=\s*\d", code):
                literal.append(f"shaders/{f.relative_to(root).as_posix()}:{i}: {line.strip()}")
    assert literal == [], "\n".join(literal)


def test_every_block_of_the_shader_tree_uses_its_own_row():
    # binding = BUFFER_X on block Y: X must be Y's row (a define of another block's row would
    # put it at a point shared by chance, which the link-time check would not see if they agree).
    root, files = shader_files()
    decl = re.compile(r"\bbinding\s*=\s*(BUFFER_\w+)\b[^;]*?\b(buffer|uniform)\s+(\w+)")
    wrong, seen = [], set()
    for f in files:
        for i, line in enumerate(f.read_text().splitlines(), 1):
            m = decl.search(line)
            if not m:
                continue
            define, interface, block = m.groups()
            seen.add(block)
            row = BY_BLOCK.get(block)
            if row is None or row["define"] != define or row["interface"] != ("storage" if interface == "buffer"
                                                                              else "uniform"):
                wrong.append(f"shaders/{f.relative_to(root).as_posix()}:{i}: {block} with {define}")
    assert wrong == [], "\n".join(wrong)
    # Every row is used: by a hand-written block or by a generated one (gpu_structs.def, settings).
    generated = {s["block"] for s in _core.gpu_struct_layouts()} | {"SsrSettings"}
    assert set(BY_BLOCK) - seen - generated == set()


def test_the_table_is_consistent():
    assert len(BY_BLOCK) == len(TABLE) and len(BY_DEFINE) == len(TABLE)
    for b in TABLE:
        assert b["define"] == "BUFFER_" + re.sub(r"(?<!^)(?=[A-Z])", "_", b["block"]).upper(), b
        assert b["interface"] in ("storage", "uniform") and b["binding"] >= 0 and b["doc"], b
    # The generated records' blocks are bound where the table says.
    for s in _core.gpu_struct_layouts():
        row = BY_BLOCK[s["block"]]
        assert (row["binding"], row["interface"]) == (s["binding"], "uniform" if s["layout"] == "std140" else "storage")
    assert f"binding = {BY_BLOCK['SsrSettings']['binding']}) uniform SsrSettings" in _core.ssr_settings_glsl()
    glsl = _core.buffer_bindings_glsl()
    assert all(f"#define {b['define']} {b['binding']}\n" in glsl for b in TABLE)


@pytest.fixture
def shader_copy(tmp_path):
    dst = tmp_path / "shaders"
    shutil.copytree(ssrlab.shader_dir(), dst)
    return dst


PROBE = """#version 450 core
layout(local_size_x = 1) in;
{block}
layout(std430, binding = BUFFER_TEXELS) writeonly buffer Texels {{ vec4 texels[]; }};
void main() {{ texels[0] = {read}; }}
"""


def test_a_block_at_another_binding_is_refused_naming_its_file_and_line(shader_copy):
    p = shader_copy / "passes" / "clear_buffer.comp"
    lines = p.read_text().splitlines()
    at = next(i for i, l in enumerate(lines) if "buffer ClearTarget" in l)
    lines[at] = lines[at].replace("binding = BUFFER_CLEAR_TARGET", "binding = BUFFER_KEPT_FRAGMENTS")
    p.write_text("\n".join(lines) + "\n")
    r = ssrlab.Renderer(shader_dir=shader_copy)
    with pytest.raises(ssrlab.ShaderError) as e:
        r.compile("passes/clear_buffer.comp")
    assert e.value.file == "shaders/passes/clear_buffer.comp" and e.value.line == at + 1
    want = BY_BLOCK["ClearTarget"]
    assert (f"shaders/passes/clear_buffer.comp:{at + 1}: storage block ClearTarget is at binding "
            f"{BY_BLOCK['KeptFragments']['binding']}, where cpp/render/buffer_bindings.def puts it at "
            f"{want['binding']}: declare it with binding = {want['define']}") in str(e.value)


def test_a_library_block_is_located_in_its_library_file(shader_copy):
    (shader_copy / "tools" / "probe.comp").write_text(PROBE.format(
        block='#include "../lib/scene_textures.glsl"', read="vec4(image_texels[0] + uint(image_info[0].x))"))
    lib = shader_copy / "lib" / "scene_textures.glsl"
    lines = lib.read_text().splitlines()
    at = next(i for i, l in enumerate(lines) if "buffer ImageInfo" in l)
    lines[at] = lines[at].replace("binding = BUFFER_IMAGE_INFO", "binding = 3")
    lib.write_text("\n".join(lines) + "\n")
    r = ssrlab.Renderer(shader_dir=shader_copy)
    with pytest.raises(ssrlab.ShaderError, match=rf"shaders/lib/scene_textures.glsl:{at + 1}: storage block "
                                                 r"ImageInfo is at binding 3.*program shaders/tools/probe.comp"):
        r.compile("tools/probe.comp")


def test_a_block_with_no_row_is_refused_in_the_shader_tree(shader_copy):
    (shader_copy / "tools" / "probe.comp").write_text(PROBE.format(
        block="layout(std430, binding = 3) readonly buffer Unlisted { vec4 unlisted[]; };", read="unlisted[0]"))
    r = ssrlab.Renderer(shader_dir=shader_copy)
    with pytest.raises(ssrlab.ShaderError, match=r"shaders/tools/probe.comp:3: storage block Unlisted \(binding 3\) "
                                                 r"is not in cpp/render/buffer_bindings.def"):
        r.compile("tools/probe.comp")


def test_a_uniform_block_of_a_storage_row_is_refused(shader_copy):
    (shader_copy / "tools" / "probe.comp").write_text(PROBE.format(
        block="layout(std140, binding = BUFFER_BVH_NODES) uniform BvhNodes { vec4 node; };", read="node"))
    r = ssrlab.Renderer(shader_dir=shader_copy)
    with pytest.raises(ssrlab.ShaderError, match=r"probe.comp:3: uniform block BvhNodes is a storage block"):
        r.compile("tools/probe.comp")


def test_a_user_shader_may_declare_its_own_blocks_but_not_move_the_tables(tmp_path, renderer):
    # A shader outside the shader tree (a user pass's) gets the defines and may bind blocks of its
    # own names where its host puts them; a name of the table keeps its binding.
    own = tmp_path / "own.comp"
    own.write_text(PROBE.format(block="layout(std430, binding = 3) readonly buffer Mine { vec4 mine[]; };",
                                read="mine[0]"))
    assert renderer.compile(str(own)) > 0
    moved = tmp_path / "moved.comp"
    moved.write_text(PROBE.format(block="layout(std430, binding = 3) readonly buffer BvhNodes { vec4 nodes[]; };",
                                  read="nodes[0]"))
    with pytest.raises(ssrlab.ShaderError) as e:
        renderer.compile(str(moved))
    assert e.value.file == str(moved) and e.value.line == 3
    assert "storage block BvhNodes is at binding 3" in str(e.value)

