"""base_local_planner's MapGrid: path and goal distance maps over the local costmap.

Distances are in cells, by breadth-first search over 4-neighbours from target cells (the
global plan's cells for the path map, the plan's last cell inside the local map for the goal
map). Cells that are LETHAL, INSCRIBED or NO_INFORMATION (and not under the robot) get the
"obstacle" distance ``size``; cells never reached get ``size + 1``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fleetsim.nav.costmap.costmap_2d import NO_INFORMATION, Costmap2D


@njit(cache=True)
def distances_from_targets(costs, targets, passable):
    """Multi-source BFS distances (cells) from ``targets`` (MapGrid::computeTargetDistance).

    Parameters
    ----------
    costs : (H, W) uint8 local costmap.
    targets : (K, 2) int64 target cells (column, row), in plan order.
    passable : (H, W) bool, cells never treated as obstacles (under the robot).

    Returns
    -------
    (H, W) float64 distances: 0 at targets, ``H*W`` at obstacles, ``H*W + 1`` unreached.
    """
    h, w = costs.shape
    size = float(h * w)
    dist = np.full((h, w), size + 1.0)
    mark = np.zeros((h, w), dtype=np.bool_)
    qx = np.empty(h * w, dtype=np.int64)
    qy = np.empty(h * w, dtype=np.int64)
    head = 0
    tail = 0
    for k in range(targets.shape[0]):
        x = targets[k, 0]
        y = targets[k, 1]
        if mark[y, x]:
            continue
        mark[y, x] = True
        dist[y, x] = 0.0
        qx[tail] = x
        qy[tail] = y
        tail += 1
    while head < tail:
        x = qx[head]
        y = qy[head]
        head += 1
        for d in range(4):
            nx_ = x + (1 if d == 0 else (-1 if d == 1 else 0))
            ny_ = y + (1 if d == 2 else (-1 if d == 3 else 0))
            if nx_ < 0 or ny_ < 0 or nx_ >= w or ny_ >= h or mark[ny_, nx_]:
                continue
            mark[ny_, nx_] = True
            c = costs[ny_, nx_]
            if not passable[ny_, nx_] and c >= 253:
                dist[ny_, nx_] = size
                continue
            if dist[y, x] + 1.0 < dist[ny_, nx_]:
                dist[ny_, nx_] = dist[y, x] + 1.0
            qx[tail] = nx_
            qy[tail] = ny_
            tail += 1
    return dist


def densified_plan(plan_xy: np.ndarray, resolution: float) -> np.ndarray:
    """The plan with points inserted so consecutive points are at most ``resolution`` apart.

    As MapGrid::adjustPlanResolution. plan_xy : (N, 2) m. Returns (M, 2) m.
    """
    p = np.asarray(plan_xy, dtype=np.float64)
    if p.shape[0] < 2:
        return p.copy()
    seg = np.diff(p, axis=0)
    n = np.maximum(1, np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / resolution).astype(np.int64))
    first = np.repeat(np.cumsum(n) - n, n)  # index of each segment's first point
    t = (np.arange(first.shape[0]) - first) / np.repeat(n, n)  # 0, 1/k, ..., (k-1)/k
    starts = np.repeat(p[:-1], n, axis=0)
    out = starts + np.repeat(seg, n, axis=0) * t[:, None]
    return np.concatenate([out, p[-1:]], axis=0)


def plan_cells_in_map(costmap: Costmap2D, plan_xy: np.ndarray) -> np.ndarray:
    """Cells of the densified plan from where it first enters the map until it leaves it.

    Cells that are NO_INFORMATION count as outside (MapGrid::setTargetCells). Returns (K, 2)
    int64 (column, row), in plan order; empty when the plan never enters the map.
    """
    p = np.ascontiguousarray(plan_xy, dtype=np.float64)
    return _plan_cells(p, costmap.origin_x, costmap.origin_y, costmap.resolution, costmap.costs)


@njit(cache=True)
def _plan_cells(p, ox, oy, res, costs):
    """Compiled `plan_cells_in_map` (the points of `densified_plan`, computed alike): it runs
    on every control cycle of every robot, where the NumPy version's dozen small-array calls
    cost ~40 us."""
    h, w = costs.shape
    n_pts = p.shape[0]
    if n_pts == 0:
        return np.empty((0, 2), np.int64)
    total = 1
    for i in range(n_pts - 1):
        dx, dy = p[i + 1, 0] - p[i, 0], p[i + 1, 1] - p[i, 1]
        total += max(1, int(np.ceil(np.hypot(dx, dy) / res)))
    out = np.empty((total, 2), np.int64)
    k = 0
    started = False
    for i in range(n_pts):
        last = i == n_pts - 1
        n = 1
        dx = dy = 0.0
        if not last:
            dx, dy = p[i + 1, 0] - p[i, 0], p[i + 1, 1] - p[i, 1]
            n = max(1, int(np.ceil(np.hypot(dx, dy) / res)))
        for j in range(n):
            if last:
                x, y = p[i, 0], p[i, 1]
            else:
                t = j / n
                x, y = p[i, 0] + dx * t, p[i, 1] + dy * t
            cx = int(np.floor((x - ox) / res))
            cy = int(np.floor((y - oy) / res))
            ok = 0 <= cx < w and 0 <= cy < h and costs[cy, cx] != NO_INFORMATION
            if ok:
                started = True
                out[k, 0] = cx
                out[k, 1] = cy
                k += 1
            elif started:
                return out[:k].copy()
    return out[:k].copy()
