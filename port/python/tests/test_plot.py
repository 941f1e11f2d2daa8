# SPDX-License-Identifier: BSD-3-Clause
"""Map.plot_slice: one pixel per voxel column, coloured by the states of one batch lookup."""
import matplotlib
import numpy as np
import pytest

import occmap
from occmap.plot import COLOURS

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def test_slice_pixels_are_the_voxel_states(tmp_path, batch_calls):
    m = occmap.Map(0.1, 1 << 22)
    pts = np.array([[1.05, y, 0.05] for y in (np.arange(-5, 5) + 0.5) * 0.1], np.float32)
    m.insert_cloud((0.05, 0.05, 0.05), pts)
    fig, ax = plt.subplots()
    img = m.plot_slice(0.05, ax=ax, bounds=(-0.2, 1.4, -0.6, 0.6))
    assert batch_calls == [12 * 16]  # the whole slice in one C call (occ_map_states_at)
    a = img.get_array()
    assert a.shape == (12, 16, 3)  # 1.2 m x 1.6 m of 0.1 m columns
    assert img.get_extent() == pytest.approx([-0.2, 1.4, -0.6, 0.6])
    # row iy (y = -0.55 + 0.1 iy), column ix (x = -0.15 + 0.1 ix): the wall is column 12
    assert (a[1:11, 12] == COLOURS[occmap.OCCUPIED]).all()
    assert (a[6, 2:12] == COLOURS[occmap.FREE]).all()  # the ray at y = 0.05
    assert (a[:, 0] == COLOURS[occmap.UNKNOWN]).all()
    out = tmp_path / "slice.png"
    fig.savefig(out)
    assert out.stat().st_size > 1000
    plt.close(fig)


def test_default_bounds_and_new_axes(geb079):
    img = occmap.Map.load(geb079).plot_slice(1.0)
    h, w, _ = img.get_array().shape
    assert (w, h) == (489, 189)  # geb079's bbox: 39.12 m x 15.12 m at 0.08 m
    colours = {tuple(c) for c in img.get_array().reshape(-1, 3)}
    assert colours == {tuple(c) for c in COLOURS}
    plt.close(img.figure)
    with pytest.raises(ValueError):
        occmap.Map(0.1, 1 << 20).plot_slice(0.0)  # empty map, no bounds
