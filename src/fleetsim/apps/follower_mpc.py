"""The predictive follower's sampling MPC: every velocity sample rolled out over the local costmap
and scored against the target's predicted path, in one compiled call.

A sample is a command ``(v, w)`` the robot reaches under its acceleration limits and holds over
the horizon (the sample set of base_local_planner's DWA, see `fleetsim.nav.controllers.rollout`);
the robot pose at each step is checked with the footprint on the local costmap
(`fleetsim.nav.costmap.footprint.footprint_cost_at`, the planners' own kernel) and scored
against where the tracker predicts the target at that time:

- visibility (the strong cost): the target's bearing from the camera beyond ``fov_margin`` of
  the half field of view costs ``fov_weight`` times the excess squared; outside the field of view
  or beyond ``detection_range`` (or nearer than ``min_range``) costs ``out_of_view_cost`` per
  step. The marker is seen from behind only: the camera's angle off the target's back beyond
  ``face_angle`` costs ``fov_weight`` times the excess squared too;
- following: the squared distance to the desired pose ``follow_distance`` behind the target;
- safety: a footprint on a lethal or unknown cell, or off the map, makes the sample infeasible
  (infinite cost), and so does coming within ``min_gap`` of the target's centre; other costmap
  cost adds ``obstacle_weight`` times its share of the lethal cost;
- smoothness: the change from the previous command.

Steps are weighted by how sure the prediction is: ``1 / (1 + (sd / sd_scale)^2)`` with ``sd``
the predicted position's standard deviation, so a far, uncertain prediction pulls less.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fleetsim.nav.controllers.rollout import new_velocity
from fleetsim.nav.costmap.costmap_2d import FREE_SPACE, LETHAL_OBSTACLE
from fleetsim.nav.costmap.footprint import footprint_cost_at

#: weights vector layout of `rollout_costs`
W_FOV, W_OUT, W_FOLLOW, W_OBSTACLE, W_SMOOTH, W_FACE = range(6)


@njit(cache=True, inline="always")
def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True)
def rollout_costs(
    costs,
    origin_x,
    origin_y,
    resolution,
    outline,
    pose,
    velocity,
    samples,
    accel,
    dt,
    targets,
    target_sd,
    camera_x,
    geometry,
    weights,
    previous,
):
    """Cost of each velocity sample, and its poses.

    Parameters
    ----------
    costs : (H, W) uint8 local costmap; origin_x, origin_y, resolution: its origin and cell (m).
    outline : (M, 2) footprint outline points in the robot frame (m).
    pose : (3,) robot x, y, yaw in the costmap frame (m, rad). velocity : (2,) v, w now.
    samples : (S, 2) commanded v (m/s), w (rad/s). accel : (2,) limits (m/s^2, rad/s^2).
    dt : step (s). targets : (T, 3) predicted target x, y, heading in the costmap frame at
    steps 1..T. target_sd : (T,) the predictions' position standard deviation (m).
    camera_x : the camera's offset ahead of the base (m).
    geometry : (7,) half fov (rad), fov margin (share), detection range, min range, follow
    distance, min gap (m), face angle (rad). weights : (6,) see ``W_*`` (+ sd scale at [6]).
    previous : (2,) the last command.

    Returns
    -------
    (S,) float64 costs (inf: infeasible) and (S, T, 3) poses.
    """
    n = samples.shape[0]
    steps = targets.shape[0]
    out = np.zeros(n)
    poses = np.empty((n, steps, 3))
    half_fov, margin, rng, min_rng, behind, gap, face = (
        geometry[0],
        geometry[1],
        geometry[2],
        geometry[3],
        geometry[4],
        geometry[5],
        geometry[6],
    )
    inner = half_fov * margin
    for i in range(n):
        x, y, th = pose[0], pose[1], pose[2]
        v, w = velocity[0], velocity[1]
        total = weights[W_SMOOTH] * (
            (samples[i, 0] - previous[0]) ** 2 + 0.1 * (samples[i, 1] - previous[1]) ** 2
        )
        for k in range(steps):
            v = new_velocity(samples[i, 0], v, accel[0], dt)
            w = new_velocity(samples[i, 1], w, accel[1], dt)
            x += v * math.cos(th) * dt
            y += v * math.sin(th) * dt
            th += w * dt
            poses[i, k, 0], poses[i, k, 1], poses[i, k, 2] = x, y, th
            fc = footprint_cost_at(costs, origin_x, origin_y, resolution, outline, x, y, th)
            if fc < 0.0:
                total = np.inf
                break
            tx, ty, tth = targets[k, 0], targets[k, 1], targets[k, 2]
            if math.hypot(tx - x, ty - y) < gap:
                total = np.inf
                break
            sd = target_sd[k] / weights[6]
            trust = 1.0 / (1.0 + sd * sd)
            cx = x + camera_x * math.cos(th)
            cy = y + camera_x * math.sin(th)
            r = math.hypot(tx - cx, ty - cy)
            bearing = abs(_wrap(math.atan2(ty - cy, tx - cx) - th))
            step = weights[W_OBSTACLE] * fc / 252.0
            if bearing > inner:
                step += trust * weights[W_FOV] * (bearing - inner) ** 2
            if bearing > half_fov or r > rng or r < min_rng:
                step += trust * weights[W_OUT]
            off_back = abs(_wrap(math.atan2(cy - ty, cx - tx) - (tth + math.pi)))
            if off_back > face:
                step += trust * weights[W_FACE] * (off_back - face) ** 2
            dx = x - (tx - behind * math.cos(tth))
            dy = y - (ty - behind * math.sin(tth))
            step += trust * weights[W_FOLLOW] * (dx * dx + dy * dy)
            total += step * dt
        out[i] = total
    return out, poses


def velocity_samples(
    min_v: float, max_v: float, max_w: float, nv: int, nw: int, extra=None
) -> np.ndarray:
    """The sample grid (nv * nw (+ extra), 2): v in [min_v, max_v] (0 included), w in
    [-max_w, max_w] (0 included)."""
    vs = np.unique(np.append(np.linspace(min_v, max_v, nv), 0.0))
    ws = np.unique(np.append(np.linspace(-max_w, max_w, nw), 0.0))
    grid = np.stack(np.meshgrid(vs, ws, indexing="ij"), axis=-1).reshape(-1, 2)
    if extra is not None:
        grid = np.concatenate([grid, np.atleast_2d(extra)])
    return np.ascontiguousarray(grid, dtype=np.float64)


def costs_without_target(
    costs: np.ndarray,
    origin_x: float,
    origin_y: float,
    resolution: float,
    track: np.ndarray,
    radius: float,
) -> np.ndarray:
    """A copy of ``costs`` with the LETHAL cells within ``radius`` of the target's track freed.

    Those marks are the target itself, which the MPC keeps ``min_gap`` from by its prediction;
    a laser that sees nothing behind them (beyond its range) never clears them, and they would
    wall the follower in behind the target. Inflation around them stays (a cost, not a wall).

    costs : (H, W) uint8; track : (N, 2) target positions in the costmap frame (m).
    """
    k = math.ceil(radius / resolution)
    d = np.arange(-k, k + 1)
    di, dj = np.meshgrid(d, d)
    keep = np.hypot(di, dj) * resolution <= radius
    di, dj = di[keep], dj[keep]
    track = np.asarray(track, float).reshape(-1, 2)
    cols = (np.floor((track[:, 0] - origin_x) / resolution).astype(int)[:, None] + di).ravel()
    rows = (np.floor((track[:, 1] - origin_y) / resolution).astype(int)[:, None] + dj).ravel()
    h, w = costs.shape
    ok = (cols >= 0) & (rows >= 0) & (cols < w) & (rows < h)
    rows, cols = rows[ok], cols[ok]
    out = costs.copy()
    lethal = out[rows, cols] == LETHAL_OBSTACLE
    out[rows[lethal], cols[lethal]] = FREE_SPACE
    return out
