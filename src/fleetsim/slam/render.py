"""The published map: scans ray-cast into hit and visit counts (gmapping's ``updateMap``).

gmapping rebuilds the published map from scratch every ``map_update_interval`` by replaying
every scan of the best particle's trajectory, a cost that grows with the length of the run.
fleetsim keeps a *base* grid holding every scan up to the particles' most recent common
ancestor in the trajectory tree (the history all particles agree on, which never changes
again), adds each scan to it once, and renders a map as a copy of the base plus the few scans
from that ancestor to the best particle. The cost of a map is the grid's size plus the scans
since the particles last coalesced, whatever the length of the run.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True)
def cast_scan(visits, hits, pose, laser, ranges, angles, usable, geom):
    """Ray-cast one scan into ``visits`` / ``hits`` (H, W) int32 counts, in place.

    Each beam marks the cells from the laser to its endpoint visited (Bresenham); an endpoint
    within ``usable`` m is a hit, a longer beam is cut at ``usable`` m and marks only free
    space. ``pose`` is the base pose (m, m, rad) in the map frame, ``laser`` the laser in the
    base frame, ``ranges``/``angles`` (B,) m/rad, ``geom`` ``(origin x, origin y, delta)``.
    """
    ox, oy, delta = geom[0], geom[1], geom[2]
    h, w = visits.shape
    c, s = math.cos(pose[2]), math.sin(pose[2])
    lx = pose[0] + c * laser[0] - s * laser[1]
    ly = pose[1] + s * laser[0] + c * laser[1]
    lt = pose[2] + laser[2]
    x0 = math.floor((lx - ox) / delta)
    y0 = math.floor((ly - oy) / delta)
    for b in range(ranges.shape[0]):
        r = ranges[b]
        hit = r < usable
        if not hit:
            r = usable
        a = lt + angles[b]
        x1 = math.floor((lx + r * math.cos(a) - ox) / delta)
        y1 = math.floor((ly + r * math.sin(a) - oy) / delta)
        dx, dy = abs(x1 - x0), -abs(y1 - y0)
        sx = 1 if x0 < x1 else -1
        sy = 1 if y0 < y1 else -1
        err = dx + dy
        x, y = x0, y0
        while True:
            if x == x1 and y == y1:
                break
            if 0 <= x < w and 0 <= y < h:
                visits[y, x] += 1
            e2 = 2 * err
            if e2 >= dy:
                err += dy
                x += sx
            if e2 <= dx:
                err += dx
                y += sy
        if 0 <= x1 < w and 0 <= y1 < h:
            visits[y1, x1] += 1
            if hit:
                hits[y1, x1] += 1


def occupancy_from_counts(visits: np.ndarray, hits: np.ndarray, occ_thresh: float) -> np.ndarray:
    """(H, W) int8: 100 where hits/visits > ``occ_thresh``, 0 where seen below it, -1 unseen."""
    out = np.full(visits.shape, -1, dtype=np.int8)
    seen = visits > 0
    ratio = np.zeros(visits.shape)
    np.divide(hits, visits, out=ratio, where=seen)
    out[seen] = np.where(ratio[seen] > occ_thresh, 100, 0)
    return out


class CountGrid:
    """Hit and visit counts over a growing extent (cell (0, 0)'s corner at ``geom[:2]``)."""

    def __init__(self, height: int, width: int, geom: np.ndarray) -> None:
        self.visits = np.zeros((height, width), dtype=np.int32)
        self.hits = np.zeros((height, width), dtype=np.int32)
        self.geom = np.array(geom, dtype=float)

    def grow(self, left: int, bottom: int, right: int, top: int) -> None:
        """Add cells on each side (unseen)."""
        pad = ((bottom, top), (left, right))
        self.visits = np.pad(self.visits, pad)
        self.hits = np.pad(self.hits, pad)
        self.geom[0] -= left * self.geom[2]
        self.geom[1] -= bottom * self.geom[2]

    def copy(self) -> CountGrid:
        out = CountGrid.__new__(CountGrid)
        out.visits, out.hits, out.geom = self.visits.copy(), self.hits.copy(), self.geom.copy()
        return out

    def add(self, pose, laser, ranges, angles, usable) -> None:
        cast_scan(self.visits, self.hits, pose, laser, ranges, angles, usable, self.geom)
