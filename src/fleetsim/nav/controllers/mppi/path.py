"""MPPI's path handling: the pruned local path, its blocked points, the furthest point reached.

Paths are (N, 3) x, y, yaw in the costmap's frame, m and rad; trajectories (B, T, 3) poses.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


def pruned_path(
    plan: np.ndarray, x: float, y: float, start: int, search_dist: float, prune_distance: float
) -> tuple[np.ndarray, int]:
    """The plan from its point nearest the robot to ``prune_distance`` m of path beyond it.

    The nearest point is searched from index ``start`` along at most ``search_dist`` m of path
    (Nav2's max_robot_pose_search_dist: a path that loops back past the robot is not cut
    there). Returns (the local path (M, 3), the nearest point's index in ``plan``).
    """
    seg = np.hypot(*np.diff(plan[start:, :2], axis=0).T)
    along = np.concatenate([[0.0], np.cumsum(seg)])
    window = int(np.searchsorted(along, search_dist, side="right"))
    window = max(window, 1)
    d2 = ((plan[start : start + window, :2] - (x, y)) ** 2).sum(axis=1)
    near = start + int(np.argmin(d2))
    end = near + int(
        np.searchsorted(along[near - start :] - along[near - start], prune_distance, side="right")
    )
    return plan[near : max(end, near + 1)], near


@njit(cache=True)
def blocked_points(costs, origin_x, origin_y, resolution, path):
    """(N,) bool: path points on an INSCRIBED or LETHAL cell, or off the grid."""
    h, w = costs.shape
    out = np.zeros(path.shape[0], dtype=np.bool_)
    for i in range(path.shape[0]):
        cx = math.floor((path[i, 0] - origin_x) / resolution)
        cy = math.floor((path[i, 1] - origin_y) / resolution)
        if cx < 0 or cy < 0 or cx >= w or cy >= h:
            out[i] = True
        else:
            c = costs[cy, cx]
            out[i] = c >= 253 and c != 255
    return out


@njit(cache=True)
def furthest_reached(poses, path):
    """The highest path index nearest to any trajectory's last pose (0 for an empty batch)."""
    best = 0
    nt = poses.shape[1]
    for b in range(poses.shape[0]):
        x, y = poses[b, nt - 1, 0], poses[b, nt - 1, 1]
        near, dmin = 0, np.inf
        for i in range(path.shape[0]):
            d = (path[i, 0] - x) ** 2 + (path[i, 1] - y) ** 2
            if d < dmin:
                dmin, near = d, i
        if near > best:
            best = near
    return best


def target_index(furthest: int, offset: int, blocked: np.ndarray) -> int:
    """``furthest + offset`` (clipped to the path), moved on past blocked points."""
    n = blocked.shape[0]
    i = min(furthest + offset, n - 1)
    while i < n - 1 and blocked[i]:
        i += 1
    return i
