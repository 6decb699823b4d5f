"""Trajectory rollout and scoring for all velocity samples at once (base_local_planner).

`trajectory_costs` is TrajectoryPlanner::generateTrajectory for S samples in one compiled
call: each sample (vx, vy, vtheta) is simulated from the robot's pose and velocity with the
acceleration limits for ``sim_time`` in ``num_steps`` steps, each pose checked with the
footprint and scored from the path / goal distance maps.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE
from fleetsim.nav.costmap.footprint import footprint_cost_rotated

_SLACK = 1e-6  # cells: margin for rounding when bounding where an outline point can land


def reach_offsets(outline: np.ndarray, resolution: float) -> np.ndarray:
    """Cell offsets an outline point can land in, relative to the robot centre's cell.

    The centre lies anywhere in its cell and every outline point within ``R`` (the largest
    outline point norm) of it, so a point's cell ``(di, dj)`` away is possible only when the
    two cells' squares come within ``R``: ``max(|di| - 1, 0)^2 + max(|dj| - 1, 0)^2 <= (R /
    resolution)^2``, at any orientation.

    outline : (M, 2) m, robot frame. Returns (P, 2) int64 (di, dj) offsets.
    """
    r = float(np.hypot(outline[:, 0], outline[:, 1]).max()) / resolution + _SLACK
    k = math.ceil(r) + 1
    d = np.arange(-k, k + 1)
    di, dj = np.meshgrid(d, d)
    gx = np.maximum(np.abs(di) - 1, 0)
    gy = np.maximum(np.abs(dj) - 1, 0)
    keep = gx * gx + gy * gy <= r * r
    return np.stack((di[keep], dj[keep]), axis=1).astype(np.int64)


@njit(cache=True)
def footprint_cost_bounds(costs, offsets):
    """Per cell, the highest cost any footprint outline point can touch from there.

    costs : (H, W) uint8 costmap. offsets : (P, 2) int64 from `reach_offsets` (symmetric,
    row by row a run ``-a(dj)..a(dj)``).
    Returns (H, W) uint8: the maximum of ``costs`` over the cell + offsets, 255
    (NO_INFORMATION) when some offset leaves the grid. A pose whose cell's bound is below
    LETHAL_OBSTACLE has a legal footprint with cost at most that bound.

    Computed separably: running row maxima of growing half-width over a grid padded with
    255, then for each row offset the maximum of the row maxima of that row's half-width.
    """
    h, w = costs.shape
    k = 0
    for i in range(offsets.shape[0]):
        k = max(k, abs(offsets[i, 0]), abs(offsets[i, 1]))
    half = np.full(2 * k + 1, -1, dtype=np.int64)  # half-width of each row offset dj
    for i in range(offsets.shape[0]):
        j = offsets[i, 1] + k
        half[j] = max(half[j], abs(offsets[i, 0]))
    hp, wp = h + 2 * k, w + 2 * k
    pad = np.full((hp, wp), 255, dtype=np.uint8)
    pad[k : k + h, k : k + w] = costs
    rows = np.empty((k + 1, hp, w), dtype=np.uint8)  # rows[a]: max over x-a..x+a
    for y in range(hp):
        for x in range(w):
            rows[0, y, x] = pad[y, x + k]
    for a in range(1, k + 1):
        for y in range(hp):
            for x in range(w):
                v = rows[a - 1, y, x]
                lo = pad[y, x + k - a]
                hi = pad[y, x + k + a]
                if lo > v:
                    v = lo
                if hi > v:
                    v = hi
                rows[a, y, x] = v
    out = np.zeros((h, w), dtype=np.uint8)
    for j in range(2 * k + 1):
        a = half[j]
        if a < 0:
            continue
        for y in range(h):
            for x in range(w):
                v = rows[a, y + j, x]
                if v > out[y, x]:
                    out[y, x] = v
    return out


def footprint_cost_bounds_near(costs, offsets, cx: int, cy: int, radius: int):
    """`footprint_cost_bounds`, exact for the cells within ``radius`` cells (each axis) of cell
    ``(cx, cy)`` and 255 (NO_INFORMATION: "check the footprint") elsewhere.

    The rollouts of one control cycle stay within their top speed times ``sim_time`` of the
    robot, a fraction of the local map; a bound of 255 only sends a pose to the exact footprint
    check, so the costs are the same whatever ``radius`` is, and this costs the window's share.
    """
    return _bounds_near(costs, offsets, cx, cy, radius)


@njit(cache=True)
def _bounds_near(costs, offsets, cx, cy, radius):
    """`footprint_cost_bounds_near`, compiled whole (it runs every control cycle of every
    robot; its NumPy wrapper's few array calls cost as much as the block's kernel)."""
    h, w = costs.shape
    k = 0
    for i in range(offsets.shape[0]):
        k = max(k, abs(offsets[i, 0]), abs(offsets[i, 1]))
    r0, r1 = max(cy - radius - k, 0), min(cy + radius + k + 1, h)
    c0, c1 = max(cx - radius - k, 0), min(cx + radius + k + 1, w)
    out = np.full((h, w), 255, dtype=np.uint8)
    if r1 <= r0 or c1 <= c0:
        return out
    sub = footprint_cost_bounds(np.ascontiguousarray(costs[r0:r1, c0:c1]), offsets)
    # rows/columns of the block whose reach leaves it where the grid goes on are padded with
    # 255 by the kernel: too high, which only costs a footprint check; keep them as they are
    out[r0:r1, c0:c1] = sub
    return out


@njit(cache=True, inline="always")
def new_velocity(vg, vi, a_max, dt):
    """``vi`` moved toward ``vg`` by at most ``a_max * dt`` (base_local_planner's
    computeNewVelocity)."""
    if vg - vi >= 0:
        return min(vg, vi + a_max * dt)
    return max(vg, vi - a_max * dt)


@njit(cache=True)
def _line_clear(costs, x0, y0, x1, y1):
    """True when no cell on the line is LETHAL, INSCRIBED or NO_INFORMATION (lineCost >= 0)."""
    n = max(abs(x1 - x0), abs(y1 - y0))
    for k in range(n + 1):
        t = k / n if n > 0 else 0.0
        x = round(x0 + (x1 - x0) * t)
        y = round(y0 + (y1 - y0) * t)
        if costs[y, x] >= 253:
            return False
    return True


@njit(cache=True)
def _heading_diff(costs, ox, oy, res, plan_cells, cx, cy, x, y, heading):
    """TrajectoryPlanner::headingDiff: angle to the farthest plan cell in line of sight."""
    for i in range(plan_cells.shape[0] - 1, -1, -1):
        gx = plan_cells[i, 0]
        gy = plan_cells[i, 1]
        if _line_clear(costs, cx, cy, gx, gy):
            wx = ox + (gx + 0.5) * res
            wy = oy + (gy + 0.5) * res
            d = math.atan2(wy - y, wx - x) - heading
            d = (d + math.pi) % (2.0 * math.pi) - math.pi
            return abs(d)
    return 1.0e300


@njit(cache=True)
def alignment_cost(path_dist, origin, resolution, x, y, th, forward, path_d):
    """Path distance (cells) of the point ``forward`` m ahead of pose (x, y, th).

    dwa_local_planner's alignment cost (its MapGridCostFunction shifted by
    ``forward_point_distance``): a rollout that ends on the path but pointing away from it
    scores worse than one that ends pointing along it. Where the point is off the map or on an
    obstacle (no path distance), dwa_local_planner rejects the rollout; here it scores as the
    farthest the point can be from the path, ``path_d`` (the pose's own path distance) plus
    ``forward`` in cells, so a robot close to obstacles still has legal choices.
    """
    h, w = path_dist.shape
    fx = (x + forward * math.cos(th) - origin[0]) / resolution
    fy = (y + forward * math.sin(th) - origin[1]) / resolution
    worst = path_d + forward / resolution
    if fx < 0.0 or fy < 0.0 or fx >= w or fy >= h:
        return worst
    d = path_dist[int(fy), int(fx)]
    if d >= float(h * w):
        return worst
    return min(d, worst)


@njit(cache=True)
def num_steps_of(samples, sim_time, sim_granularity, angular_sim_granularity, heading_scoring):
    """Simulation steps of each sample (at least 1). samples : (S, 3). Returns (S,) int64."""
    out = np.empty(samples.shape[0], dtype=np.int64)
    for s in range(samples.shape[0]):
        if heading_scoring:
            n = int(sim_time / sim_granularity + 0.5)
        else:
            vmag = math.hypot(samples[s, 0], samples[s, 1])
            n = int(
                max(vmag * sim_time / sim_granularity, abs(samples[s, 2]) / angular_sim_granularity)
                + 0.5
            )
        out[s] = max(n, 1)
    return out


@njit(cache=True)
def trajectory_costs(
    samples,
    pose,
    velocity,
    acc,
    sim_time,
    num_steps,
    costs,
    origin,
    resolution,
    outline,
    path_dist,
    goal_dist,
    scales,
    heading,
    plan_cells,
    simple_attractor,
    final_goal,
    poses_out,
    bounds,
    alignment,
):
    """Score every sample's rollout as TrajectoryPlanner::generateTrajectory.

    The footprint is laid on the grid only where it can matter: when the cell's bound (see
    `footprint_cost_bounds`) is legal and no higher than the trajectory's highest cost so far,
    the footprint cannot change the result, so it is skipped (the result is the same). The
    first pose is every sample's, so its footprint is laid once; a heading's cosine and sine
    are computed once for its footprint and its step, and kept while the heading does not
    change; a step at rest (vx = vy = 0) needs neither (the same results, bit for bit).

    Parameters
    ----------
    samples : (S, 3) commanded (vx, vy, vtheta), m/s and rad/s, robot frame.
    pose : (3,) robot x, y (m), yaw (rad) in the costmap frame.
    velocity : (3,) current (vx, vy, vtheta).
    acc : (3,) acceleration limits (x, y, theta), m/s^2 and rad/s^2.
    sim_time : s. num_steps : (S,) steps per sample (see `num_steps_of`).
    costs : (H, W) uint8 local costmap; origin : (2,) m; resolution : m.
    outline : (M, 2) footprint outline points, robot frame, m.
    path_dist, goal_dist : (H, W) float64 MapGrid distances (cells).
    scales : (3,) pdist_scale, gdist_scale, occdist_scale.
    heading : (2,) heading_scoring (0/1), heading_scoring_timestep (s).
    plan_cells : (K, 2) int64 plan cells in the map, for heading scoring.
    simple_attractor : score by squared distance to ``final_goal`` (2,) instead of the maps.
    poses_out : (S, T, 3) float64 written with each rollout's poses (T >= max num_steps); the
        steps of a rollout cut short by a negative cost are NaN.
    bounds : (H, W) uint8 from `footprint_cost_bounds` for ``costs`` and ``outline``.
    alignment : (2,) weight (per cell of path distance; 0 = off) and forward distance (m) of
        the alignment cost: the path distance of the point that far ahead of the rollout's
        last pose (dwa_local_planner's alignment cost, `alignment_cost`).

    Returns
    -------
    (S,) float64 costs: >= 0 legal; -1 footprint collision or off the map; -2 a pose with no
    path to the goal (distance at least the map size).
    """
    h, w = costs.shape
    impossible = float(h * w)
    out = np.empty(samples.shape[0])
    fp0 = np.nan  # the footprint cost of the first pose, the same for every sample
    for s in range(samples.shape[0]):
        n = num_steps[s]
        dt = sim_time / n
        x, y, th = pose[0], pose[1], pose[2]
        vx, vy, vth = velocity[0], velocity[1], velocity[2]
        path_d = 0.0
        goal_d = 0.0
        occ = 0.0
        hdiff = 0.0
        t = 0.0
        cost = 0.0
        th_cs = np.nan  # the heading whose cosine and sine c, sn hold
        c = 1.0
        sn = 0.0
        for i in range(n):
            # a rollout found illegal is still followed to its end, unscored: the escape, taken
            # blind, publishes it as the local plan, and the escape guard checks it
            if cost >= 0.0:
                fx = (x - origin[0]) / resolution
                fy = (y - origin[1]) / resolution
                if fx < 0.0 or fy < 0.0 or fx >= w or fy >= h:
                    cost = -1.0
                else:
                    cx = int(fx)
                    cy = int(fy)
                    occ = max(occ, float(costs[cy, cx]))
                    bound = bounds[cy, cx]
                    if bound >= LETHAL_OBSTACLE or bound > occ:
                        if i == 0 and fp0 == fp0:
                            fp = fp0
                        else:
                            if th != th_cs:
                                c = math.cos(th)
                                sn = math.sin(th)
                                th_cs = th
                            fp = footprint_cost_rotated(
                                costs, origin[0], origin[1], resolution, outline, x, y, c, sn
                            )
                            if i == 0:
                                fp0 = fp
                        if fp < 0.0:
                            cost = -1.0
                        else:
                            occ = max(occ, fp)
                    if cost >= 0.0 and simple_attractor:
                        goal_d = (x - final_goal[0]) ** 2 + (y - final_goal[1]) ** 2
                    elif cost >= 0.0:
                        update = True
                        if heading[0] > 0.5:
                            if t >= heading[1] and t < heading[1] + dt:
                                hdiff = _heading_diff(
                                    costs, origin[0], origin[1], resolution, plan_cells, cx, cy,
                                    x, y, th,
                                )  # fmt: skip
                            else:
                                update = False
                        if update:
                            path_d = path_dist[cy, cx]
                            goal_d = goal_dist[cy, cx]
                            if impossible <= goal_d or impossible <= path_d:
                                cost = -2.0
            poses_out[s, i, 0] = x
            poses_out[s, i, 1] = y
            poses_out[s, i, 2] = th
            vx = new_velocity(samples[s, 0], vx, acc[0], dt)
            vy = new_velocity(samples[s, 1], vy, acc[1], dt)
            vth = new_velocity(samples[s, 2], vth, acc[2], dt)
            if vy != 0.0:
                x = x + (vx * math.cos(th) + vy * math.cos(math.pi / 2.0 + th)) * dt
                y = y + (vx * math.sin(th) + vy * math.sin(math.pi / 2.0 + th)) * dt
            elif vx != 0.0 or x == 0.0 or y == 0.0:
                # the same sums (a zero term adds nothing) without two of the four trig calls;
                # at rest x and y stay (adding a signed zero changes only a zero's sign)
                if th != th_cs:
                    c = math.cos(th)
                    sn = math.sin(th)
                    th_cs = th
                x = x + vx * c * dt
                y = y + vx * sn * dt
            th = th + vth * dt
            t += dt
        if cost < 0.0:
            out[s] = cost
            continue
        total = scales[0] * path_d + scales[1] * goal_d + scales[2] * occ
        if alignment[0] > 0.0 and n > 0:
            k = n - 1
            total += alignment[0] * alignment_cost(
                path_dist,
                origin,
                resolution,
                poses_out[s, k, 0],
                poses_out[s, k, 1],
                poses_out[s, k, 2],
                alignment[1],
                path_d,
            )
        if heading[0] > 0.5:
            total += 0.3 * hdiff
        out[s] = total
    return out
