"""Compiled scores of MPPI's critics, each over the whole batch.

Shapes: ``poses``, ``vels`` (B, T, 3) the sampled trajectories' poses (x, y, yaw; m, rad) and
state velocities (vx, vy, wz; m/s, rad/s); ``path`` (N, 3); ``costs`` the (H, W) uint8 costmap.
Each returns (B,) raw terms; the critic weighs them and raises them to its power.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

COLLISION = -1.0


@njit(cache=True, inline="always")
def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True, inline="always")
def pose_cost(
    costs, clear2, ox, oy, res, outline, use_footprint, inside2, outside2, escape2, x, y, c, s
):
    """`strict_pose_cost`, escaping: with ``escape2`` >= 0 (the robot's own pose already counts
    as a collision, ``escape2`` its clearance2), a pose that would collide only by the
    footprint or inscribed rule, no nearer to a lethal cell than the robot is now, costs 253
    (critical) instead, so the robot can back or turn out of the spot it is in rather than
    fail every sample (a padded footprint touching a post the robot itself has not hit)."""
    r = strict_pose_cost(
        costs, clear2, ox, oy, res, outline, use_footprint, inside2, outside2, x, y, c, s
    )
    if r != COLLISION or escape2 < 0.0:
        return r
    h, w = costs.shape
    fx = (x - ox) / res
    fy = (y - oy) / res
    if fx < 0.0 or fy < 0.0 or fx >= w or fy >= h:
        return r
    iy, ix = int(fy), int(fx)
    d2 = clear2[iy, ix]
    if costs[iy, ix] == 254 or (d2 >= 0 and d2 < escape2):  # d2 -1: no lethal cell at all
        return r
    return 253.0


@njit(cache=True, inline="always")
def centre_cost(costs, ox, oy, res, x, y):
    """`pose_cost` without the footprint and with no escape (``use_footprint`` false,
    ``escape2`` < 0): the centre cell's cost, `COLLISION` off the grid, INSCRIBED or LETHAL.
    The critics' loops take it for those poses: through `pose_cost` (as a call) each pose
    cost ~60 ns, here ~8 (2000 samples x 28 poses of a lizi's CostCritic, 3.5 ms -> 0.4 ms a
    cycle). `pose_cost` and `strict_pose_cost` are inlined into the loops too (the footprint
    case 10.4 -> 7.7 ms a cycle in `benchmarks/mppi_cycle.py`)."""
    h, w = costs.shape
    fx = (x - ox) / res
    fy = (y - oy) / res
    if fx < 0.0 or fy < 0.0 or fx >= w or fy >= h:
        return COLLISION
    v = costs[int(fy), int(fx)]
    return COLLISION if v == 253 or v == 254 else float(v)  # NO_INFORMATION passes


@njit(cache=True, inline="always")
def strict_pose_cost(
    costs, clear2, ox, oy, res, outline, use_footprint, inside2, outside2, x, y, c, s
):
    """The cost of one pose (heading cos ``c``, sin ``s``): its centre cell's, or `COLLISION`.

    A lethal centre cell or one off the grid is a collision. Without ``use_footprint`` so is an
    inscribed (253) one. With it, ``clear2`` (H, W) gives each cell's squared distance (cells)
    to the nearest lethal cell (-1: none): beyond ``outside2`` no footprint can touch one, below
    ``inside2`` one lies inside the footprint, in between the footprint's outline is laid on
    the grid and a lethal cell (or the grid's edge) under it is a collision; a pose the
    footprint passes costs at most 252 (below INSCRIBED, so not critical_cost by itself). The
    graded cost stays the centre's: the inflation layer's costs are distances from the centre
    (an outline cell at 253 only says an obstacle is within the inscribed radius of the
    robot's edge, and in clutter nearly every pose's outline has one). NO_INFORMATION (255) is
    passable (Nav2 with unknown space tracked)."""
    h, w = costs.shape
    fx = (x - ox) / res
    fy = (y - oy) / res
    if fx < 0.0 or fy < 0.0 or fx >= w or fy >= h:
        return COLLISION
    iy, ix = int(fy), int(fx)
    v = costs[iy, ix]
    if v == 254:
        return COLLISION
    if not use_footprint:
        return COLLISION if v == 253 else float(v)
    d2 = clear2[iy, ix]
    if d2 < 0 or d2 > outside2:
        return float(min(v, 252))
    if d2 < inside2:
        return COLLISION
    for k in range(outline.shape[0]):
        fx = (x + c * outline[k, 0] - s * outline[k, 1] - ox) / res
        fy = (y + s * outline[k, 0] + c * outline[k, 1] - oy) / res
        if fx < 0.0 or fy < 0.0 or fx >= w or fy >= h or costs[int(fy), int(fx)] == 254:
            return COLLISION
    # the footprint found no contact: an INSCRIBED centre (an obstacle within the inscribed
    # radius of the centre cell, a cell's rounding from the outline) is not "near collision"
    # by itself; it scores as the highest graded cost, so a gap the footprint fits through
    # costs what its tightness costs rather than critical_cost per pose
    return float(min(v, 252))


@njit(cache=True, inline="always")
def _sample_cost(
    centre_only, costs, clear2, ox, oy, res, outline, use_footprint, inside2, outside2, escape2,
    poses, headings, b, t,
):  # fmt: skip
    """The cost of sample ``b``'s pose ``t`` for the critics' loops: `centre_cost` when
    ``centre_only`` (no footprint, no escape), else `pose_cost`."""
    if centre_only:
        return centre_cost(costs, ox, oy, res, poses[b, t, 0], poses[b, t, 1])
    return pose_cost(
        costs, clear2, ox, oy, res, outline, use_footprint, inside2, outside2, escape2,
        poses[b, t, 0], poses[b, t, 1], headings[b, t, 0], headings[b, t, 1],
    )  # fmt: skip


@njit(cache=True)
def cost_terms(
    poses,
    headings,
    costs,
    clear2,
    ox,
    oy,
    res,
    outline,
    use_footprint,
    inside2,
    outside2,
    escape2,
    step,
    near_collision,
    critical,
    near_goal,
):
    """CostCritic: per trajectory, the sum over every ``step``-th pose of its cost (or
    ``critical`` from ``near_collision`` up; cell costs skipped when ``near_goal``), over the
    poses checked; and whether it collides. Returns ((B,) terms, (B,) bool collided)."""
    nb, nt = poses.shape[0], poses.shape[1]
    out = np.zeros(nb)
    hit = np.zeros(nb, dtype=np.bool_)
    n = (nt + step - 1) // step
    centre_only = not use_footprint and escape2 < 0.0
    for b in range(nb):
        acc = 0.0
        for t in range(0, nt, step):
            c = _sample_cost(
                centre_only, costs, clear2, ox, oy, res, outline, use_footprint, inside2,
                outside2, escape2, poses, headings, b, t,
            )  # fmt: skip
            if c == COLLISION:
                hit[b] = True
                break
            if c >= near_collision:
                acc += critical
            elif not near_goal:
                acc += c
        out[b] = acc / n
    return out, hit


@njit(cache=True)
def obstacle_terms(
    poses,
    headings,
    costs,
    clear2,
    ox,
    oy,
    res,
    outline,
    use_footprint,
    inside2,
    outside2,
    escape2,
    inscribed,
    scaling,
    margin,
    inflation_radius,
    near_goal,
):
    """ObstaclesCritic: per trajectory the critical term (sum of ``margin - distance`` where
    the distance to the nearest obstacle, recovered from the cost, is below ``margin``), the
    repulsive term (mean of ``inflation_radius - distance`` elsewhere in inflated space; none
    when ``near_goal``) and whether it collides. Returns three (B,) arrays."""
    nb, nt = poses.shape[0], poses.shape[1]
    critical = np.zeros(nb)
    repulsive = np.zeros(nb)
    hit = np.zeros(nb, dtype=np.bool_)
    log253 = math.log(253.0)
    centre_only = not use_footprint and escape2 < 0.0
    for b in range(nb):
        for t in range(nt):
            c = _sample_cost(
                centre_only, costs, clear2, ox, oy, res, outline, use_footprint, inside2,
                outside2, escape2, poses, headings, b, t,
            )  # fmt: skip
            if c == COLLISION:
                hit[b] = True
                break
            if c <= 0.0:
                continue
            dist = (scaling * inscribed - math.log(min(c, 253.0)) + log253) / scaling
            if dist < margin:
                critical[b] += margin - dist
            elif not near_goal:
                repulsive[b] += max(inflation_radius - dist, 0.0)
        repulsive[b] /= nt
    return critical, repulsive, hit


@njit(cache=True)
def constraint_terms(vels, vx_min, vx_max, vy_max, model, min_turning_r, dt):
    """ConstraintCritic: per trajectory, time-integrated velocity beyond the limits (and, for
    Ackermann, turning radius below ``min_turning_r``)."""
    nb, nt = vels.shape[0], vels.shape[1]
    out = np.zeros(nb)
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            vx, vy, wz = vels[b, t, 0], vels[b, t, 1], vels[b, t, 2]
            acc += max(vx - vx_max, 0.0) + max(vx_min - vx, 0.0)
            if model == 1:
                acc += max(abs(vy) - vy_max, 0.0)
            if model == 2 and abs(wz) > 1e-9:
                acc += max(min_turning_r - abs(vx / wz), 0.0)
        out[b] = acc * dt
    return out


@njit(cache=True)
def goal_terms(poses, gx, gy):
    """GoalCritic: the mean distance (m) of each trajectory's poses to the goal."""
    nb, nt = poses.shape[0], poses.shape[1]
    out = np.zeros(nb)
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            acc += math.hypot(poses[b, t, 0] - gx, poses[b, t, 1] - gy)
        out[b] = acc / nt
    return out


@njit(cache=True)
def goal_angle_terms(poses, gyaw):
    """GoalAngleCritic: the mean |yaw error| (rad) of each trajectory to the goal yaw."""
    nb, nt = poses.shape[0], poses.shape[1]
    out = np.zeros(nb)
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            acc += abs(_wrap(poses[b, t, 2] - gyaw))
        out[b] = acc / nt
    return out


@njit(cache=True)
def path_align_terms(poses, path, valid, step, use_orientations):
    """PathAlignCritic: the mean distance (m) of every ``step``-th pose to the nearest valid
    path point, searched forwards from the previous pose's (plus the yaw error to that
    point's yaw with ``use_orientations``)."""
    nb, nt, n = poses.shape[0], poses.shape[1], path.shape[0]
    out = np.zeros(nb)
    for b in range(nb):
        j = 0
        acc = 0.0
        count = 0
        for t in range(step - 1, nt, step):
            x, y = poses[b, t, 0], poses[b, t, 1]
            d = (path[j, 0] - x) ** 2 + (path[j, 1] - y) ** 2
            while j + 1 < n:
                dn = (path[j + 1, 0] - x) ** 2 + (path[j + 1, 1] - y) ** 2
                if dn > d:
                    break
                j += 1
                d = dn
            if valid[j]:
                acc += math.sqrt(d)
                if use_orientations:
                    acc += abs(_wrap(poses[b, t, 2] - path[j, 2]))
                count += 1
        out[b] = acc / count if count > 0 else 0.0
    return out


@njit(cache=True)
def path_follow_terms(poses, tx, ty):
    """PathFollowCritic: the distance (m) of each trajectory's last pose to the target."""
    nb, nt = poses.shape[0], poses.shape[1]
    out = np.zeros(nb)
    for b in range(nb):
        out[b] = math.hypot(poses[b, nt - 1, 0] - tx, poses[b, nt - 1, 1] - ty)
    return out


@njit(cache=True)
def path_angle_terms(poses, tx, ty, forward_preference):
    """PathAngleCritic: the mean |angle| (rad) between each pose's heading and the direction
    to the target point (either heading, without ``forward_preference``)."""
    nb, nt = poses.shape[0], poses.shape[1]
    out = np.zeros(nb)
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            a = abs(_wrap(math.atan2(ty - poses[b, t, 1], tx - poses[b, t, 0]) - poses[b, t, 2]))
            if not forward_preference:
                a = min(a, math.pi - a)
            acc += a
        out[b] = acc / nt
    return out


@njit(cache=True)
def reverse_terms(vels, dt):
    """PreferForwardCritic: the distance (m) each trajectory drives backwards."""
    nb, nt = vels.shape[0], vels.shape[1]
    out = np.zeros(nb)
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            acc += max(-vels[b, t, 0], 0.0)
        out[b] = acc * dt
    return out


@njit(cache=True)
def twirl_terms(vels):
    """TwirlingCritic: the mean |wz| (rad/s) of each trajectory."""
    nb, nt = vels.shape[0], vels.shape[1]
    out = np.zeros(nb)
    for b in range(nb):
        acc = 0.0
        for t in range(nt):
            acc += abs(vels[b, t, 2])
        out[b] = acc / nt
    return out
