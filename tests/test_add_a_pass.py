"""A new pass added the way the built-in ones are: one C++ file with its registration line, one
shader, no other file touched (docs/howto/add-a-pass.md). The file is compiled with the flags of
this checkout's own build and linked with its objects into a module of its own, which a fresh
process imports: the renderer orders the pass after the writer of what it reads, binds its
texture and image by name, and Frame reads what it wrote.

The build's objects come from the package's build folder (build/<wheel tag>, which `./run.sh
test` leaves); where there is none the test says so and skips."""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import subprocess
import sys

import pytest

from conftest import REPO

PASS_CPP = r"""
// reflection_luma: the luminance of the frame's reflection (Rec. 709 weights), in a texture of its own.
#include "passes/compute.h"
#include "render/pass_registry.h"

namespace ssr {
namespace {

class ReflectionLumaPass : public RenderPass {
public:
    std::string name() const override { return "reflection_luma"; }
    bool runs(const RenderSettings& s, const FrameFacts& f) const override { return f.reflections; }
    std::vector<std::string> inputs(const RenderSettings&, const FrameFacts&) const override { return {"reflection"}; }
    std::vector<ResourceDesc> outputs(const RenderSettings& s) const override {
        return {ResourceDesc{"reflection_luma", GL_R32F, s.width, s.height, 0, 1}.with(
            {{"luma", "luminance", 0, 1, ChannelDecode::Value, "Rec. 709 luminance of the reflection"}})};
    }
    void execute(FrameContext& ctx) override {
        const NamedUnits units{{"reflection"}, {{"reflection_luma", GL_WRITE_ONLY}}};
        Defines d = ctx.defines;
        units.add_unit_defines(d);
        glUseProgram(ctx.shaders.program({"passes/reflection_luma.comp"}, d));
        units.bind_by_name(ctx.resources);
        dispatch_2d(ctx.settings.width, ctx.settings.height, 1, 8, 8);
    }
};

}  // namespace

SSR_REGISTER_PASS(ReflectionLumaPass());

}  // namespace ssr
"""

PASS_COMP = r"""#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = TEXTURE_REFLECTION) uniform sampler2D u_reflection;
layout(binding = IMAGE_REFLECTION_LUMA, r32f) writeonly uniform image2D o_luma;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, textureSize(u_reflection, 0)))) return;
    vec3 c = texelFetch(u_reflection, p, 0).rgb;
    imageStore(o_luma, p, vec4(dot(c, vec3(0.2126, 0.7152, 0.0722)), 0.0, 0.0, 1.0));
}
"""

CHECK = r"""
import json, sys
import numpy as np
import ssrlab
shaders = sys.argv[1]
r = ssrlab.Renderer("cpu", shader_dir=shaders)
scene = ssrlab.scenes.load("hall")
settings = ssrlab.Settings(width=64, height=36)
frame = r.render(scene, settings=settings)
chain = r.chain(settings, scene)
luma = frame.read("reflection_luma")
view = frame.view("luma")
reflection = frame.read("reflection")
want = reflection[..., :3].astype(np.float64) @ np.array([0.2126, 0.7152, 0.0722])
print(json.dumps({
    "passes": frame.passes,
    "chain": [[p.name, list(p.inputs), list(p.outputs)] for p in chain],
    "derived": ssrlab.chain.derive(settings, scene, device="cpu").names,
    "max_error": float(np.abs(luma[..., 0] - want).max()),
    "mean_luma": float(luma[..., 0].mean()),
    "shape": list(luma.shape),
    "view_equals_read": bool(np.array_equal(view.luminance, luma[0, ..., 0])),
    "channels": [[c["texture"], c["name"], c["doc"]] for c in view.channels],
}))
"""


def build_folder():
    """This checkout's build folder (build/<wheel tag>/build.ninja compiling this checkout's cpp/)."""
    for ninja in sorted((REPO / "build").glob("*/build.ninja")):
        if str(REPO / "cpp" / "passes") in ninja.read_text(errors="replace"):
            return ninja.parent
    return None


