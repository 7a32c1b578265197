"""Minimal glTF files that each hit one way a file used to crash, hang or poison the loader,
with what loading each must give: the reproducers of tests/data/hostile/ and the fuzzer's seeds
(benchmarks/fuzzing/fuzz_gltf.py).

    python -m ssrlab.lab.hostile_gltf tests/data/hostile     # rewrites the test data

Each case starts from one valid triangle (base(); buffer inline as a data: URI, so every file
stands alone) and changes one thing. write() puts the files and manifest.json into a folder; the
manifest maps each file to {"error": [substrings of the SceneError]} or {"warning": [substrings
of a SceneWarning]}, optionally with "kwargs" for Scene.load. tests/test_gltf_hostile.py loads
every entry.
"""

from __future__ import annotations

import base64
import copy
import json
import struct
import zlib
from pathlib import Path

POSITIONS = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
INDICES = struct.pack("<3H", 0, 1, 2) + b"\0\0"
BUFFER = POSITIONS + INDICES


def data_uri(data: bytes, mime: str = "application/octet-stream") -> str:
    return f"data:{mime};base64," + base64.b64encode(data).decode()


def png_1x1() -> bytes:
    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    raw = b"\0\xff\x80\x40\xff"
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def base() -> dict:
    """One lit triangle seen by a camera: every kind of object the loader checks, all valid."""
    return {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "buffers": [{"byteLength": len(BUFFER), "uri": data_uri(BUFFER)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
        "images": [{"uri": data_uri(png_1x1(), "image/png")}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497, "magFilter": 9729, "minFilter": 9987}],
        "textures": [{"source": 0, "sampler": 0}],
        "materials": [{"name": "red", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 0.2, 0.2, 1], "metallicFactor": 0.0, "roughnessFactor": 0.5,
            "baseColorTexture": {"index": 0}}}],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100.0}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "color": [1, 1, 1], "intensity": 3.0}]}},
        "nodes": [
            {"name": "tri", "mesh": 0},
            {"name": "camera", "camera": 0, "translation": [0.3, 0.3, 3.0]},
            {"name": "sun", "rotation": [-0.3826834, 0, 0, 0.9238795],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
        ],
        "scenes": [{"nodes": [0, 1, 2]}],
        "scene": 0,
    }


def glb(json_bytes: bytes, bin_bytes: bytes | None = None) -> bytes:
    json_bytes += b" " * (-len(json_bytes) % 4)
    out = struct.pack("<I4s", len(json_bytes), b"JSON") + json_bytes
    if bin_bytes is not None:
        bin_bytes += b"\0" * (-len(bin_bytes) % 4)
        out += struct.pack("<I4s", len(bin_bytes), b"BIN\0") + bin_bytes
    return struct.pack("<4sII", b"glTF", 2, 12 + len(out)) + out


def ssrlab_extras(**values) -> dict:
    return {"extras": {"ssrlab": values}}


CASES: dict[str, tuple] = {}  # name -> (document: dict | bytes, expectation)


def case(name: str, expect: dict, **kwargs):
    def register(build):
        doc = build(copy.deepcopy(base()))
        CASES[name] = (doc, dict(expect, **({"kwargs": kwargs} if kwargs else {})))
        return build
    return register


def err(*parts):
    return {"error": list(parts)}


def warn(*parts):
    return {"warning": list(parts)}


# --- crashes: bounds arithmetic that wrapped, recursion that overflowed the stack ----------
@case("bufferview_offset_wraps_4k.gltf", err("bufferView 0", "outside buffer 0"))
def _(d):
    d["bufferViews"][0]["byteOffset"] = 2 ** 64 - 4096
    return d


@case("bufferview_offset_max.gltf", err("bufferView 1", "outside buffer 0"))
def _(d):
    d["bufferViews"][1]["byteOffset"] = 2 ** 64 - 1
    return d


@case("accessor_offset_wraps.gltf", err("accessor 0", "bufferView 0"))
def _(d):
    d["accessors"][0]["byteOffset"] = 2 ** 64 - 8
    return d


@case("accessor_count_huge.gltf", err("accessor 0", "count"))
def _(d):
    d["accessors"][0]["count"] = 2 ** 62
    return d


