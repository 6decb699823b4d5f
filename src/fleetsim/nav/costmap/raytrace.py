"""Grid ray casting kernels: costmap_2d's Bresenham raytraceLine, batched over rays.

All kernels work on a (size_y, size_x) uint8 grid indexed ``[my, mx]`` in place.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _trace(grid, x, y, abs_da, abs_db, error_b, ax, ay, bx, by, max_length, value):
    end = min(max_length, abs_da)
    for _ in range(end):
        grid[y, x] = value
        x += ax
        y += ay
        error_b += abs_db
        if error_b >= abs_da:
            x += bx
            y += by
            error_b -= abs_da
    grid[y, x] = value


@njit(cache=True)
def trace_rays(grid, x0, y0, ends, max_length, value):
    """Set every cell on the Bresenham line from (x0, y0) to each end cell to ``value``.

    As costmap_2d's raytraceLine: the line is cut after ``max_length`` cells along its major
    axis (scaled by the true length), and its last cell is included.

    Parameters
    ----------
    grid : (size_y, size_x) uint8, modified in place.
    x0, y0 : start cell (column, row), inside the grid.
    ends : (N, 2) int64 end cells (column, row), inside the grid.
    max_length : ray length limit in cells.
    value : the cost written.
    """
    for i in range(ends.shape[0]):
        x1 = ends[i, 0]
        y1 = ends[i, 1]
        dx = x1 - x0
        dy = y1 - y0
        abs_dx = abs(dx)
        abs_dy = abs(dy)
        sx = 1 if dx > 0 else (-1 if dx < 0 else 0)
        sy = 1 if dy > 0 else (-1 if dy < 0 else 0)
        dist = math.hypot(dx, dy)
        scale = 1.0 if dist == 0.0 else min(1.0, max_length / dist)
        if abs_dx >= abs_dy:
            _trace(
                grid, x0, y0, abs_dx, abs_dy, abs_dx // 2, sx, 0, 0, sy, int(scale * abs_dx), value
            )
        else:
            _trace(
                grid, x0, y0, abs_dy, abs_dx, abs_dy // 2, 0, sy, sx, 0, int(scale * abs_dy), value
            )


def ray_ends_clipped(
    origin: np.ndarray, points: np.ndarray, map_min: np.ndarray, map_max: np.ndarray
) -> np.ndarray:
    """Ray end points pulled back along each ray to lie inside the map box.

    As ObstacleLayer::raytraceFreespace: ends below the minimum are moved onto it, ends past
    the maximum onto it less 1 mm.

    origin : (2,) sensor position, m. points : (N, 2) ray ends, m. map_min, map_max : (2,)
    corners of the grid, m. Returns (N, 2) m.
    """
    o = np.asarray(origin, dtype=np.float64)[:2]
    w = np.array(points, dtype=np.float64)[:, :2].copy()
    _clip_ends(
        o[0], o[1], w, float(map_min[0]), float(map_min[1]), float(map_max[0]),
        float(map_max[1]),
    )  # fmt: skip
    return w


@njit(cache=True, error_model="numpy")  # a zero-length ray divides as NumPy did
def _clip_ends(ox, oy, w, x0, y0, x1, y1):
    """`ray_ends_clipped` in place on ``w`` (N, 2), point by point in the same order of steps
    (low x, low y, high x, high y), compiled: every costmap update of every robot clears along
    each beam of each scan, and the NumPy form cost a dozen array passes a scan."""
    for i in range(w.shape[0]):
        if w[i, 0] < x0:
            t = (x0 - ox) / (w[i, 0] - ox)
            w[i, 1] = oy + (w[i, 1] - oy) * t
            w[i, 0] = x0
        if w[i, 1] < y0:
            t = (y0 - oy) / (w[i, 1] - oy)
            w[i, 0] = ox + (w[i, 0] - ox) * t
            w[i, 1] = y0
        if w[i, 0] > x1:
            t = (x1 - ox) / (w[i, 0] - ox)
            w[i, 1] = oy + (w[i, 1] - oy) * t
            w[i, 0] = x1 - 0.001
        if w[i, 1] > y1:
            t = (y1 - oy) / (w[i, 1] - oy)
            w[i, 0] = ox + (w[i, 0] - ox) * t
            w[i, 1] = y1 - 0.001


@njit(cache=True, error_model="numpy")  # a zero-length ray divides as NumPy did
def clear_along_rays(grid, ox, oy, points, x0, y0, x1, y1, resolution, sx, sy, max_length, value):
    """ObstacleLayer::raytraceFreespace's clearing in one compiled pass: each point's ray from
    the sensor at (ox, oy) m is pulled back into the map box [x0, x1) x [y0, y1) m
    (`ray_ends_clipped`), its end cell taken (`cells_from_points`, floor), and when that cell
    is on the grid the line from the sensor's cell (sx, sy) to it is set to ``value``
    (`trace_rays`, cut at ``max_length`` cells). points : (N, >= 2) m. The same cells as those
    steps one after another."""
    w = np.empty((points.shape[0], 2))
    for i in range(points.shape[0]):
        w[i, 0] = points[i, 0]
        w[i, 1] = points[i, 1]
    _clip_ends(ox, oy, w, x0, y0, x1, y1)
    h, wd = grid.shape
    ends = np.empty((w.shape[0], 2), np.int64)
    n = 0
    for i in range(w.shape[0]):
        fx = (w[i, 0] - x0) / resolution
        fy = (w[i, 1] - y0) / resolution
        if fx >= 0.0 and fy >= 0.0 and fx < wd and fy < h:  # floor(f) in [0, n) (not NaN)
            ends[n, 0] = math.floor(fx)
            ends[n, 1] = math.floor(fy)
            n += 1
    trace_rays(grid, sx, sy, ends[:n], max_length, value)
