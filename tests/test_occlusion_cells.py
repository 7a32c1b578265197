"""specular_occlusion='exit': each enclosure cell holds the farthest layer-0 surface of its pixels
(1e30 where a pixel shows the background), whatever the work groups' order of reduction."""

import numpy as np
import pytest

import ssrlab
from conftest import small


@pytest.mark.parametrize("size", [(96, 70), (64, 48)])
def test_enclosure_cells_are_the_farthest_surface_of_each_cell(renderer, size):
    w, h = size
    f = renderer.render(ssrlab.scenes.spheres_and_boxes(seed=3),
                        settings=small(width=w, height=h, specular_occlusion="exit"))
    # GL's rows (row 0 at the bottom), where the cells start
    depth = f.read("linear_depth")[0, ::-1, :, 0]
    covered = f.read("gbuffer.material")[0, ::-1, :, 1] > 0.5
    far = np.where(covered, depth, np.float32(1e30))
    cell = max(4, h // 16)
    cells = f.read("occlusion_cells")[0, ::-1, :, 0]
    ny, nx = -(-h // cell), -(-w // cell)
    assert cells.shape == (ny, nx)
    expected = np.array([[far[y * cell:(y + 1) * cell, x * cell:(x + 1) * cell].max() for x in range(nx)]
                         for y in range(ny)], dtype=np.float32)
    assert covered.any() and (~covered).any()
    np.testing.assert_array_equal(cells, expected)
