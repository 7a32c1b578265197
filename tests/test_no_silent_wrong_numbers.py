"""Numbers a researcher can trust: results keep the values they computed whatever is computed
after them, transforms and radiances that would overflow float32 are refused where they are
made (naming the object and the value), and output failures are OSErrors naming the file."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import ssrlab
from conftest import small, suzanne_copy

# -- results own their values ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def hall_frame(renderer):
    f = renderer.render(ssrlab.scenes.hall(floor_roughness=0.0), settings=small(width=80, height=48, layers=2))
    yield f
    f.release()


def _converged(frame, variant):
    return frame.reference("converged", rays=1, **variant)


def _per_ray(frame, variant):
    return frame.reference("per_ray", **variant)


REFERENCE_VARIANTS = [dict(), dict(shadows="map"), dict(viewer="camera"), dict(seed=3)]


def _arrays(result) -> dict[str, np.ndarray]:
    if result.kind == "converged":
        return {"reflection": result.reflection, "color": result.color}
    return {"hit": result.hit, "t": result.t, "position": result.position, "radiance": result.radiance,
            "hit_pixel": result.hit_pixel, "on_screen": result.on_screen}


@pytest.mark.parametrize("make", [_converged, _per_ray], ids=["converged", "per_ray"])
@pytest.mark.parametrize("read_first_before", [True, False], ids=["read-before", "read-after"])
def test_a_reference_keeps_its_values_after_another(hall_frame, make, read_first_before):
    a_args, b_args = dict(), dict(shadows="map", viewer="camera")
    a = make(hall_frame, a_args)
    early = {k: v.copy() for k, v in _arrays(a).items()} if read_first_before else None
    b = make(hall_frame, b_args)
    b_values = {k: v.copy() for k, v in _arrays(b).items()}
    a_values = _arrays(a)
    # The two references differ (otherwise this test could not fail) ...
    assert any(not np.array_equal(a_values[k], b_values[k]) for k in a_values)
    # ... a still holds its own: the same as when first read, and the same as computed afresh.
    if early is not None:
        for k in early:
            np.testing.assert_array_equal(a_values[k], early[k], err_msg=k)
    again = make(hall_frame, a_args)
    for k, v in _arrays(again).items():
        np.testing.assert_array_equal(a_values[k], v, err_msg=k)
    # And b was not changed by a's recomputation either.
    for k, v in _arrays(b).items():
        np.testing.assert_array_equal(v, b_values[k], err_msg=k)


def test_converged_and_per_ray_references_do_not_disturb_each_other(hall_frame):
    c = hall_frame.reference("converged", rays=1)
    reflection = c.reflection.copy()
    p = hall_frame.reference("per_ray")
    t = p.t.copy()
    hall_frame.reference("converged", rays=1, shadows="map")
    hall_frame.reference("per_ray", viewer="camera", seed=5)
    np.testing.assert_array_equal(c.reflection, reflection)
    np.testing.assert_array_equal(p.t, t)


def test_a_reference_of_a_released_frame_says_so(renderer):
    f = renderer.render(ssrlab.scenes.mirror_test(), settings=small(width=32, height=24, layers=1))
    ref = f.reference("converged", rays=1)
    f.release()
    with pytest.raises(ValueError, match="ConvergedReference.*released"):
        ref.reflection
    # One that was kept before the release (a later reference on its frame) still reads.
    g = renderer.render(ssrlab.scenes.mirror_test(), settings=small(width=32, height=24, layers=1))
    first = g.reference("converged", rays=1)
    g.reference("converged", rays=1, shadows="map")
    kept = first.reflection.copy()
    g.release()
    np.testing.assert_array_equal(first.reflection, kept)


FRAME_READS = {
    "color": lambda f: f.color,
    "reflection": lambda f: f.reflection,
    "gbuffer.depth": lambda f: f.gbuffer.depth,
    "gbuffer.normal": lambda f: f.gbuffer.normal,
    "gbuffer.lit": lambda f: f.gbuffer.lit,
    "rays.hit_uv": lambda f: f.rays.hit_uv,
    "rays.direction": lambda f: f.rays.direction,
    "stats": lambda f: np.array([f.stats["rays_traced"], f.stats["depth_fetches"]]),
    "fallback_stats": lambda f: np.array(sorted(f.fallback_stats.items()), dtype=object)[:, 1].astype(float),
}


@pytest.mark.parametrize("what", sorted(FRAME_READS))
@pytest.mark.parametrize("order", ["first-frame-read-late", "first-frame-read-early"])
def test_frame_results_keep_their_values_across_later_renders(renderer, what, order):
    """Two frames of one renderer with different settings, read in both orders: each keeps its own."""
    scene = ssrlab.scenes.hall(floor_roughness=0.2)
    read = FRAME_READS[what]
    a = renderer.render(scene, settings=small(width=64, height=40, layers=2, rays_per_pixel=2, seed=1))
    early = np.array(read(a), copy=True) if order == "first-frame-read-early" else None
    b = renderer.render(scene, settings=small(width=64, height=40, layers=3, rays_per_pixel=1, seed=9,
                                              method="linear"))
    b_value = np.array(read(b), copy=True)
    a_value = np.array(read(a), copy=True)
    if early is not None:
        np.testing.assert_array_equal(a_value, early)
    # Rendered again from scratch, a's settings give a's values (determinism), so a kept its own.
    a2 = renderer.render(scene, settings=a.settings)
    np.testing.assert_array_equal(a_value, np.array(read(a2)))
    assert a_value.shape != b_value.shape or not np.array_equal(a_value, b_value)
    for f in (a, b, a2):
        f.release()


def test_sequence_frames_keep_their_values(renderer):
    scene = ssrlab.scenes.hall(floor_roughness=0.2)
    c = scene.camera
    cams = [ssrlab.Camera(position=tuple(np.add(c.position, (0.05 * i, 0, 0))), target=tuple(c.target),
                          fov_y=c.fov_y, near=c.near, far=c.far) for i in range(3)]
    s = small(width=64, height=40, layers=2, temporal_reflections=True)
    frames, seen = [], []
    for f in renderer.render_sequence(scene, cams, s):
        frames.append(f)
        seen.append((f.reflection.copy(), f.reprojection.valid.copy()))
    for f, (refl, valid) in zip(frames, seen):
        np.testing.assert_array_equal(f.reflection, refl)
        np.testing.assert_array_equal(f.reprojection.valid, valid)
    assert not np.array_equal(seen[0][0], seen[-1][0])


def test_frame_arrays_are_read_only(renderer):
    """Every property shares the frame's one cached copy: an in-place change raises instead of
    silently changing what every later read returns."""
    f = renderer.render(ssrlab.scenes.mirror_test(), settings=small(width=32, height=24, layers=1))
    with pytest.raises(ValueError, match="read-only"):
        f.color[0, 0, 0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        f.gbuffer.depth[...] *= 2.0
    mine = f.color.copy()
    mine[...] = 0.0
    assert f.color.max() > 0.0
    f.release()


# -- finite in, finite out ------------------------------------------------------------------------

@pytest.mark.parametrize("element", [3, 7, 11, 15])
def test_a_non_affine_node_matrix_is_refused_naming_the_node(tmp_path, element):
    path = suzanne_copy(tmp_path)
    j = json.loads(path.read_text())
    m = [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0]
    m[element] = 1e20 if element != 15 else 2.0
    j["nodes"][0]["matrix"] = m
    path.write_text(json.dumps(j))
    with pytest.raises(ssrlab.SceneError, match=r"Suzanne\.gltf.*node 0: matrix is not affine.*bottom row"):
        ssrlab.Scene.load(path)


def test_an_affine_matrix_within_rounding_loads(tmp_path):
    path = suzanne_copy(tmp_path)
    j = json.loads(path.read_text())
    j["nodes"][0]["matrix"] = [1.0, 0, 0, 1e-9, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0.5, 0, 0, 1.0]
    path.write_text(json.dumps(j))
    assert ssrlab.Scene.load(path).object_count == 1


BIG = ssrlab.transforms.scale(1e30)


@pytest.mark.parametrize("transform, message", [
    (np.diag([1.0, 1.0, 1.0, 2.0]), "not affine"),
    (np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 1e20, 0, 1]], np.float32), "not affine"),
    (BIG, "beyond|overflows"),
    (ssrlab.transforms.translate((0.0, 2e9, 0.0)), "beyond"),
    (ssrlab.transforms.scale(1e-30), "singular|overflows"),
    (np.diag([1e-4, 1.0, 1e4, 1.0]), "apart"),
], ids=["w-scale", "projective-row", "huge-scale", "far-offset", "tiny-scale", "anisotropic"])
def test_object_transforms_that_would_overflow_are_refused(transform, message):
    s = ssrlab.Scene()
    with pytest.raises(ValueError, match=rf"object 'crate'.*({message})"):
        s.add_box((0, 0, 0), (1, 1, 1), transform=transform, name="crate")
    assert s.object_count == 0


@pytest.mark.parametrize("make, message", [
    (lambda: ssrlab.directional_light((0, -1, 0), intensity=float("inf"), name="sun"), "light 'sun'.*NaN or Inf"),
    (lambda: ssrlab.directional_light((0, -1, 0), intensity=1e30, name="sun"), "light 'sun'.*more than"),
    (lambda: ssrlab.directional_light((0, -1, 0), color=(1e20, 1, 1), name="sun"), "light 'sun'.*more than"),
    (lambda: ssrlab.point_light((0, 3e9, 0), name="lamp"), "light 'lamp'.*position.*beyond"),
], ids=["inf-intensity", "huge-intensity", "huge-colour", "far-point"])
def test_lights_that_would_overflow_are_refused(make, message):
    s = ssrlab.Scene()
    with pytest.raises(ValueError, match=message):
        s.add_light(make())


def test_radiances_and_materials_that_would_overflow_are_refused():
    s = ssrlab.Scene()
    with pytest.raises(ValueError, match="Scene.ambient.*NaN or Inf"):
        s.ambient = (float("inf"), 0, 0)
    with pytest.raises(ValueError, match="Scene.ambient.*more than"):
        s.ambient = (1e30, 0, 0)
    with pytest.raises(ValueError, match="Scene.environment: zenith.*more than"):
        s.environment = ssrlab.Environment.sky(intensity=1e30)
    with pytest.raises(ValueError, match="Scene.environment: color.*NaN or Inf"):
        s.environment = ssrlab.Environment.constant((float("nan"), 0, 0))
    with pytest.raises(ValueError, match=r"Material.base_color.*\[0, 1\]"):
        ssrlab.Material(base_color=(1e30, 0.5, 0.5))


@pytest.mark.parametrize("field, value", [("position", (0.0, 1e20, 5.0)), ("target", (1e10, 0.0, 0.0))])
def test_cameras_beyond_the_world_are_refused(renderer, field, value):
    scene = ssrlab.scenes.mirror_test()
    c = scene.camera
    kw = dict(position=tuple(c.position), target=tuple(c.target), fov_y=c.fov_y, near=c.near, far=c.far)
    kw[field] = value
    with pytest.raises(ValueError, match=f"Camera.{field}.*beyond"):
        renderer.render(scene, ssrlab.Camera(**kw), small(width=32, height=24))


# -- output errors ------------------------------------------------------------------------------

def _tiny_filesystem(tmp_path) -> Path:
    """A 48 KiB tmpfs (root only), else a skip: a real full disk, not a simulation."""
    mnt = tmp_path / "full"
    mnt.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs needs root")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=48k", "tmpfs", str(mnt)], capture_output=True, timeout=30)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {r.stderr.decode(errors='replace').strip()}")
    return mnt


def test_a_full_disk_raises_an_oserror_naming_the_file(renderer, tmp_path):
    mnt = _tiny_filesystem(tmp_path)
    try:
        f = renderer.render(ssrlab.scenes.load("spheres_and_boxes"), settings=small(width=160, height=90, layers=2))
        with pytest.raises(OSError) as info:
            f.save(mnt / "out")
        e = info.value
        assert isinstance(e, ssrlab.OutputError) and not isinstance(e, ssrlab.SceneError)
        assert e.errno == errno.ENOSPC
        assert e.filename and Path(e.filename).parent == mnt / "out" and not Path(e.filename).name.startswith(".")
        assert Path(e.filename).name in str(e)
        # Nothing half-written: no temporary file, and every file there is one ssrlab finished.
        left = sorted(p.name for p in (mnt / "out").iterdir())
        assert not [n for n in left if n.startswith(".ssrlab-") and n != ".ssrlab-manifest.json"], left
        manifest = json.loads((mnt / "out" / ".ssrlab-manifest.json").read_text())["files"]
        assert sorted(manifest) == sorted(n for n in left if n != ".ssrlab-manifest.json")
    finally:
        subprocess.run(["umount", str(mnt)], timeout=30)


def test_a_file_size_limit_raises_an_oserror_naming_the_file(tmp_path):
    """Any write failure, not only a full disk (here the process's file-size limit, EFBIG), is an
    OSError naming the file asked for, and leaves no partial file."""
    script = textwrap.dedent(f"""
        import resource, signal, ssrlab, sys
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        r = ssrlab.Renderer()
        f = r.render(ssrlab.scenes.mirror_test(), settings=ssrlab.Settings(width=128, height=96, layers=1))
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
        try:
            f.save({str(tmp_path / 'out')!r})
        except OSError as e:
            print(type(e).__name__, e.errno, e.filename)
            sys.exit(0)
        sys.exit("no error")
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    name, code, filename = out.stdout.split()[-3:]
    assert name == "OutputError" and int(code) == errno.EFBIG
    assert Path(filename).parent == tmp_path / "out" and not Path(filename).name.startswith(".")
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.startswith(".ssrlab-") and "manifest" not in p.name]


def test_scene_save_failure_is_an_oserror_and_leaves_nothing(tmp_path):
    mnt = _tiny_filesystem(tmp_path)
    try:
        scene = ssrlab.Scene()
        rng = np.random.default_rng(0)
        scene.add_mesh(rng.normal(size=(30000, 3)).astype(np.float32), None, name="soup")  # ~360 KB of positions
        with pytest.raises(ssrlab.OutputError) as info:
            scene.save(mnt / "big.gltf")
        assert Path(info.value.filename) == mnt / "big.gltf"
        assert list(mnt.iterdir()) == []
    finally:
        subprocess.run(["umount", str(mnt)], timeout=30)
