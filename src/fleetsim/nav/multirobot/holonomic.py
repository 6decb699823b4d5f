"""Kernels between a path, a holonomic ORCA velocity and a differential-drive base.

* `preferred_velocity`: where the robot wants to go, a carrot on the global plan;
* `obstacle_points`: static obstacles of the local costmap as the nearest lethal cell per
  bearing sector, the points ORCA keeps clear of with full responsibility;
* `tracking_command`: a differential-drive (v, w) that tracks a holonomic velocity within
  ``time_to_holo`` (collvoid's NH-ORCA idea, Alonso-Mora et al. 2010: turn at
  ``heading error / time_to_holo`` and drive at the speed whose arc best matches the
  holonomic displacement); the tracking error this leaves is bounded by ``max_error_holo``,
  which the planner adds to the robot's radius;
* `speed_along_heading`: the forward speed nearest the tracking one that the ORCA half-planes
  admit for motion along the robot's heading (a 1-D linear program). While the base turns
  towards the holonomic velocity it moves along its heading, not along that velocity; without
  this check the arc can lead into a wall or a neighbour that the holonomic velocity avoided;
* `speed_nearest_still`: the same along the heading, forwards or backwards, nearest standing
  still: a robot waiting for another to go by moves only as ORCA requires, without turning.
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.nav.costmap.costmap_2d import FREE_SPACE, LETHAL_OBSTACLE
from fleetsim.nav.multirobot.yielding import clear_distance

#: m/s: a robot faster than this goes round a disc on the tangent nearest its direction
MOVING_SPEED = 0.1


def plan_carrot(
    plan_xy: np.ndarray, xy: np.ndarray, lookahead: float
) -> tuple[np.ndarray, int, float]:
    """The plan point ``lookahead`` m along the plan past the point nearest ``xy``.

    plan_xy : (N, 2) plan points, m. Returns (carrot (2,), index of the nearest point,
    distance to that point plus the plan's length from it to its end, m).
    """
    d = np.hypot(plan_xy[:, 0] - xy[0], plan_xy[:, 1] - xy[1])
    i = int(np.argmin(d))
    seg = np.hypot(*np.diff(plan_xy[i:], axis=0).T) if plan_xy.shape[0] - i > 1 else np.zeros(0)
    along = np.concatenate([[0.0], np.cumsum(seg)])
    j = i + int(np.searchsorted(along, lookahead, side="left"))
    j = min(j, plan_xy.shape[0] - 1)
    return plan_xy[j], i, float(d[i] + along[-1])


def preferred_velocity(
    carrot: np.ndarray,
    xy: np.ndarray,
    remaining: float,
    max_speed: float,
    min_speed: float,
    deceleration: float,
) -> np.ndarray:
    """(2,) m/s towards ``carrot``: ``max_speed``, or the speed from which ``deceleration``
    (m/s^2) stops the robot within the ``remaining`` path (m), but at least ``min_speed``."""
    to = np.asarray(carrot, dtype=np.float64) - xy
    n = float(np.hypot(*to))
    if n < 1e-9:
        return np.zeros(2)
    speed = min(max_speed, max(min_speed, math.sqrt(2.0 * deceleration * remaining)))
    return to / n * speed


def rays_blocked(
    directions: np.ndarray, rel_pos: np.ndarray, radii: np.ndarray, reach: float
) -> np.ndarray:
    """(M,) whether each unit ray in ``directions`` (M, 2) enters one of the discs (rel_pos
    (N, 2) m, radii (N,) m) within ``reach`` m of the robot (at the origin)."""
    along = directions @ rel_pos.T  # (M, N)
    side = directions[:, :1] * rel_pos[None, :, 1] - directions[:, 1:] * rel_pos[None, :, 0]
    inside = radii[None, :] ** 2 - side**2
    entry = along - np.sqrt(np.maximum(inside, 0.0))
    return np.any((along > 1e-9) & (inside > 0.0) & (entry < reach), axis=1)


def detour_velocity(
    pref: np.ndarray,
    rel_pos: np.ndarray,
    radii: np.ndarray,
    reach: float,
    closed: np.ndarray | None = None,
    keep: np.ndarray | None = None,
    moving: np.ndarray | None = None,
) -> tuple[np.ndarray, int]:
    """``pref`` turned to the nearest heading whose ray is clear of every disc within ``reach``.

    Robots standing still in the way make ORCA's velocity nearest ``pref`` (which points at
    them) a standstill: a permitted half-plane square to ``pref``, or two parked robots whose
    gap is too narrow. Going round them is the preferred velocity's job (a velocity obstacle of
    the still robots over ``reach``): the candidate headings are the tangents to each disc, and
    the one nearest ``pref`` whose ray enters no disc wins (the right one on a tie, the side
    oncoming traffic keeps to).

    pref : (2,) m/s; rel_pos : (N, 2) disc centres relative to the robot, m; radii : (N,) m
    (combined: own + theirs + margin); closed : (N, 2) bool or None, the way past each disc on
    its right, on its left (as seen from the robot) shut by a wall (`gaps_closed`): that
    tangent is no candidate; keep : (N,) int or None, the side the robot already goes round
    each disc on (0: its right tangent, 1: its left, -1: none): the other side's tangent is
    no candidate while one on the kept side is clear (else the robot, drawn by a carrot on
    the other side, turns back and forth in front of the disc); moving : (2,) m/s or None,
    the robot's velocity: the tangents are tried nearest its direction first (a differential
    drive already under way turns least; the tangents nearest ``pref`` when it stands).
    Returns (the velocity (2,) m/s, same speed; the index of the disc
    whose tangent it follows, or -1 when ``pref`` is clear or no heading is).
    """
    speed = float(np.hypot(*pref))
    if speed < 1e-9 or rel_pos.shape[0] == 0:
        return pref, -1
    u = pref / speed
    if not rays_blocked(u[None, :], rel_pos, radii, reach)[0]:
        return pref, -1
    d = np.hypot(rel_pos[:, 0], rel_pos[:, 1])
    bearing = np.arctan2(rel_pos[:, 1], rel_pos[:, 0])
    half = np.arcsin(np.clip(radii / np.maximum(d, 1e-9), 0.0, 1.0)) + 1e-3
    heading = np.concatenate([bearing - half, bearing + half])  # right tangents, then left
    ref = u
    if moving is not None and float(np.hypot(*moving)) > MOVING_SPEED:
        ref = np.asarray(moving, dtype=np.float64)
    turn = np.remainder(heading - math.atan2(ref[1], ref[0]) + math.pi, 2 * math.pi) - math.pi
    order = np.argsort(np.abs(turn) + 1e-6 * (turn > 0), kind="stable")
    dirs = np.stack([np.cos(heading[order]), np.sin(heading[order])], axis=1)
    free = ~rays_blocked(dirs, rel_pos, radii, reach)
    if closed is not None:
        shut = np.concatenate([closed[:, 0], closed[:, 1]])  # right tangents, then left
        free &= ~shut[order]
    if keep is not None:
        n = rel_pos.shape[0]
        side = (order >= n).astype(int)
        committed = np.asarray(keep)[order % n]
        kept = free & ((committed < 0) | (side == committed))
        if kept.any():
            free = kept
    if not free.any():
        return pref, -1
    first = int(np.argmax(free))
    return speed * dirs[first], int(order[first] % rel_pos.shape[0])


def gaps_closed(
    grid: tuple[np.ndarray, tuple[float, float], float],
    xy: np.ndarray,
    rel_pos: np.ndarray,
    radii: np.ndarray,
    wall_clearance: float,
) -> np.ndarray:
    """(N, 2) bool: whether the way past each disc on its right, on its left (seen from the
    robot at ``xy``) is too narrow between the disc and a wall: the lethal cells across our
    bearing to the disc are nearer its centre than ``radii`` (combined, m) + ``wall_clearance``
    (m, the robot's body to a wall). A robot parked off the middle of a corridor leaves room on
    one side only; going round it on the other wedges the robot between it and the wall.

    grid : (costs (H, W) uint8, origin (2,) m, resolution m); rel_pos : (N, 2) m.
    """
    out = np.zeros((rel_pos.shape[0], 2), dtype=bool)
    for k, (rel, r) in enumerate(zip(rel_pos, radii)):
        d = float(np.hypot(*rel))
        if d < 1e-9:
            continue
        u = rel / d
        need = float(r) + wall_clearance
        for side, normal in enumerate((np.array([u[1], -u[0]]), np.array([-u[1], u[0]]))):
            out[k, side] = clear_distance(*grid, xy + rel, normal, need) < need
    return out


def rotated(v: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def obstacle_points(
    costs: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    xy: np.ndarray,
    reach: float,
    sectors: int = 24,
) -> np.ndarray:
    """The nearest lethal cell centre in each of ``sectors`` bearings within ``reach`` m.

    costs : (H, W) uint8 costmap; origin : its lower-left corner, m; xy : (2,) robot, m.
    Returns (M, 2) points in the costmap frame, M <= sectors, nearest first.
    """
    ox, oy = origin
    c0 = max(int((xy[0] - reach - ox) / resolution), 0)
    c1 = min(int((xy[0] + reach - ox) / resolution) + 1, costs.shape[1])
    r0 = max(int((xy[1] - reach - oy) / resolution), 0)
    r1 = min(int((xy[1] + reach - oy) / resolution) + 1, costs.shape[0])
    if c1 <= c0 or r1 <= r0:
        return np.zeros((0, 2))
    rows, cols = np.nonzero(costs[r0:r1, c0:c1] >= LETHAL_OBSTACLE)
    if rows.size == 0:
        return np.zeros((0, 2))
    px = ox + (cols + c0 + 0.5) * resolution
    py = oy + (rows + r0 + 0.5) * resolution
    dx, dy = px - xy[0], py - xy[1]
    d = np.hypot(dx, dy)
    keep = d <= reach
    dx, dy, d, px, py = dx[keep], dy[keep], d[keep], px[keep], py[keep]
    if d.size == 0:
        return np.zeros((0, 2))
    sector = ((np.arctan2(dy, dx) + math.pi) / (2 * math.pi) * sectors).astype(int) % sectors
    order = np.lexsort((d, sector))
    first = np.ones(order.size, dtype=bool)
    first[1:] = sector[order][1:] != sector[order][:-1]
    pick = order[first]
    pick = pick[np.argsort(d[pick], kind="stable")]
    return np.stack([px[pick], py[pick]], axis=1)


def without_robots(
    costs: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    centres: np.ndarray,
    radii: np.ndarray,
) -> np.ndarray:
    """``costs`` with the LETHAL cells inside the discs ``centres`` (K, 2) m, ``radii`` (K,) m
    cleared to free space: the other robots as this robot's laser sees them.

    A robot whose laser sweeps another robot's body has that body in its local costmap as a
    lethal obstacle, and the planner's wall half-planes then count it a second time, with all
    the responsibility and as if it stood still: two pioneer3ats (whose lasers see each other,
    where the lizis' sweep above each other) stopped face to face on the circle of 8 for
    40-55 s. The robot half-planes from /position_share already cover them. NO_INFORMATION
    cells stay. Returns ``costs`` itself when nothing is cleared, else a copy.
    """
    out = costs
    h, w = costs.shape
    ox, oy = origin
    for (cx, cy), r in zip(np.asarray(centres, dtype=np.float64), np.asarray(radii, float)):
        c0 = max(math.floor((cx - r - ox) / resolution), 0)
        c1 = min(math.floor((cx + r - ox) / resolution) + 1, w)
        r0 = max(math.floor((cy - r - oy) / resolution), 0)
        r1 = min(math.floor((cy + r - oy) / resolution) + 1, h)
        if c1 <= c0 or r1 <= r0:
            continue
        block = out[r0:r1, c0:c1]
        px = ox + (np.arange(c0, c1) + 0.5) * resolution - cx
        py = oy + (np.arange(r0, r1) + 0.5) * resolution - cy
        hit = (block == LETHAL_OBSTACLE) & (py[:, None] ** 2 + px[None, :] ** 2 <= r * r)
        if hit.any():
            if out is costs:
                out = costs.copy()
            out[r0:r1, c0:c1][hit] = FREE_SPACE
    return out


def tracking_command(
    v_holo: np.ndarray,
    yaw: float,
    time_to_holo: float,
    max_vel_x: float,
    max_vel_theta: float,
) -> tuple[float, float]:
    """(v m/s, w rad/s) of a differential drive tracking the holonomic velocity ``v_holo``.

    Heading error θ: turn at θ / time_to_holo (clamped to max_vel_theta); drive at
    ``|v_holo| θ sin θ / (2 (1 - cos θ))``, the speed whose arc over the turn ends where the
    holonomic motion would (NH-ORCA), i.e. |v_holo| when θ = 0. Where the turn would need more
    than max_vel_theta (|θ| > max_vel_theta * time_to_holo) that speed fades linearly to a turn
    in place at twice that error (and always from θ = π/2 on).
    """
    speed = float(np.hypot(*v_holo))
    if speed < 1e-4:
        return 0.0, 0.0
    theta = math.remainder(math.atan2(v_holo[1], v_holo[0]) - yaw, 2 * math.pi)
    w = max(-max_vel_theta, min(max_vel_theta, theta / time_to_holo))
    if abs(theta) >= math.pi / 2:
        return 0.0, w
    if abs(theta) < 1e-6:
        v = speed
    else:
        v = speed * theta * math.sin(theta) / (2.0 * (1.0 - math.cos(theta)))
    # the base turns at most max_vel_theta: a heading error it cannot close within
    # time_to_holo slows it down, to a turn in place at twice that error (else, near a goal,
    # it circles the goal on a turning circle wider than the distance left)
    reach = max_vel_theta * time_to_holo
    if abs(theta) > reach:
        v *= max(0.0, 2.0 - abs(theta) / reach)
    return min(max(v, 0.0), max_vel_x), w


#: m/s a speed along the heading may leave the static half-planes by when none is inside them
#: (`speed_along`)
HEADING_SLACK = 0.01


def speed_interval(
    points: np.ndarray,
    directions: np.ndarray,
    heading: np.ndarray,
    max_speed: float,
    slack: float = 0.0,
) -> tuple[float, float]:
    """[lo, hi] of speeds v in [0, max_speed] with v * heading inside every half-plane, or
    outside none by more than ``slack`` m/s.

    points, directions : (L, 2) half-planes (permitted side: left of the direction);
    heading : (2,) unit vector. lo > hi when no such speed exists.
    """
    a = directions[:, 0] * heading[1] - directions[:, 1] * heading[0]  # det(d, u)
    # det(d, p), less the slack (d is a unit vector: det(d, p - v u) is m/s outside)
    b = directions[:, 0] * points[:, 1] - directions[:, 1] * points[:, 0] - slack
    # permitted: det(d, p - v u) = b - v a <= 0
    lo, hi = 0.0, max_speed
    pos, neg, flat = a > 1e-12, a < -1e-12, np.abs(a) <= 1e-12
    if pos.any():
        lo = max(lo, float(np.max(b[pos] / a[pos])))
    if neg.any():
        hi = min(hi, float(np.min(b[neg] / a[neg])))
    if flat.any() and float(np.max(b[flat])) > 1e-12:
        return 1.0, 0.0
    return lo, hi


def least_violation_speed(
    points: np.ndarray,
    directions: np.ndarray,
    heading: np.ndarray,
    lo: float,
    hi: float,
    wanted: float,
) -> float:
    """The speed v in [lo, hi] whose motion v * ``heading`` (2,) violates the half-planes
    (``points``, ``directions`` (L, 2)) least: the smallest largest distance beyond a line
    (RVO2's linearProgram3 along one line of velocities); of equal ones, the nearest
    ``wanted``. The largest violation is convex and piecewise linear in v, so its minimum is
    at an end of the interval or where two lines' violations cross."""
    if points.shape[0] == 0:
        return min(max(wanted, lo), hi)
    a = directions[:, 0] * heading[1] - directions[:, 1] * heading[0]
    b = directions[:, 0] * points[:, 1] - directions[:, 1] * points[:, 0]
    da, db = a[:, None] - a[None, :], b[:, None] - b[None, :]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # inf: filtered below
        cross = np.where(np.abs(da) > 1e-12, db / da, np.nan).ravel()
    v = np.concatenate([[lo, hi, min(max(wanted, lo), hi)], cross])
    v = v[np.isfinite(v) & (v >= lo) & (v <= hi)]
    worst = np.max(b[None, :] - v[:, None] * a[None, :], axis=1)
    best = v[worst <= worst.min() + 1e-9]
    return float(best[np.argmin(np.abs(best - wanted))])


def speed_along_heading(
    points: np.ndarray,
    directions: np.ndarray,
    num_obstacle_lines: int,
    yaw: float,
    wanted: float,
    max_speed: float,
    hard: tuple[np.ndarray, np.ndarray] | None = None,
) -> float:
    """The forward speed (m/s) nearest ``wanted`` whose motion along ``yaw`` all half-planes
    admit; if none does, the one the static-obstacle half-planes (the first
    ``num_obstacle_lines``; left by at most `HEADING_SLACK` when none is inside them) and the
    ``hard`` ones (points, directions: robots' bodies,
    `fleetsim.nav.multirobot.orca.contact_halfplanes`) admit; if those admit none, of the speeds
    the static-obstacle ones admit, the one that violates the hard ones least
    (`least_violation_speed`); if none does either, 0. Dropping the robots' half-planes
    altogether, a pioneer3at inside another's body disc, heading into it, drove on at the speed
    it wanted and touched it (circle of 8, seed 7); keeping them all, lizis that ORCA sends
    along an edge stood until their heading was on it (circle of 16, seed 0: 2.4 s)."""
    u = np.array([math.cos(yaw), math.sin(yaw)])
    return speed_along(points, directions, num_obstacle_lines, u, wanted, max_speed, hard)


def speed_along(points, directions, num_obstacle_lines, u, wanted, max_speed, hard=None):
    """`speed_along_heading` along the unit vector ``u`` (2,) instead of a yaw."""
    lo, hi = speed_interval(points, directions, u, max_speed)
    if lo <= hi:
        return min(max(wanted, lo), hi)
    n = num_obstacle_lines
    lo, hi = speed_interval(points[:n], directions[:n], u, max_speed)
    if lo > hi:
        # a heading a hair off a velocity the static half-planes admit: an obstacle point
        # inside the disc asks for a little motion away from it, which the holonomic velocity
        # has and the heading a tenth of a degree off it has not, where a wall ahead caps the
        # speed; tracking asks no turn of such a heading, so without the slack it stood for
        # good (pioneers' corridor of 4, seed 17: 48 s, until move_base's recovery)
        lo, hi = speed_interval(points[:n], directions[:n], u, max_speed, HEADING_SLACK)
    if lo > hi:
        return 0.0
    if hard is None or hard[0].shape[0] == 0:
        return min(max(wanted, lo), hi)
    h_lo, h_hi = speed_interval(*hard, u, max_speed)
    if max(lo, h_lo) <= min(hi, h_hi):
        return min(max(wanted, max(lo, h_lo)), min(hi, h_hi))
    return least_violation_speed(*hard, u, lo, hi, wanted)


def speed_nearest_still(
    points: np.ndarray,
    directions: np.ndarray,
    yaw: float,
    max_forward: float,
    max_backward: float,
) -> float | None:
    """The speed along ``yaw`` (m/s, negative: backwards) nearest 0 that every half-plane
    admits, or None when no speed along that line does."""
    u = np.array([math.cos(yaw), math.sin(yaw)])
    options = []
    lo, hi = speed_interval(points, directions, u, max_forward)
    if lo <= hi:
        options.append(lo)
    lo, hi = speed_interval(points, directions, -u, max_backward)
    if lo <= hi:
        options.append(-lo)
    return min(options, key=abs) if options else None
