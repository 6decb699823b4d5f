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

`path_distance` is a fleetsim addition for explore's ``progress_on_path``: the distance from
the robot to a frontier through the cells it can drive on, not the straight line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage, sparse
from scipy.sparse.csgraph import dijkstra

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
    region = _reachable(data, resolution, origin, robot)
    if region is None:
        return []
    reachable = region[0] & (data == 0)
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


def _reachable(
    data: np.ndarray, resolution: float, origin: tuple[float, float], robot: tuple[float, float]
) -> tuple[np.ndarray, tuple[int, int]] | None:
    """The (H, W) bool cells the robot can drive through (known, cost below `INSCRIBED`,
    4-connected to its cell, or to the nearest free cell when it stands on cost, as
    explore_lite starts) and its cell (row, col); None when it is off the grid or nothing is
    free."""
    h, w = data.shape
    rx = int(np.floor((robot[0] - origin[0]) / resolution))
    ry = int(np.floor((robot[1] - origin[1]) / resolution))
    free = data == 0
    if not (0 <= rx < w and 0 <= ry < h) or not free.any():
        return None
    passable = (data >= 0) & (data < INSCRIBED)
    labels, _ = ndimage.label(passable, structure=FOUR)
    start = labels[ry, rx]
    if start == 0:
        _, (iy, ix) = ndimage.distance_transform_edt(~free, return_indices=True)
        ry, rx = int(iy[ry, rx]), int(ix[ry, rx])
        start = labels[ry, rx]
    return labels == start, (ry, rx)


def path_distance(
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    robot: tuple[float, float],
    points: np.ndarray,
) -> float:
    """Distance (m) from ``robot`` to the nearest of ``points`` (frontier cell centres, m)
    through the cells it can drive on (8-connected, diagonal steps sqrt(2) cells; a frontier
    cell is reached from a drivable 4-neighbour); inf when none is reachable.

    Dijkstra over the robot's drivable region with scipy's ``csgraph`` (one run per call).
    """
    data = np.asarray(data)
    region = _reachable(data, resolution, origin, robot)
    if region is None:
        return math.inf
    ok, (ry, rx) = region
    h, w = ok.shape
    index = np.full((h, w), -1, dtype=np.int64)
    ys, xs = np.nonzero(ok)
    index[ys, xs] = np.arange(len(ys))
    rows, cols, costs = [], [], []
    for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):
        y2, x2 = ys + dy, xs + dx
        good = (y2 < h) & (x2 >= 0) & (x2 < w)
        good[good] &= ok[y2[good], x2[good]]
        rows.append(index[ys[good], xs[good]])
        cols.append(index[y2[good], x2[good]])
        costs.append(np.full(int(good.sum()), math.hypot(dx, dy) * resolution))
    n = len(ys)
    graph = sparse.csr_matrix(
        (np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )
    dist = dijkstra(graph, directed=False, indices=int(index[ry, rx]))
    px = np.floor((np.asarray(points)[:, 0] - origin[0]) / resolution).astype(int)
    py = np.floor((np.asarray(points)[:, 1] - origin[1]) / resolution).astype(int)
    best = math.inf
    for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        ny, nx = py + dy, px + dx
        inside = (ny >= 0) & (ny < h) & (nx >= 0) & (nx < w)
        k = index[ny[inside], nx[inside]]
        k = k[k >= 0]
        if len(k):
            best = min(best, float(dist[k].min()) + resolution)
    return best
