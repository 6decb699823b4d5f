"""Planar rays against an occupancy grid: the walls of a map world are its occupied cells.

Rays walk the grid cell by cell (Amanatides & Woo) and jump across open space using a
clearance map (distance to the nearest occupied cell), so the cost follows the free space a ray
crosses near walls, not the size of the map.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def _dda_start(ox, oy, dx, dy, t, x0, y0, res):
    """Grid traversal state of the ray at parameter ``t``: cell, next boundary params, steps."""
    px = (ox + t * dx - x0) / res
    py = (oy + t * dy - y0) / res
    ix = int(np.floor(px))
    iy = int(np.floor(py))
    if abs(dx) > 1e-15:
        tmx = t + ((ix + (1 if dx > 0 else 0)) - px) * res / dx
    else:
        tmx = np.inf
    if abs(dy) > 1e-15:
        tmy = t + ((iy + (1 if dy > 0 else 0)) - py) * res / dy
    else:
        tmy = np.inf
    return ix, iy, tmx, tmy


@numba.njit(cache=True)
def ranges_from_occupancy(
    origins, angles, range_min, range_max, occupied, clearance, x0, y0, res, zmax
):
    """Ranges of planar rays to the first occupied cell of a grid (walls extruded 0..zmax).

    Parameters
    ----------
    origins : (R, 3) float64 ray origins, world (= map) frame, m.
    angles : (R,) float64 world yaws, rad.
    range_min, range_max : (R,) float64, m.
    occupied : (H, W) bool, row 0 at ``y0`` (OccupancyGrid order); cell (i, j) covers
        ``[x0 + j res, x0 + (j + 1) res) x [y0 + i res, y0 + (i + 1) res)``.
    clearance : (H, W) float32, distance in cells from each cell centre to the nearest occupied
        cell centre (``clearance_from_occupancy``); lets rays jump across open space.
    zmax : wall height, m; rays from above it (or below 0) see nothing.

    Returns
    -------
    (R,) float64 distance to the first occupied cell's boundary, ``inf`` when none within range
    (exactly the boxes a map world is extruded into). A ray starting inside an occupied cell
    hits at ``range_min``.
    """
    h, w = occupied.shape
    n = origins.shape[0]
    out = np.full(n, np.inf)
    for r in range(n):
        oz = origins[r, 2]
        if oz < 0.0 or oz > zmax:
            continue
        ox = origins[r, 0]
        oy = origins[r, 1]
        dx = np.cos(angles[r])
        dy = np.sin(angles[r])
        tmax = range_max[r]
        stepx = 1 if dx > 0 else -1
        stepy = 1 if dy > 0 else -1
        tdx = res / abs(dx) if abs(dx) > 1e-15 else np.inf
        tdy = res / abs(dy) if abs(dy) > 1e-15 else np.inf
        t = range_min[r]
        ix, iy, tmx, tmy = _dda_start(ox, oy, dx, dy, t, x0, y0, res)
        while t <= tmax:
            if 0 <= ix < w and 0 <= iy < h:
                if occupied[iy, ix]:
                    out[r] = t
                    break
                safe = clearance[iy, ix] - 1.5  # cells free around any point of this cell
                if safe > 4.0:
                    t += safe * res
                    ix, iy, tmx, tmy = _dda_start(ox, oy, dx, dy, t, x0, y0, res)
                    continue
            else:
                # outside the grid: stop once moving away from it
                if (ix < 0 and stepx < 0) or (ix >= w and stepx > 0):
                    break
                if (iy < 0 and stepy < 0) or (iy >= h and stepy > 0):
                    break
            if tmx < tmy:
                t = tmx
                tmx += tdx
                ix += stepx
            else:
                t = tmy
                tmy += tdy
                iy += stepy
    return out


def clearance_from_occupancy(occupied: np.ndarray) -> np.ndarray:
    """(H, W) float32 distance (cells) from each cell centre to the nearest occupied centre."""
    from scipy import ndimage

    if not occupied.any():
        return np.full(occupied.shape, np.float32(1e6))
    return ndimage.distance_transform_edt(~occupied).astype(np.float32)