@case("accessor_count_wraps_stride.gltf", err("accessor 1", "bufferView 1"))
def _(d):
    d["accessors"][1]["count"] = 2 ** 63 + 1  # stride * (count - 1) wraps to 0 in 64 bits
    return d


@case("node_chain_10000.gltf", err("node 1000", "deeper than 1000"))
def _(d):
    n = 10_000
    d["nodes"] = [{"children": [i + 1]} for i in range(n - 1)] + [{"mesh": 0}]
    d["scenes"] = [{"nodes": [0]}]
    return d


@case("node_cycle.gltf", err("cycle through node 0"))
def _(d):
    d["nodes"][0]["children"] = [3]
    d["nodes"].append({"children": [0]})
    return d


@case("extras_nested_30000.gltf", err("JSON nests", "deeper than 64"))
def _(d):
    depth = 30_000
    text = json.dumps(d)
    return text.replace('"asset": {', '"extras": ' + "[" * depth + "]" * depth + ', "asset": {', 1).encode()


@case("extras_nested_30000.glb", err("JSON nests", "deeper than 64"))
def _(d):
    depth = 30_000
    text = json.dumps(d).replace('"asset": {', '"extras": ' + "[" * depth + "]" * depth + ', "asset": {', 1)
    return glb(text.encode())


@case("glb_chunk_length_wraps.glb", err("GLB JSON chunk", "past the file's end"))
def _(d):
    data = bytearray(glb(json.dumps(d).encode()))
    data[12:16] = struct.pack("<I", 0xFFFFFFF8)
    return bytes(data)


# --- hangs and reads outside the model: devices, absolute paths, '..' ----------------------
@case("envmap_dev_zero.gltf", err("environment map", "/dev/zero", "absolute path", "allow_external_files"))
def _(d):
    d["scenes"][0].update(ssrlab_extras(environment={"type": "map", "map": "/dev/zero"}))
    return d


@case("envmap_dev_zero_allowed.gltf", err("environment map", "not a regular file"), allow_external_files=True)
def _(d):
    d["scenes"][0].update(ssrlab_extras(environment={"type": "map", "map": "/dev/urandom"}))
    return d


@case("envmap_not_an_image.gltf", err("environment map", "not an image"), allow_external_files=True)
def _(d):
    d["scenes"][0].update(ssrlab_extras(environment={"type": "map", "map": "/etc/passwd"}))
    return d


@case("image_uri_etc_passwd.gltf", err("image 0", "/etc/passwd", "absolute path"))
def _(d):
    d["images"][0] = {"uri": "/etc/passwd"}
    return d


@case("image_uri_dotdot.gltf", err("image 0", "outside the model's folder"))
def _(d):
    d["images"][0] = {"uri": "../" * 16 + "etc/passwd"}
    return d


@case("image_uri_percent_dotdot.gltf", err("image 0", "outside the model's folder"))
def _(d):
    d["images"][0] = {"uri": "%2e%2e/" * 16 + "etc/passwd"}
    return d


@case("buffer_uri_dev_zero.gltf", err("buffer 0", "/dev/zero", "absolute path"))
def _(d):
    d["buffers"][0]["uri"] = "/dev/zero"
    return d


@case("buffer_uri_dev_zero_allowed.gltf", err("buffer 0", "not a regular file"), allow_external_files=True)
def _(d):
    d["buffers"][0]["uri"] = "/dev/zero"
    return d


@case("buffer_uri_folder.gltf", err("buffer 0", "not a regular file"))
def _(d):
    d["buffers"][0]["uri"] = "."
    return d


@case("buffer_uri_missing.gltf", err("buffer 0", "file not found"))
def _(d):
    d["buffers"][0]["uri"] = "no_such_buffer.bin"
    return d


