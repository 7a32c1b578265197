"""Hostile glTF input: every reproducer in tests/data/hostile/ must give a SceneError
(or a SceneWarning) naming the file and the object, never a crash, a hang or a poisoned scene.
The files are written by ssrlab.lab.hostile_gltf; manifest.json says what each must give."""

import json
import math
import os
import warnings
from pathlib import Path

import pytest

import ssrlab
from conftest import suzanne_copy
from ssrlab.lab import hostile_gltf

HOSTILE = Path(__file__).parent / "data" / "hostile"
MANIFEST = json.loads((HOSTILE / "manifest.json").read_text())


def test_manifest_lists_every_file():
    files = {p.name for p in HOSTILE.iterdir() if p.suffix in (".gltf", ".glb")}
    assert files == set(MANIFEST)


def test_the_committed_files_are_what_the_generator_writes(tmp_path):
    assert hostile_gltf.write(tmp_path) == MANIFEST
    for name in MANIFEST:
        assert (tmp_path / name).read_bytes() == (HOSTILE / name).read_bytes(), name


@pytest.mark.parametrize("name", sorted(n for n, e in MANIFEST.items() if "error" in e))
def test_hostile_file_gives_scene_error(name):
    expect = MANIFEST[name]
    with pytest.raises(ssrlab.SceneError) as info:
        ssrlab.Scene.load(HOSTILE / name, **expect.get("kwargs", {}))
    message = str(info.value)
    assert name in message, message
    for part in expect["error"]:
        assert part in message, f"{part!r} not in {message!r}"


@pytest.mark.parametrize("name", sorted(n for n, e in MANIFEST.items() if "warning" in e))
def test_hostile_file_gives_scene_warning(name):
    expect = MANIFEST[name]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = ssrlab.Scene.load(HOSTILE / name, **expect.get("kwargs", {}))
    messages = [str(w.message) for w in caught if issubclass(w.category, ssrlab.SceneWarning)]
    assert messages, "no SceneWarning"
    text = "\n".join(messages)
    assert name in text, text
    for part in expect["warning"]:
        assert part in text, f"{part!r} not in {text!r}"
    for light in scene.lights:  # what did load is finite
        assert all(math.isfinite(c) for c in light.color) and math.isfinite(light.intensity)


def test_base_of_the_reproducers_loads_cleanly(tmp_path):
    """The reproducers differ from a valid file in one place: the valid file loads with no warning."""
    f = tmp_path / "base.gltf"
    f.write_text(json.dumps(hostile_gltf.base()))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = ssrlab.Scene.load(f)
    assert scene.object_count == 1 and len(scene.lights) == 1 and scene.camera is not None


def test_fifo_as_buffer_is_refused_without_blocking(tmp_path):
    path = suzanne_copy(tmp_path)
    (path.parent / "Suzanne.bin").unlink()
    os.mkfifo(path.parent / "Suzanne.bin")  # reading it would wait for a writer for ever
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne\.gltf.*buffer 0.*not a regular file"):
        ssrlab.Scene.load(path)


def test_fifo_as_image_is_refused(tmp_path):
    path = suzanne_copy(tmp_path)
    (path.parent / "Suzanne_BaseColor.png").unlink()
    os.mkfifo(path.parent / "Suzanne_BaseColor.png")
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne\.gltf.*image \d.*not a regular file"):
        ssrlab.Scene.load(path)


def test_symlink_leaving_the_folder_needs_opt_in(tmp_path):
    path = suzanne_copy(tmp_path)
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (path.parent / "Suzanne.bin").rename(outside / "Suzanne.bin")
    (path.parent / "Suzanne.bin").symlink_to(outside / "Suzanne.bin")
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne\.gltf.*buffer 0.*outside the model's folder.*allow_external_files"):
        ssrlab.Scene.load(path)
    scene = ssrlab.Scene.load(path, allow_external_files=True)
    assert scene.triangle_count > 0


def test_relative_uri_into_a_subfolder_is_fine(tmp_path):
    path = suzanne_copy(tmp_path)
    (path.parent / "sub").mkdir()
    (path.parent / "Suzanne.bin").rename(path.parent / "sub" / "Suzanne.bin")
    j = json.loads(path.read_text())
    j["buffers"][0]["uri"] = "sub/../sub/Suzanne.bin"
    path.write_text(json.dumps(j))
    assert ssrlab.Scene.load(path).triangle_count > 0


def test_absolute_uri_inside_allowed_only_with_opt_in(tmp_path):
    path = suzanne_copy(tmp_path)
    j = json.loads(path.read_text())
    j["buffers"][0]["uri"] = str(path.parent / "Suzanne.bin")
    path.write_text(json.dumps(j))
    with pytest.raises(ssrlab.SceneError, match=r"buffer 0.*absolute path"):
        ssrlab.Scene.load(path)
    assert ssrlab.Scene.load(path, allow_external_files=True).triangle_count > 0


def test_environment_map_round_trip_stays_inside_the_folder(tmp_path):
    """A saved scene's environment map is written relative to the file, so it loads back
    without allow_external_files; a device named as the map is refused at load time."""
    import numpy as np
    scene = ssrlab.Scene()
    scene.add_box()
    env = tmp_path / "env.exr"
    ssrlab.io.write_image(env, np.full((4, 8, 3), 0.5, np.float32))
    scene.environment = ssrlab.Environment.map(str(env))
    scene.save(tmp_path / "s.gltf")
    back = ssrlab.Scene.load(tmp_path / "s.gltf")
    assert Path(back.environment.map_path).resolve() == env.resolve()
    with pytest.raises(ssrlab.SceneError, match="not a regular file"):
        ssrlab.Environment.map("/dev/zero")


def test_error_messages_are_valid_text_for_odd_file_names(tmp_path):
    odd = tmp_path / "bad\udcff name.gltf"
    try:
        odd.write_bytes(b"{not json")
    except (UnicodeEncodeError, OSError):
        pytest.skip("file system refuses the name")
    with pytest.raises(ssrlab.SceneError, match=r"bad\\xff name\.gltf"):
        ssrlab.Scene.load(odd)
