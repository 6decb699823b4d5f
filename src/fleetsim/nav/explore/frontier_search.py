"""explore_lite's frontier search (``frontier_search.cpp``) over an OccupancyGrid, vectorised.

explore_lite walks breadth-first from the robot's cell through cells whose cost does not rise
(from free space that means free cells only) and marks as frontier every unknown cell with a
free 4-neighbour; 8-connected frontier cells form one frontier. fleetsim walks through every
cell the robot's centre may occupy (cost below the inscribed cost, published as
`INSCRIBED`) instead of free cells only: explore_lite's walk stops at a door whose middle
carries a little inflation cost (a 1 m door with the hunter's 1 m inflation radius), so a
robot that has entered a room finds no frontier beyond it and stops with most of the world
unknown (m-explore issues #26 and #33 report exactly that; frontier_exploration issue #32
asks for this very change). For the same reason a frontier cell is an unknown cell with a
4-neighbour in that region, not only with a *free* one (cost 0): in a door the inflation leaves
free only the middle, and less than ``min_frontier_size`` of it (office, one hunter, seed 5:
a 1.2 m door with the manual's 0.15 m radius and 1 m inflation at scaling 20 had 0.25 m of
free cells, the frontier was dropped, and the room behind it was never explored; any cell
beyond the inscribed radius is where the robot's centre may stand and look from). The region
is the 4-connected component holding the robot's cell (or the nearest such cell), found with
`scipy.ndimage.label` instead of a queue, as are the frontiers.
A frontier's ``cost = potential_scale * min_distance * res - gain_scale * size * res``; those
smaller than ``min_frontier_size`` m are dropped, and the list is sorted by cost.
"""

from __future__ import annotations

import math
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


#: unknown cells kept around the known part of a grid by `known_window`, m
KNOWN_MARGIN = 1.0


def known_window(
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    points: list[tuple[float, float]],
    margin: float = KNOWN_MARGIN,
) -> tuple[np.ndarray, tuple[float, float]]:
    """The part of the (H, W) grid ``data`` holding its known cells (>= 0) and ``points`` (m,
    e.g. the robots), widened by ``margin`` m of unknown cells and clipped to the grid, as a view,
    with that part's origin.

    A SLAM map starts at gmapping's ``xmin..ymax`` (slam_explore's hunter: 100 x 100 m, 4 M
    cells) around a 30 x 20 m office, 3 % of it known: explore's flood fills and wavefronts over
    the whole grid took ~300 ms a plan (navfn's field through unknown cells alone 200 ms), over
    the window ~20 ms. Frontier cells are unknown cells next to known ones, so the window holds
    every frontier and every cell the search walks; a wavefront through unknown cells
    (``path_distance_field`` with ``allow_unknown``) no longer finds ways looping more than
    ``margin`` outside everything known, which cost ``margin`` / resolution unknown cells each
    way (navfn charges an unknown cell as five free ones)."""
    data = np.asarray(data)
    h, w = data.shape
    rows = np.flatnonzero((data >= 0).any(axis=1))
    if rows.size == 0:
        return data, origin
    cols = np.flatnonzero((data >= 0).any(axis=0))
    y0, y1, x0, x1 = int(rows[0]), int(rows[-1]), int(cols[0]), int(cols[-1])
    for px, py in points:
        cx = math.floor((px - origin[0]) / resolution)
        cy = math.floor((py - origin[1]) / resolution)
        x0, x1, y0, y1 = min(x0, cx), max(x1, cx), min(y0, cy), max(y1, cy)
    pad = max(2, math.ceil(margin / resolution))
    y0, x0 = max(0, y0 - pad), max(0, x0 - pad)
    y1, x1 = min(h, y1 + pad + 1), min(w, x1 + pad + 1)
    return data[y0:y1, x0:x1], (origin[0] + x0 * resolution, origin[1] + y0 * resolution)


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
    reachable = labels == start
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
