"""explore_lite's frontier search (``frontier_search.cpp``) over an OccupancyGrid, vectorised.

explore_lite walks breadth-first from the robot's cell through cells whose cost does not rise
(from free space that means free cells only) and marks as frontier every unknown cell with a
free 4-neighbour; 8-connected frontier cells form one frontier. fleetsim walks through every
cell the robot's centre may occupy (cost below the inscribed cost, published as
`INSCRIBED`) instead of free cells only: explore_lite's walk stops at a door whose middle
carries a little inflation cost (a 1 m door with the hunter's 1 m inflation radius), so a
robot that has entered a room finds no frontier beyond it and stops with most of the world
unknown (m-explore issues #26 and #33 report exactly that; frontier_exploration issue #32
asks for this very change). Frontier cells are still unknown cells with a *free* 4-neighbour
in that region. The region is the 4-connected component holding the robot's cell (or the
nearest such cell), found with `scipy.ndimage.label` instead of a queue, as are the frontiers.
A frontier's ``cost = potential_scale * min_distance * res - gain_scale * size * res``; those
smaller than ``min_frontier_size`` m are dropped, and the list is sorted by cost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

FOUR = ndimage.generate_binary_structure(2, 1)
EIGHT = ndimage.generate_binary_structure(2, 2)
#: costmap_2d's inscribed cost (253) as the costmap publisher writes it; lethal is 100
INSCRIBED = 99


@dataclass(frozen=True)
class Frontier:
    """One frontier: its cells' count, centroid, closest cell to the robot, cost (map frame)."""

    size: int
    centroid: tuple[float, float]
    middle: tuple[float, float]
    initial: tuple[float, float]
    min_distance: float
    cost: float
    points: np.ndarray  # (N, 2) cell centres, m
    #: where the robot sees it from (explore's ``view_points``, `fleetsim.nav.explore.view_points`)
    view_point: tuple[float, float] | None = None

    @property
    def goal(self) -> tuple[float, float]:
        """The point explore sends move_base to: the view point, else (explore_lite) the
        centroid."""
        return self.view_point if self.view_point is not None else self.centroid


def frontiers_from_grid(
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    robot: tuple[float, float],
    potential_scale: float = 1e-3,
    gain_scale: float = 1.0,
    min_frontier_size: float = 0.5,
) -> list[Frontier]:
    """Frontiers of the (H, W) int8 grid ``data`` (-1 unknown, 0 free, >0 cost), cheapest first.

    ``robot`` is the robot's position (m) in the grid's frame; a robot off the grid sees none.
    The robot reaches every cell of cost below `INSCRIBED` connected to it.
    """
    data = np.asarray(data)
    h, w = data.shape
    rx = int(np.floor((robot[0] - origin[0]) / resolution))
    ry = int(np.floor((robot[1] - origin[1]) / resolution))
    if not (0 <= rx < w and 0 <= ry < h):
        return []
    free = data == 0
    passable = (data >= 0) & (data < INSCRIBED)
    if not free.any():
        return []
    labels, _ = ndimage.label(passable, structure=FOUR)
    start = labels[ry, rx]
    if start == 0:  # the robot stands on cost: start from the nearest free cell, as explore_lite
        _, (iy, ix) = ndimage.distance_transform_edt(~free, return_indices=True)
        start = labels[iy[ry, rx], ix[ry, rx]]
    reachable = (labels == start) & free
    unknown = data < 0
    frontier = unknown & ndimage.binary_dilation(reachable, structure=FOUR)
    groups, count = ndimage.label(frontier, structure=EIGHT)
    out = []
    if count == 0:
        return out
    ys, xs = np.nonzero(groups)
    ids = groups[ys, xs]
    order = np.argsort(ids, kind="stable")
    ys, xs, ids = ys[order], xs[order], ids[order]
    splits = np.flatnonzero(np.diff(ids)) + 1
    for gy, gx in zip(np.split(ys, splits), np.split(xs, splits)):
        size = len(gx)
        if size * resolution < min_frontier_size:
            continue
        px = origin[0] + (gx + 0.5) * resolution
        py = origin[1] + (gy + 0.5) * resolution
        d = np.hypot(px - robot[0], py - robot[1])
        k = int(np.argmin(d))
        mid = size // 2
        out.append(
            Frontier(
                size=size,
                centroid=(float(px.mean()), float(py.mean())),
                middle=(float(px[mid]), float(py[mid])),
                initial=(float(px[k]), float(py[k])),
                min_distance=float(d[k]),
                cost=float(potential_scale * d[k] * resolution - gain_scale * size * resolution),
                points=np.c_[px, py],
            )
        )
    out.sort(key=lambda f: f.cost)
    return out
