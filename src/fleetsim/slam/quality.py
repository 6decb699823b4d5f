"""How good a SLAM run is, against the simulator's ground truth (issue 17's metrics).

- `ate`: the absolute trajectory error, RMS of the position error after the rigid alignment
  (Horn / Umeyama, rotation and translation, no scale) of the estimate onto the truth, as the
  TUM RGB-D benchmark defines it. Written out in NumPy in a few lines rather than adding
  ``evo`` for one function.
- `occupancy_precision_recall`: occupied-cell precision and recall of a map against the
  world's true occupancy after the best small rigid alignment, a cell counting within 0.1 m;
  recall over the true occupied cells a laser can see from where the robot can go
  (`surface_cells`), explored or not, or over those a route's scans hit (`visible_cells`).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree


def ate(est: np.ndarray, truth: np.ndarray) -> float:
    """RMS position error (m) of (N, 2) ``est`` after its rigid alignment onto (N, 2) ``truth``."""
    est, truth = np.asarray(est, float), np.asarray(truth, float)
    me, mt = est.mean(0), truth.mean(0)
    u, _, vt = np.linalg.svd((truth - mt).T @ (est - me))
    d = np.diag([1.0, np.sign(np.linalg.det(u @ vt))])
    rot = u @ d @ vt
    aligned = (est - me) @ rot.T + mt
    return float(np.sqrt(np.mean(np.sum((aligned - truth) ** 2, axis=1))))


def surface_cells(occupied: np.ndarray, start: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: the occupied cells a robot starting at cell ``start`` (row, col) can see.

    Those with a free 8-neighbour in the free region connected to ``start`` (4-connected):
    the inside of a thick wall or of a solid desk, and the outside of the outer walls, cannot be
    seen by any laser, so a map cannot be asked to hold them.
    """
    free = ~occupied
    labels, _ = ndimage.label(free, structure=ndimage.generate_binary_structure(2, 1))
    if labels[start] == 0:
        raise ValueError(f"the start cell {start} is occupied in the true map")
    reachable = labels == labels[start]
    near = ndimage.binary_dilation(reachable, structure=ndimage.generate_binary_structure(2, 2))
    return occupied & near


@numba.njit(cache=True)
def _first_walls(occ, ox, oy, res, poses, angles, max_range, seen):
    """Mark in ``seen`` the first occupied cell of each beam (an exact grid traversal)."""
    h, w = occ.shape
    limit = max_range / res
    for i in range(poses.shape[0]):
        gx, gy = (poses[i, 0] - ox) / res, (poses[i, 1] - oy) / res
        cx0, cy0 = math.floor(gx), math.floor(gy)
        if cx0 < 0 or cy0 < 0 or cx0 >= w or cy0 >= h or occ[cy0, cx0]:
            continue  # a laser inside a wall or off the map sees nothing
        for a in angles:
            dx, dy = math.cos(poses[i, 2] + a), math.sin(poses[i, 2] + a)
            sx = 1 if dx > 0 else -1
            sy = 1 if dy > 0 else -1
            # the ray parameter (cells) at the next x / y cell border, and between borders
            tx = (cx0 + (dx > 0) - gx) / dx if dx != 0 else math.inf
            ty = (cy0 + (dy > 0) - gy) / dy if dy != 0 else math.inf
            ddx = abs(1.0 / dx) if dx != 0 else math.inf
            ddy = abs(1.0 / dy) if dy != 0 else math.inf
            cx, cy = cx0, cy0
            while True:
                if tx < ty:
                    t, cx, tx = tx, cx + sx, tx + ddx
                else:
                    t, cy, ty = ty, cy + sy, ty + ddy
                if t >= limit or cx < 0 or cy < 0 or cx >= w or cy >= h:
                    break
                if occ[cy, cx]:
                    seen[cy, cx] = True
                    break


