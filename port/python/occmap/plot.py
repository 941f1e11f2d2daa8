# SPDX-License-Identifier: BSD-3-Clause
"""Map.plot_slice: a horizontal slice of the map as a matplotlib image (one pixel per voxel
column, the states of all pixels from one C call: Map.state_at, occ_map_states_at)."""
import numpy as np

COLOURS = np.array([[0.5, 0.5, 0.5], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]])  # unknown free occupied


def slice_states(m, z, bounds=None):
    """(states[ny, nx], extent) of the voxel columns over bounds at height z; the pixel centres
    are the voxel centres."""
    res = float(m.resolution_m)
    if bounds is None:
        st = m.stats()
        if not st["has_known"]:
            raise ValueError("plot_slice: the map is empty; give bounds=(xmin, xmax, ymin, ymax)")
        bounds = (st["bbox_min"][0], st["bbox_max"][0], st["bbox_min"][1], st["bbox_max"][1])
    x0, x1, y0, y1 = (float(b) for b in bounds)
    if not (x1 > x0 and y1 > y0):
        raise ValueError(f"plot_slice: bounds must be (xmin, xmax, ymin, ymax), got {bounds}")
    ix = np.arange(np.floor(x0 / res), np.ceil(x1 / res))
    iy = np.arange(np.floor(y0 / res), np.ceil(y1 / res))
    gx, gy = np.meshgrid((ix + 0.5) * res, (iy + 0.5) * res)
    pts = np.stack([gx, gy, np.full_like(gx, float(z))], axis=-1)
    extent = (ix[0] * res, (ix[-1] + 1) * res, iy[0] * res, (iy[-1] + 1) * res)
    return m.state_at(pts), extent


def plot_slice(m, z, ax=None, bounds=None):
    import matplotlib.pyplot as plt
    states, extent = slice_states(m, z, bounds)
    if ax is None:
        _, ax = plt.subplots()
    img = ax.imshow(COLOURS[states], origin="lower", extent=extent, interpolation="nearest")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"z = {z:g} m: black occupied, white free, grey unknown")
    return img
