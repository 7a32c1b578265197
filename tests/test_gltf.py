"""glTF 2.0 import and export (tinygltf + OpenImageIO) and the errors of bad files."""

import json
import shutil

import numpy as np
import pytest

import ssrlab
from conftest import gltf_json, model_path, small


def scene_triangles(path) -> int:
    """Triangles of a glTF file's default scene, instanced per node, counted from the JSON."""
    j = gltf_json(path)

    def node_tris(i):
        node = j["nodes"][i]
        n = 0
        if "mesh" in node:
            for p in j["meshes"][node["mesh"]]["primitives"]:
                acc = j["accessors"][p["indices"]] if "indices" in p else j["accessors"][p["attributes"]["POSITION"]]
                n += acc["count"] // 3
        return n + sum(node_tris(c) for c in node.get("children", []))

    return sum(node_tris(i) for i in j["scenes"][j.get("scene", 0)]["nodes"])


@pytest.mark.parametrize("rel, triangles, objects", [
    ("Suzanne/Suzanne.gltf", 3936, 1),
    ("2CylinderEngine/2CylinderEngine.glb", 121496, None),
])
def test_sample_models_load_with_the_right_triangle_count(rel, triangles, objects):
    path = model_path(rel)
    scene = ssrlab.Scene.load(path)
    assert scene.triangle_count == triangles == scene_triangles(path)
    if objects is not None:
        assert scene.object_count == objects


def test_suzanne_textures_are_decoded(renderer):
    scene = ssrlab.Scene.load(model_path("Suzanne/Suzanne.gltf"))
    assert scene.image_count == 2
    mat = scene.material(0)
    assert mat.base_color_texture >= 0 and mat.metallic_roughness_texture >= 0
    scene.add_light(ssrlab.directional_light((0, -1, -1)))
    cam = ssrlab.Camera(position=(0, 0, 4), target=(0, 0, 0))
    g = renderer.render(scene, cam, small()).gbuffer
    albedo = g.albedo[0][g.coverage[0]]
    assert albedo.std(axis=0).max() > 0.01, "a textured model must not render flat"


def test_engine_renders_deep_layers(renderer):
    scene = ssrlab.scenes.load(str(model_path("2CylinderEngine/2CylinderEngine.glb")))
    assert scene.camera is not None
    g = renderer.render(scene, settings=small(width=128, height=96, layers=6)).gbuffer
    assert g.coverage[5].any(), "the engine's overlapping parts fill six layers"


def test_missing_file():
    with pytest.raises(FileNotFoundError, match="no_such_model.gltf"):
        ssrlab.Scene.load("/tmp/does/not/exist/no_such_model.gltf")


def copy_suzanne(tmp_path):
    src = model_path("Suzanne/Suzanne.gltf").parent
    for f in src.iterdir():
        shutil.copy(f, tmp_path / f.name)
    return tmp_path / "Suzanne.gltf"


def test_invalid_json(tmp_path):
    bad = tmp_path / "broken.gltf"
    bad.write_text('{"asset": {"version": "2.0"}, "nodes": [')
    with pytest.raises(ssrlab.SceneError, match="broken.gltf") as e:
        ssrlab.Scene.load(bad)
    assert "JSON" in str(e.value) or "json" in str(e.value) or "parse" in str(e.value)


def test_out_of_range_accessor(tmp_path):
    path = copy_suzanne(tmp_path)
    j = json.loads(path.read_text())
    j["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 99
    path.write_text(json.dumps(j))
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne.gltf.*accessor.*99.*out of range"):
        ssrlab.Scene.load(path)


def test_accessor_past_the_end_of_its_buffer(tmp_path):
    path = copy_suzanne(tmp_path)
    j = json.loads(path.read_text())
    j["accessors"][1]["count"] = 10 ** 6
    path.write_text(json.dumps(j))
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne.gltf.*(past the end|buffer)"):
        ssrlab.Scene.load(path)


def test_missing_image(tmp_path):
    path = copy_suzanne(tmp_path)
    (tmp_path / "Suzanne_BaseColor.png").unlink()
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne.gltf.*Suzanne_BaseColor.png.*not found"):
        ssrlab.Scene.load(path)


def test_corrupt_image(tmp_path):
    path = copy_suzanne(tmp_path)
    (tmp_path / "Suzanne_MetallicRoughness.png").write_bytes(b"this is not a png")
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne"):
        ssrlab.Scene.load(path)


def test_node_cycle_is_detected(tmp_path):
    path = copy_suzanne(tmp_path)
    j = json.loads(path.read_text())
    j["nodes"].append({"name": "loop", "children": [1]})
    j["nodes"][0]["children"] = [1]
    j["scenes"][0]["nodes"] = [0]
    path.write_text(json.dumps(j))
    with pytest.raises(ssrlab.SceneError, match="cycle"):
        ssrlab.Scene.load(path)


def _round(r):
    return r if r == "auto" else round(r, 5)


def scene_summary(s: ssrlab.Scene) -> dict:
    return {
        "objects": [(s.object_name(i), s.object_transform(i).round(5).tolist()) for i in range(s.object_count)],
        "materials": [(round(s.material(i).roughness, 5), round(s.material(i).metallic, 5),
                       _round(s.material(i).reflectivity), tuple(round(c, 5) for c in s.material(i).base_color))
                      for i in range(s.object_count)],
        "triangles": s.triangle_count,
        "lights": [(l.type, l.intensity, tuple(np.round(l.direction, 5)), l.cast_shadow) for l in s.lights],
        "ambient": tuple(np.round(s.ambient, 5)),
        "environment": (s.environment.type, tuple(np.round(s.environment.zenith, 5))),
        "camera": repr(s.camera),
    }


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_save_and_load_back_identically(renderer, tmp_path, suffix):
    model_path("Suzanne/Suzanne.gltf")
    scene = ssrlab.scenes.spheres_and_boxes(seed=2, with_suzanne=True)
    path = scene.save(tmp_path / f"scene{suffix}")
    back = ssrlab.Scene.load(path)
    assert scene_summary(back) == scene_summary(scene)
    a = renderer.render(scene, settings=small(layers=2))
    b = renderer.render(back, settings=small(layers=2))
    np.testing.assert_array_equal(a.color, b.color)
    np.testing.assert_array_equal(a.gbuffer.depth, b.gbuffer.depth)


def test_save_refuses_to_overwrite(tmp_path):
    scene = ssrlab.scenes.mirror_test()
    target = tmp_path / "m.glb"
    target.write_text("the user's own file")
    with pytest.raises(FileExistsError):
        scene.save(target)
    assert target.read_text() == "the user's own file"
    scene.save(target, overwrite=True)
    assert ssrlab.Scene.load(target).object_count == scene.object_count
