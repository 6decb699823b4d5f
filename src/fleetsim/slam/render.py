"""The published map: every processed scan ray-cast into each particle's own visit and hit
counts (gmapping's ``updateMap``, kept up to date instead of rebuilt).

gmapping rebuilds the published map from scratch every ``map_update_interval`` by replaying
every scan along the best particle's trajectory, a cost that grows with the length of the run.
fleetsim casts each processed scan once into every particle's count grid, a `CowTiles` grid
whose tiles resampled particles share, so a published map is the best particle's counts read
out: its cost is the map's size, whatever the length of the run. The counts are those
gmapping's replay makes: the cells a beam crosses are visited (its start cell included, its
end cell not), a beam shorter than ``maxUrange`` adds a visit and a hit at its end cell, and a
longer one is cut at ``maxUrange`` and marks free space only.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .scan_align import laser_origin
from .tiles import MASK, SHIFT, writable_tile

_SATURATED = 65535  # uint16 counts stop here (a cell visited that often is settled)


@numba.njit(cache=True, inline="always")
def _bump(pool, t, x, y, channel):
    v = pool[t, y & MASK, x & MASK, channel]
    if v < _SATURATED:
        pool[t, y & MASK, x & MASK, channel] = v + 1


@numba.njit(cache=True)
def cast_counts(
    pool, table, refs, free, top, blank, start, poses, laser, ranges, angles, usable, geom
):
    """Ray-cast one scan into each particle's counts (from ``start`` on); a `CowTiles` kernel.

    ``pool`` (T, TILE, TILE, 2) uint16 holds visits and hits per cell; ``poses`` (P, 3) are the
    base poses (m, m, rad) in the map frame, ``laser`` the laser in the base frame,
    ``ranges``/``angles`` (B,) m/rad, all beams up to maxRange; ``geom`` ``(origin x, origin
    y, delta)``; every cell a beam reaches lies inside the grid (grow it first). Returns
    ``(next particle, free-stack top, tiles needed)``: early when the free tiles might not
    cover the next particle's scan.
    """
    ox, oy, delta = geom[0], geom[1], geom[2]
    nb = ranges.shape[0]
    x1s = np.empty(nb, dtype=np.int64)
    y1s = np.empty(nb, dtype=np.int64)
    for p in range(start, poses.shape[0]):
        lx, ly, lt = laser_origin(poses[p, 0], poses[p, 1], poses[p, 2], laser)
        x0 = math.floor((lx - ox) / delta)
        y0 = math.floor((ly - oy) / delta)
        bx0, bx1, by0, by1 = x0, x0, y0, y0
        for b in range(nb):
            r = min(ranges[b], usable)
            x1s[b] = math.floor((lx + r * math.cos(lt + angles[b]) - ox) / delta)
            y1s[b] = math.floor((ly + r * math.sin(lt + angles[b]) - oy) / delta)
            bx0, bx1 = min(bx0, x1s[b]), max(bx1, x1s[b])
            by0, by1 = min(by0, y1s[b]), max(by1, y1s[b])
        need = ((bx1 >> SHIFT) - (bx0 >> SHIFT) + 1) * ((by1 >> SHIFT) - (by0 >> SHIFT) + 1)
        if top < need:
            return p, top, need
        key = -1
        t = -1
        for b in range(nb):
            x1, y1 = x1s[b], y1s[b]
            dx, dy = abs(x1 - x0), -abs(y1 - y0)
            sx = 1 if x0 < x1 else -1
            sy = 1 if y0 < y1 else -1
            err = dx + dy
            x, y = x0, y0
            while x != x1 or y != y1:  # Bresenham, the end cell excluded
                k = (y >> SHIFT) * table.shape[2] + (x >> SHIFT)
                if k != key:
                    t, top = writable_tile(
                        pool, table, refs, free, top, blank, p, y >> SHIFT, x >> SHIFT
                    )
                    key = k
                _bump(pool, t, x, y, 0)
                e2 = 2 * err
                if e2 >= dy:
                    err += dy
                    x += sx
                if e2 <= dx:
                    err += dx
                    y += sy
            if ranges[b] < usable:
                k = (y1 >> SHIFT) * table.shape[2] + (x1 >> SHIFT)
                if k != key:
                    t, top = writable_tile(
                        pool, table, refs, free, top, blank, p, y1 >> SHIFT, x1 >> SHIFT
                    )
                    key = k
                _bump(pool, t, x1, y1, 0)
                _bump(pool, t, x1, y1, 1)
    return poses.shape[0], top, 0


def occupancy_from_counts(visits: np.ndarray, hits: np.ndarray, occ_thresh: float) -> np.ndarray:
    """(H, W) int8: 100 where hits/visits > ``occ_thresh``, 0 where seen below it, -1 unseen."""
    out = np.full(visits.shape, -1, dtype=np.int8)
    seen = visits > 0
    ratio = np.zeros(visits.shape)
    np.divide(hits, visits, out=ratio, where=seen)
    out[seen] = np.where(ratio[seen] > occ_thresh, 100, 0)
    return out
