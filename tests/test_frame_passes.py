"""The faster G-buffer, lighting and composite: what their shortcuts must keep exact
(the covered-tile lighting leaves no covered texel unlit, the composite's r read from lit's
alpha is the G-buffer's r), and benchmarks/tools/ab_frame.py (two interpreters, interleaved)."""

import subprocess
import sys

import numpy as np

import ssrlab
from conftest import REPO, small


def reflective_scene():
    """spheres_and_boxes with reflectivities that are not multiples of 1/255 and one of 1."""
    scene = ssrlab.scenes.spheres_and_boxes(seed=3)
    for i, r in zip(range(scene.object_count), [0.37, 1.0, 0.013, 0.5, 0.91] * 10):
        m = scene.material(i)
        m.reflectivity = r
        scene.set_material(i, m)
    return scene


def test_every_covered_texel_of_every_layer_is_lit_and_the_rest_is_empty(renderer):
    # The lighting dispatches only the 8x8 tiles the peeling marked as covered and clears the
    # rest: a covered texel in an unlisted tile would keep the clear (alpha 0, far depth).
    scene = ssrlab.scenes.hall()
    f = renderer.render(scene, settings=small(width=101, height=67, layers=4))
    g = f.gbuffer
    lit = f.read("lit")
    depth = f.read("linear_depth")[..., 0]
    cov = np.stack([g.coverage[k] for k in range(4)])
    assert cov[1:].any() and (~cov[1:]).any(), "the deeper layers should be partly covered"
    r = np.stack([g.reflectivity[k] for k in range(4)])
    # alpha: 0.5 + r / 2 where covered (the composite's coverage and r), 0 where not.
    np.testing.assert_allclose(lit[..., 3][cov], 0.5 + 0.5 * r[cov], atol=5e-4)
    assert (lit[~cov] == 0.0).all()
    far = float(depth[~cov].max())
    assert (depth[~cov] == far).all() and (depth[cov] < far).all()
    assert np.isfinite(lit).all()


def test_linear_composite_uses_the_gbuffer_r_exactly(renderer):
    # The composite reads r from lit's half-float alpha and rounds it to the RGBA8 G-buffer's
    # k / 255: the blend must match the G-buffer's r to float precision, not to 1/255.
    scene = reflective_scene()
    f = renderer.render(scene, settings=small(width=96, height=64, layers=2))
    g = f.gbuffer
    cov = g.coverage[0]
    r = g.reflectivity[0][..., None]
    assert len(np.unique(np.round(r[cov] * 255))) >= 3
    expected = np.where(r > 0, r * f.reflection + (1 - r) * g.lit[0], g.lit[0])
    np.testing.assert_allclose(f.color[cov], expected[cov], rtol=1e-5, atol=1e-6)


def test_ab_frame_script_same_build_on_both_sides_gives_identical_images():
    out = subprocess.run(
        [sys.executable, str(REPO / "benchmarks" / "tools" / "ab_frame.py"), "--baseline-python", sys.executable,
         "--scenes", "hall", "--width", "64", "--height", "48", "--frames", "2", "--warmup", "1",
         "--set", "shadow_map_size=256"],
        capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    text = out.stdout
    assert "| baseline |" in text and "| current |" in text
    assert "speed-up (baseline / current median)" in text
    # Same build, same inputs: the two processes' images are identical (deterministic).
    assert "thesis error between the images 0.00e+00" in text, text