def ninja_commands(folder) -> list[str]:
    ninja = shutil.which("ninja") or shutil.which("ninja-build")
    if ninja is None:
        try:
            import ninja as ninja_module  # the build's own ninja, from PyPI

            ninja = os.path.join(ninja_module.BIN_DIR, "ninja")
        except ImportError:
            return []
    r = subprocess.run([ninja, "-C", str(folder), "-t", "commands"], capture_output=True, text=True, timeout=60)
    return r.stdout.splitlines() if r.returncode == 0 else []


def test_a_pass_added_in_one_file_and_one_shader_runs_in_its_place(tmp_path):
    folder = build_folder()
    if folder is None:
        pytest.skip("no build folder of this checkout (build/<wheel tag>, which ./run.sh test leaves)")
    commands = ninja_commands(folder)
    compile_taa = next((c for c in commands if "-c " in c and c.rstrip().endswith("cpp/passes/taa.cpp")), None)
    link = next((c for c in commands if " -shared " in c and "_core" in c), None)
    if compile_taa is None or link is None:
        pytest.skip("the build folder's ninja does not list the module's compile and link commands")
    objects = re.findall(r"CMakeFiles/_core\.dir/\S+\.o", link)
    if not objects or not all((folder / o).is_file() for o in objects):
        pytest.skip("the build folder holds no objects of the module (cleaned after the install)")

    # The pass: one C++ file and one shader, beside copies of nothing else.
    source = tmp_path / "reflection_luma.cpp"
    source.write_text(PASS_CPP)
    shaders = tmp_path / "shaders"
    shutil.copytree(REPO / "shaders", shaders)
    (shaders / "passes" / "reflection_luma.comp").write_text(PASS_COMP)

    # Compiled as any pass of the build is (taa.cpp's command, dependency-file options left out),
    # linked with the build's own objects into a module of its own.
    args = [a for a in shlex.split(compile_taa) if a not in ("-MD",)]
    for flag in ("-MT", "-MF", "-o"):
        while flag in args:
            i = args.index(flag)
            del args[i:i + 2]
    args = [str(source) if a.endswith("cpp/passes/taa.cpp") else a for a in args]
    obj = tmp_path / "reflection_luma.o"
    args = [a for a in args if a != "-c"] + ["-c", "-o", str(obj)]
    args = [a for a in args if a != str(source)] + [str(source)]
    r = subprocess.run(args, cwd=folder, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-4000:]
    package = tmp_path / "pkg" / "ssrlab"
    shutil.copytree(REPO / "python" / "ssrlab", package, symlinks=False,
                    ignore=shutil.ignore_patterns("_core*.so", "shaders", "__pycache__"))
    module = next(iter(re.findall(r"-o (\S+\.so)", link)))
    # ninja's line is ": && <link> && <post-link steps> && :"; the link alone is what is needed.
    linked = shlex.split(next(part for part in link.split(" && ") if " -shared " in part))
    linked[linked.index("-o") + 1] = str(package / os.path.basename(module))
    linked.append(str(obj))
    r = subprocess.run(linked, cwd=folder, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-4000:]

    env = dict(os.environ, PYTHONPATH=str(tmp_path / "pkg"))
    r = subprocess.run([sys.executable, "-c", CHECK, str(shaders)], capture_output=True, text=True, timeout=300,
                       env=env, cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-4000:]
    got = json.loads(r.stdout.strip().splitlines()[-1])
    passes = got["passes"]
    # Ordered by its declaration: after every pass that writes or rewrites the reflection.
    assert "reflection_luma" in passes
    writers = [p for p, ins, outs in got["chain"] if "reflection" in outs and p != "reflection_luma"]
    assert writers and all(passes.index(w) < passes.index("reflection_luma") for w in writers), passes
    assert [p for p, _, _ in got["chain"]] == passes == got["derived"]
    assert ["reflection_luma", ["reflection"], ["reflection_luma"]] in got["chain"]
    # Bound by name and read back by Frame: the luminance of the reflection it read.
    assert got["max_error"] < 1e-5 and got["mean_luma"] > 0.0, got
    # Its channel, as it declared it, is a view of the frame like the G-buffer's.
    assert got["channels"] == [["reflection_luma", "luminance", "Rec. 709 luminance of the reflection"]]
    assert got["view_equals_read"]