def visible_cells(
    occupied: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    sensor_poses: np.ndarray,
    angles: np.ndarray,
    max_range: float,
) -> np.ndarray:
    """(H, W) bool: the occupied cells a laser's beams hit first from any of its poses.

    Parameters
    ----------
    occupied : (H, W) bool true occupancy at ``resolution`` m/cell, cell (0, 0)'s corner at
        ``origin`` (m).
    sensor_poses : (N, 3) the laser's poses (m, m, rad) in the map's frame, e.g. every scan of
        a route (a route that does not explore the whole world is scored on what it passed).
    angles : (B,) the beams' angles in the laser's frame (rad): the laser's own field of view
        and beam count, so that a wall counts only where a beam of this laser lands on it.
    max_range : m; a wall farther along the beam than this is not seen.

    Each beam is followed cell by cell through every cell it crosses (Amanatides and Woo's
    traversal), so a beam cannot slip between two occupied cells that touch at a corner, as a
    wall drawn diagonally in a map does: the simulator's laser cannot either (the walls are
    extruded from the same cells). Written out (a few lines of numba) because scikit-image's
    ``line`` is Bresenham's, which takes such diagonal steps.
    """
    occ = np.ascontiguousarray(occupied, dtype=np.bool_)
    seen = np.zeros_like(occ)
    poses = np.ascontiguousarray(np.asarray(sensor_poses, float).reshape(-1, 3))
    _first_walls(
        occ, float(origin[0]), float(origin[1]), float(resolution), poses,
        np.ascontiguousarray(angles, dtype=np.float64), float(max_range), seen,
    )  # fmt: skip
    return seen


def occupancy_precision_recall(
    slam_xy: np.ndarray,
    true_occupied: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    start: tuple[float, float] | None,
    tolerance: float = 0.1,
    shifts: float = 0.2,
    turns: float = np.radians(2.0),
    visible: np.ndarray | None = None,
) -> tuple[float, float, tuple[float, float, float]]:
    """Occupied-cell precision and recall of a SLAM map against the true occupancy.

    Parameters
    ----------
    slam_xy : (N, 2) centres (m) of the SLAM map's occupied cells, in the true map's frame.
    true_occupied : (H, W) bool, the true occupancy at ``resolution`` m/cell, cell (0, 0)'s
        corner at ``origin`` (m).
    start : where the robot started (m): the true cells it could see are those of
        `surface_cells` from there (unused with ``visible``).

    Returns
    -------
    ``(precision, recall, (dx m, dy m, yaw rad))`` at the best rigid alignment of the SLAM map
    (a grid search of +-``shifts`` m in 0.05 m steps and +-``turns`` in 0.5 degree steps, best
    precision + recall): precision is the share of SLAM cells within ``tolerance`` m of a true
    occupied cell, recall the share of the visible true cells within ``tolerance`` of a SLAM
    cell. Recall counts every visible wall of the world, seen or not, so a run that leaves part
    of the world unexplored scores low; give ``visible`` (H, W) bool (`visible_cells` of a route)
    to count only those cells instead.
    """
    slam_xy = np.asarray(slam_xy, float).reshape(-1, 2)
    occ = np.asarray(true_occupied, bool)
    h, w = occ.shape
    if visible is None:
        sc = (int((start[1] - origin[1]) // resolution), int((start[0] - origin[0]) // resolution))
        ty, tx = np.nonzero(surface_cells(occ, sc))
    else:
        ty, tx = np.nonzero(visible & occ)
    true_xy = np.c_[origin[0] + (tx + 0.5) * resolution, origin[1] + (ty + 0.5) * resolution]
    dist_true = ndimage.distance_transform_edt(~occ) * resolution
    best = (0.0, 0.0, (0.0, 0.0, 0.0))
    if len(slam_xy) == 0 or len(true_xy) == 0:
        return best
    best_key = (-1.0, 0.0)
    steps = np.arange(-shifts, shifts + 1e-9, 0.05)
    for yaw in np.arange(-turns, turns + 1e-9, np.radians(0.5)):
        c, s = np.cos(yaw), np.sin(yaw)
        turned = slam_xy @ np.array([[c, s], [-s, c]])
        for dx in steps:
            for dy in steps:
                q = turned + np.array([dx, dy])
                gx = np.floor((q[:, 0] - origin[0]) / resolution).astype(int)
                gy = np.floor((q[:, 1] - origin[1]) / resolution).astype(int)
                inside = (gx >= 0) & (gy >= 0) & (gx < w) & (gy < h)
                d_true = np.full(len(q), np.inf)
                d_true[inside] = dist_true[gy[inside], gx[inside]]
                precision = float((d_true <= tolerance + 1e-9).mean())
                if precision + 1.0 < best_key[0]:
                    continue  # cannot beat the best even with full recall
                d, _ = cKDTree(q).query(true_xy, distance_upper_bound=tolerance + 1e-9)
                recall = float(np.isfinite(d).mean())
                # ties (several shifts within the tolerance): the closest fit
                key = (precision + recall, -float(np.minimum(d_true, 1.0).mean()))
                if key > best_key:
                    best_key = key
                    best = (precision, recall, (float(dx), float(dy), float(yaw)))
    return best