# --- poisoned renders: values that overflow to Inf/NaN in the lighting ---------------------
@case("light_color_1e39.gltf", err("light 0", "color", "1e+39"))
def _(d):
    d["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = [1e39, 1, 1]
    return d


@case("light_intensity_1e39.gltf", err("light 0", "intensity", "1e+39"))
def _(d):
    d["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = 1e39
    return d


@case("light_intensity_negative.gltf", err("light 0", "intensity", "-5"))
def _(d):
    d["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = -5
    return d


@case("light_direction_zero.gltf", err("light 0", "direction", "zero"))
def _(d):
    d["extensions"]["KHR_lights_punctual"]["lights"][0]["extras"] = {"direction": [0, 0, 0]}
    return d


@case("light_node_zero_scale.gltf", err("node 2", "light 0", "no direction"))
def _(d):
    d["nodes"][2]["scale"] = [0, 0, 0]
    return d


@case("ambient_1e39.gltf", err("ambient", "1e+39"))
def _(d):
    d["scenes"][0].update(ssrlab_extras(ambient=[1e39, 0, 0]))
    return d


@case("environment_color_1e39.gltf", err("environment.color", "1e+39"))
def _(d):
    d["scenes"][0].update(ssrlab_extras(environment={"type": "constant", "color": [1, 1e39, 1]}))
    return d


@case("environment_intensity_1e39.gltf", err("environment.intensity", "1e+39"))
def _(d):
    d["scenes"][0].update(ssrlab_extras(environment={"type": "sky", "intensity": 1e39}))
    return d


@case("material_basecolor_1e39.gltf", err("material 0", "baseColorFactor", "1e+39"))
def _(d):
    d["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = [1e39, 1, 1, 1]
    return d


@case("material_roughness_negative.gltf", err("material 0", "roughnessFactor"))
def _(d):
    d["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = -1
    return d


@case("node_matrix_1e39.gltf", err("node 0", "matrix", "1e+39"))
def _(d):
    d["nodes"][0]["matrix"] = [1e39, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    return d


@case("node_translation_1e39.gltf", err("node 0", "translation"))
def _(d):
    d["nodes"][0]["translation"] = [0, -1e39, 0]
    return d


@case("node_rotation_zero.gltf", err("node 0", "rotation", "zero length"))
def _(d):
    d["nodes"][0]["rotation"] = [0, 0, 0, 0]
    return d


@case("node_world_overflow.gltf", err("node 3", "world transform"))
def _(d):
    d["nodes"][0]["children"] = [3]
    d["nodes"][0]["scale"] = [1e30, 1e30, 1e30]
    d["nodes"].append({"mesh": 0, "scale": [1e30, 1e30, 1e30]})
    return d


@case("node_zero_scale.gltf", warn("node 0", "singular", "mesh 0 skipped"))
def _(d):
    d["nodes"][0]["scale"] = [1, 1, 0]  # the triangle is flat in z, but its normals would be NaN
    return d


@case("node_scale_ratio_1e19.gltf", warn("node 0", "degenerate", "mesh 0 skipped"))
def _(d):
    d["nodes"][0]["scale"] = [1, 1, 1.8e19]  # fuzzer finding: normals underflowed to zero length, NaN image
    return d


@case("node_far_from_origin.gltf", err("node 0", "world space", "1e+09"))
def _(d):
    d["nodes"][0]["translation"] = [3e12, 0, 0]
    return d


@case("camera_far_from_origin.gltf", err("node 1", "camera 0", "world space"))
def _(d):
    d["nodes"][1]["translation"] = [0, 0, 2 ** 40]
    return d


@case("camera_yfov_zero.gltf", err("camera 0", "yfov"))
def _(d):
    d["cameras"][0]["perspective"]["yfov"] = 0
    return d


@case("camera_znear_negative.gltf", err("camera 0", "znear"))
def _(d):
    d["cameras"][0]["perspective"]["znear"] = -1
    return d


@case("camera_zfar_below_znear.gltf", err("camera 0", "zfar"))
def _(d):
    d["cameras"][0]["perspective"]["zfar"] = 0.01
    return d


@case("sampler_wrap_invalid.gltf", err("sampler 0", "wrapS", "12345"))
def _(d):
    d["samplers"][0]["wrapS"] = 12345
    return d


@case("sampler_filter_invalid.gltf", err("sampler 0", "minFilter"))
def _(d):
    d["samplers"][0]["minFilter"] = 7
    return d


# --- silent nonsense: now an error or a warning --------------------------------------------
@case("primitive_no_position.gltf", err("mesh 0", "primitive 0", "no POSITION"))
def _(d):
    d["meshes"][0]["primitives"][0]["attributes"] = {"NORMAL": 0}
    return d


@case("primitive_float_indices.gltf", err("mesh 0", "indices", "accessor 1", "unsigned"))
def _(d):
    d["accessors"][1]["componentType"] = 5126
    d["bufferViews"][1]["byteLength"] = 8
    d["accessors"][1]["count"] = 2
    return d


@case("primitive_attribute_out_of_range.gltf", err("mesh 0 primitive 0 attribute POSITION", "accessor 7", "out of range"))
def _(d):
    d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 7
    return d


@case("primitive_attribute_not_integer.gltf", err("mesh 0 primitive 0 attribute POSITION", "integer", "0.5"))
def _(d):
    d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 0.5
    return d


@case("primitive_attribute_huge_index.gltf", err("mesh 0 primitive 0 attribute POSITION", "out of range"))
def _(d):
    d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 2 ** 40  # an int cast makes it 0
    return d


@case("primitive_indices_string.gltf", err("mesh 0 primitive 0", "indices", "integer"))
def _(d):
    d["meshes"][0]["primitives"][0]["indices"] = "x"
    return d


@case("node_light_index_out_of_range.gltf", err("node 2", "light", "out of range"))
def _(d):
    d["nodes"][2]["extensions"]["KHR_lights_punctual"]["light"] = 5
    return d


@case("mesh_no_primitives.gltf", warn("mesh 0", "no primitives"))
def _(d):
    d["meshes"][0]["primitives"] = []
    return d


@case("mode_points.gltf", warn("mesh 0", "primitive 0", "POINTS"))
def _(d):
    d["meshes"][0]["primitives"][0]["mode"] = 0
    return d


@case("mode_lines.gltf", warn("mesh 0", "primitive 0", "LINES"))
def _(d):
    d["meshes"][0]["primitives"][0]["mode"] = 1
    return d


@case("mode_invalid.gltf", warn("mesh 0", "primitive 0", "mode 9"))
def _(d):
    d["meshes"][0]["primitives"][0]["mode"] = 9
    return d


@case("morph_targets.gltf", warn("mesh 0", "morph target"))
def _(d):
    d["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": 0}]
    return d


@case("skin.gltf", warn("skin"))
def _(d):
    d["skins"] = [{"joints": [1]}]
    d["nodes"][0]["skin"] = 0
    return d


@case("empty_scene.gltf", warn("no triangles were loaded"))
def _(d):
    d["scenes"] = [{"nodes": [1, 2]}]
    return d


@case("scene_without_scenes.gltf", err("'scene'", "no 'scenes' array"))
def _(d):
    del d["scenes"]
    return d


@case("extension_required_unknown.gltf", err("KHR_draco_mesh_compression", "does not implement"))
def _(d):
    d["extensionsUsed"].append("KHR_draco_mesh_compression")
    d["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    return d


# --- animations: keyframes, samplers and channels that are malformed -----------------------
def animated(d, times=(0.0, 1.0), values=((0, 0, 0), (1, 0, 0)), path="translation", interpolation=None, node=0,
             output_type=None, input_component=5126):
    """Adds an animation "move" of one channel, its keyframes in a second buffer."""
    values = [float(x) for v in values for x in v]
    width = {"translation": 3, "scale": 3, "rotation": 4, "weights": 1}.get(path, 3)
    times_bytes = struct.pack(f"<{len(times)}f", *times)
    data = times_bytes + struct.pack(f"<{len(values)}f", *values)
    d["buffers"].append({"byteLength": len(data), "uri": data_uri(data)})
    buffer = len(d["buffers"]) - 1
    d["bufferViews"] += [{"buffer": buffer, "byteOffset": 0, "byteLength": len(times_bytes)},
                         {"buffer": buffer, "byteOffset": len(times_bytes), "byteLength": 4 * len(values)}]
    views = len(d["bufferViews"])
    d["accessors"] += [{"bufferView": views - 2, "componentType": input_component, "count": len(times),
                        "type": "SCALAR", "min": [min(times)], "max": [max(times)]},
                       {"bufferView": views - 1, "componentType": 5126, "count": len(values) // width,
                        "type": output_type or {1: "SCALAR", 3: "VEC3", 4: "VEC4"}[width]}]
    sampler = {"input": len(d["accessors"]) - 2, "output": len(d["accessors"]) - 1}
    if interpolation:
        sampler["interpolation"] = interpolation
    d["animations"] = [{"name": "move", "samplers": [sampler],
                        "channels": [{"sampler": 0, "target": {"node": node, "path": path}}]}]
    return d


MOVE = ("animation 0 ('move') channel 0 (node 0 'tri', translation)",)


@case("anim_times_not_increasing.gltf", err(*MOVE, "sampler 0", "increase strictly", "time 2"))
def _(d):
    return animated(d, times=(0.0, 1.0, 1.0), values=((0, 0, 0),) * 3)


@case("anim_time_negative.gltf", err(*MOVE, "first keyframe time is -1"))
def _(d):
    return animated(d, times=(-1.0, 1.0))


@case("anim_output_count.gltf", err(*MOVE, "3 output values for 2 keyframes"))
def _(d):
    return animated(d, values=((0, 0, 0), (1, 0, 0), (2, 0, 0)))


@case("anim_cubic_one_key.gltf", err(*MOVE, "CUBICSPLINE needs at least 2 keyframes"))
def _(d):
    return animated(d, times=(0.0,), values=((0, 0, 0),) * 3, interpolation="CUBICSPLINE")


@case("anim_cubic_no_tangents.gltf", err(*MOVE, "2 output values for 2 keyframes", "in-tangent, value, out-tangent"))
def _(d):
    return animated(d, interpolation="CUBICSPLINE")


@case("anim_interpolation_unknown.gltf", err(*MOVE, "interpolation 'SMOOTH'"))
def _(d):
    return animated(d, interpolation="SMOOTH")


@case("anim_value_nan.gltf", err(*MOVE, "sampler 0 output", "NaN or Inf"))
def _(d):
    return animated(d, values=((0, 0, 0), (float("nan"), 0, 0)))


@case("anim_input_not_float.gltf", err(*MOVE, "input accessor 2 must hold float scalars"))
def _(d):
    return animated(d, times=(0.0, 1.0), input_component=5125)  # the same bytes read as integers


@case("anim_output_vec4_translation.gltf", err(*MOVE, "output accessor 3 must hold float VEC3"))
def _(d):
    return animated(d, values=((0, 0, 0), (1, 0, 0), (0, 0, 0), (1, 0, 0)), output_type="VEC4")


@case("anim_rotation_zero.gltf", err("animation 0 ('move') channel 0 (node 0 'tri', rotation)", "keyframe 1",
                                     "zero quaternion"))
def _(d):
    return animated(d, path="rotation", values=((0, 0, 0, 1), (0, 0, 0, 0)))


@case("anim_node_with_matrix.gltf", err(*MOVE, "given by a matrix"))
def _(d):
    d["nodes"][0]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    return animated(d)


@case("anim_channel_twice.gltf", err("animation 0 ('move') channel 1", "second channel for the same node and path"))
def _(d):
    d = animated(d)
    d["animations"][0]["channels"].append(dict(d["animations"][0]["channels"][0]))
    return d


@case("anim_sampler_out_of_range.gltf", err("animation 0 channel 0", "sampler 4 is out of range"))
def _(d):
    d = animated(d)
    d["animations"][0]["channels"][0]["sampler"] = 4
    return d


@case("anim_node_out_of_range.gltf", err("animation 0 channel 0 target", "node 9 is out of range"))
def _(d):
    return animated(d, node=9)


@case("anim_input_out_of_range.gltf", err("animation 0 sampler 0", "input 2147483648 is out of range"))
def _(d):
    d = animated(d)
    d["animations"][0]["samplers"][0]["input"] = 2 ** 31
    return d


@case("anim_target_not_object.gltf", err("animation 0 channel 0", "target is not a JSON object"))
def _(d):
    d = animated(d)
    d["animations"][0]["channels"][0]["target"] = 0
    return d


@case("anim_output_past_view.gltf", err(*MOVE, "sampler 0 output: accessor 3", "read past the end of bufferView 3"))
def _(d):
    d = animated(d)
    d["accessors"][3]["count"] = 3
    return d


@case("anim_pose_not_unit.gltf", err("node 0", "extras.ssrlab.pose.rotation is not a unit quaternion"))
def _(d):
    d["nodes"][0]["extras"] = {"ssrlab": {"pose": {"rotation": [0, 0, 0, 3]}}}
    return animated(d)


@case("anim_weights.gltf", warn("animation 0 ('move')", "morph target weights", "not rendered"))
def _(d):
    d["meshes"][0]["weights"] = [0.0]
    return animated(d, path="weights", values=((0,), (1,)))


@case("anim_path_unknown.gltf", warn("animation 0 ('move')", "target path 'pointer'", "not rendered"))
def _(d):
    d = animated(d)
    d["animations"][0]["channels"][0]["target"]["path"] = "pointer"
    return d


# --- exceptions that escaped without the file's name ---------------------------------------
@case("invalid_utf8.gltf", err("not valid UTF-8"))
def _(d):
    return json.dumps(d).replace('"tri"', '"tri\udcff"', 1).encode("utf-8", "surrogateescape")


@case("top_level_array.gltf", err("top level"))
def _(d):
    return json.dumps([d]).encode()


def read_glb(path) -> tuple[dict, bytes]:
    """The JSON document and the BIN chunk of a .glb file."""
    data = Path(path).read_bytes()
    json_length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + json_length])
    at = 20 + json_length
    bin_length = struct.unpack_from("<I", data, at)[0] if at + 8 <= len(data) else 0
    return doc, data[at + 8:at + 8 + bin_length]


def instanced(path, instances: int = 20_000, *, model=None, mesh: int = 3, spacing: float = 60.0) -> Path:
    """Writes `path` (.glb): `instances` nodes that all draw one mesh of a sample model
    (default: 2CylinderEngine's mesh 3, 2163 triangles), on a square grid `spacing` apart in the
    model's units, under the model's own camera: the fuzzer's instancing mutant, a file of a few MB
    whose drawn triangles run to the tens of millions (20,000 instances: 43 million). No light is
    added (Scene.load adds none; ssrlab.scenes.load gives the model its default lighting)."""
    if model is None:
        from ..models import find

        model = find("2CylinderEngine")
    doc, bin_bytes = read_glb(model)
    side = max(1, int(round(instances ** 0.5)))
    cameras = [i for i, n in enumerate(doc["nodes"]) if "camera" in n]
    doc["nodes"] = [doc["nodes"][i] for i in cameras] + [
        {"name": f"instance {i}", "mesh": mesh,
         "translation": [spacing * (i % side - side / 2), 0.0, spacing * (i // side - side / 2)]}
        for i in range(instances)]
    first = len(cameras)
    doc["scenes"] = [{"nodes": list(range(first + instances))}]
    doc["scene"] = 0
    path = Path(path)
    path.write_bytes(glb(json.dumps(doc, separators=(",", ":")).encode(), bin_bytes))
    return path


def write(folder) -> dict:
    """Writes every case into `folder` (created; its earlier .gltf/.glb files removed) with
    manifest.json; returns the manifest."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    for old in out.iterdir():
        if old.suffix in (".gltf", ".glb"):
            old.unlink()
    manifest = {}
    for name, (doc, expect) in CASES.items():
        data = doc if isinstance(doc, bytes) else json.dumps(doc, indent=1).encode()
        if len(data) > 20_000 and not isinstance(doc, bytes):
            data = json.dumps(doc, separators=(",", ":")).encode()
        (out / name).write_bytes(data)
        manifest[name] = expect
    (out / "manifest.json").write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    return manifest


def main(argv=None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description="Writes the hostile glTF reproducers and their manifest.json.")
    ap.add_argument("folder", type=Path, help="where to write them (tests/data/hostile in the repository)")
    args = ap.parse_args(argv)
    manifest = write(args.folder)
    print(f"wrote {len(manifest)} files to {args.folder}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
