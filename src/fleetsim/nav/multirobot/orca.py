"""Optimal Reciprocal Collision Avoidance (ORCA) kernels, after RVO2.

van den Berg, Guy, Lin, Manocha, "Reciprocal n-body Collision Avoidance" (ISRR 2009) and the
RVO2 library's Agent.cpp: every neighbour (a disc moving at a known velocity) gives a half-plane
of permitted velocities (`orca_halfplanes`); the new velocity is the one closest to the
preferred velocity inside every half-plane and the max-speed disc (`orca_velocity`: RVO2's 2-D
incremental linear program, and when that is infeasible, its 3-D program that minimises the
largest violation of the agent half-planes while keeping the static-obstacle ones).

Why our own: ``pyrvo`` (the maintained binding of RVO2) requires ``ir-sim``, another simulator,
and ``rvo2`` (Python-RVO2) is not on PyPI and is untested past Python 3.6. The half-planes are
built for all neighbours at once with NumPy; the linear programs are sequential by nature
(each line cuts the previous solution) and run under numba.

A half-plane is a line (point p, unit direction d); the permitted side is the left of d:
``det(d, v - p) <= 0``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

RVO_EPSILON = 1e-5
#: m/s a (nearly) parallel line may lie on the wrong side of another by rounding alone
PARALLEL_SLACK = 1e-9


def orca_halfplanes(
    rel_pos: np.ndarray,
    rel_vel: np.ndarray,
    radii: np.ndarray,
    velocity: np.ndarray,
    time_horizon: float,
    time_step: float,
    responsibility: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """ORCA half-planes of one agent against N neighbours.

    Parameters
    ----------
    rel_pos : (N, 2) neighbour position minus own position, m.
    rel_vel : (N, 2) own velocity minus neighbour velocity, m/s.
    radii : (N,) combined radius (own + neighbour), m.
    velocity : (2,) own current velocity, m/s.
    time_horizon : s, collisions later than this are not avoided (the VO's cut-off).
    time_step : s, the control period (used when the discs already overlap).
    responsibility : (N,) share of the avoidance this agent takes: 0.5 reciprocal (ORCA),
        1.0 for a neighbour that does not avoid (a static obstacle, a robot that yields to us
        not, or one not controlled).

    Returns
    -------
    points : (N, 2) a point on each line, m/s.
    directions : (N, 2) unit direction of each line; permitted velocities lie to its left.
    """
    rel_pos = np.asarray(rel_pos, dtype=np.float64).reshape(-1, 2)
    rel_vel = np.asarray(rel_vel, dtype=np.float64).reshape(-1, 2)
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    dist_sq = np.einsum("ij,ij->i", rel_pos, rel_pos)
    r_sq = r * r
    inv_tau = 1.0 / time_horizon
    apart = dist_sq > r_sq
    # vector from the cut-off centre to the relative velocity (the overlap case uses the
    # control period as horizon, as RVO2 does)
    inv_t = np.where(apart, inv_tau, 1.0 / time_step)[:, None]
    w = rel_vel - inv_t * rel_pos
    w_len_sq = np.einsum("ij,ij->i", w, w)
    dot1 = np.einsum("ij,ij->i", w, rel_pos)
    on_cutoff = ~apart | ((dot1 < 0.0) & (dot1 * dot1 > r_sq * w_len_sq))
    w_len = np.sqrt(np.maximum(w_len_sq, 1e-300))
    unit_w = w / w_len[:, None]
    cut_dir = np.stack([unit_w[:, 1], -unit_w[:, 0]], axis=1)
    cut_u = ((r * inv_t[:, 0]) - w_len)[:, None] * unit_w
    # the legs of the cone
    leg = np.sqrt(np.maximum(dist_sq - r_sq, 0.0))
    px, py = rel_pos[:, 0], rel_pos[:, 1]
    left = px * w[:, 1] - py * w[:, 0] > 0.0
    safe_d = np.maximum(dist_sq, 1e-300)
    left_dir = np.stack([px * leg - py * r, px * r + py * leg], axis=1) / safe_d[:, None]
    right_dir = -np.stack([px * leg + py * r, -px * r + py * leg], axis=1) / safe_d[:, None]
    leg_dir = np.where(left[:, None], left_dir, right_dir)
    dot2 = np.einsum("ij,ij->i", rel_vel, leg_dir)
    leg_u = dot2[:, None] * leg_dir - rel_vel
    directions = np.where(on_cutoff[:, None], cut_dir, leg_dir)
    u = np.where(on_cutoff[:, None], cut_u, leg_u)
    resp = np.broadcast_to(np.asarray(responsibility, dtype=np.float64), r.shape)
    points = np.asarray(velocity, dtype=np.float64)[None, :] + resp[:, None] * u
    return points, directions


def contact_halfplanes(
    rel_pos: np.ndarray,
    rel_vel: np.ndarray,
    hard: np.ndarray,
    velocity: np.ndarray,
    closing_time: float,
    responsibility: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Half-planes that close the gap between two bodies' discs no faster than in
    ``closing_time``, along the line of centres: the approach speed of the pair stays at most
    ``(distance - hard) / closing_time`` (negative inside ``hard``: they part at that speed).

    What ORCA's velocity obstacle becomes as the gap to the combined radius goes to zero (the
    cone opens to the half-plane of approaching velocities). RVO2's overlap half-plane is
    tangent to the cut-off disc of one time step, which for a horizon of a control period is
    this line; parted over a longer time it tilts with the relative velocity and admits a pass
    straight through the other robot within that time (two lizis whose discs touched drove into
    each other at 0.25 m/s on the circle of 16). Arguments as `orca_halfplanes`; ``hard`` (N,) m
    the radii the bodies must not come inside (their circumscribed discs, without the tracking
    allowance). Returns (points (N, 2), directions (N, 2)).
    """
    n, gaps = disc_gaps(rel_pos, hard)
    return contact_halfplanes_along(n, gaps, rel_vel, velocity, closing_time, responsibility)


def disc_gaps(rel_pos: np.ndarray, hard: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Discs' `fleetsim.nav.multirobot.polygon_vo.shape_gaps`: the unit line of centres
    (N, 2) towards each other body at ``rel_pos`` (N, 2) m, and the distance minus the combined
    radii ``hard`` (N,) m (negative by the depth of an overlap)."""
    rel_pos = np.asarray(rel_pos, dtype=np.float64).reshape(-1, 2)
    dist = np.sqrt(np.einsum("ij,ij->i", rel_pos, rel_pos))
    gaps = dist - np.asarray(hard, dtype=np.float64).reshape(-1)
    return rel_pos / np.maximum(dist, 1e-9)[:, None], gaps


def contact_halfplanes_along(
    normals: np.ndarray,
    gaps: np.ndarray,
    rel_vel: np.ndarray,
    velocity: np.ndarray,
    closing_time: float,
    responsibility: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """`contact_halfplanes` for bodies of any shape: the approach speed along unit
    ``normals`` (N, 2) (the way the two close their gap fastest) stays at most
    ``gaps / closing_time`` (``gaps`` (N,) m, negative by the depth of an overlap). For discs
    the normal is the line of centres and the gap the distance minus the radii; for polygons
    `fleetsim.nav.multirobot.polygon_vo.shape_gaps`. Other arguments as `contact_halfplanes`'s."""
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 2)
    rel_vel = np.asarray(rel_vel, dtype=np.float64).reshape(-1, 2)
    allowed = np.asarray(gaps, dtype=np.float64).reshape(-1) / closing_time
    u = (allowed - np.einsum("ij,ij->i", rel_vel, n))[:, None] * n
    resp = np.broadcast_to(np.asarray(responsibility, dtype=np.float64), allowed.shape)
    points = np.asarray(velocity, dtype=np.float64)[None, :] + resp[:, None] * u
    return points, np.stack([-n[:, 1], n[:, 0]], axis=1)


@numba.njit(cache=True)
def _det(ax, ay, bx, by):
    return ax * by - ay * bx


@numba.njit(cache=True)
def _lp1(P, D, n, radius, opt, direction_opt, result):
    """Optimise along line n subject to lines [0, n) and the disc (RVO2 linearProgram1)."""
    dot = P[n, 0] * D[n, 0] + P[n, 1] * D[n, 1]
    disc = dot * dot + radius * radius - (P[n, 0] ** 2 + P[n, 1] ** 2)
    if disc < 0.0:
        return False
    s = math.sqrt(disc)
    t_left = -dot - s
    t_right = -dot + s
    for i in range(n):
        den = _det(D[n, 0], D[n, 1], D[i, 0], D[i, 1])
        num = _det(D[i, 0], D[i, 1], P[n, 0] - P[i, 0], P[n, 1] - P[i, 1])
        if abs(den) <= RVO_EPSILON:
            # (nearly) parallel: line n lies on the wrong side of line i. RVO2 tests num < 0;
            # two neighbours 1e-14 m apart give lines that differ by rounding only, and that
            # made a feasible program infeasible (found by the grid-search property test)
            if num < -PARALLEL_SLACK:
                return False
            continue
        t = num / den
        if den >= 0.0:
            t_right = min(t_right, t)
        else:
            t_left = max(t_left, t)
        if t_left > t_right:
            return False
    if direction_opt:
        if opt[0] * D[n, 0] + opt[1] * D[n, 1] > 0.0:
            t = t_right
        else:
            t = t_left
    else:
        t = D[n, 0] * (opt[0] - P[n, 0]) + D[n, 1] * (opt[1] - P[n, 1])
        t = min(max(t, t_left), t_right)
    result[0] = P[n, 0] + t * D[n, 0]
    result[1] = P[n, 1] + t * D[n, 1]
    return True


@numba.njit(cache=True)
def _lp2(P, D, count, radius, opt, direction_opt, result):
    """RVO2 linearProgram2: index of the first line that fails, or ``count``."""
    if direction_opt:
        result[0] = opt[0] * radius
        result[1] = opt[1] * radius
    elif opt[0] ** 2 + opt[1] ** 2 > radius * radius:
        norm = math.sqrt(opt[0] ** 2 + opt[1] ** 2)
        result[0] = opt[0] / norm * radius
        result[1] = opt[1] / norm * radius
    else:
        result[0] = opt[0]
        result[1] = opt[1]
    keep = np.empty(2)
    for i in range(count):
        if _det(D[i, 0], D[i, 1], P[i, 0] - result[0], P[i, 1] - result[1]) > 0.0:
            keep[0] = result[0]
            keep[1] = result[1]
            if not _lp1(P, D, i, radius, opt, direction_opt, result):
                result[0] = keep[0]
                result[1] = keep[1]
                return i
    return count


@numba.njit(cache=True)
def _lp3(P, D, count, num_obst, begin, radius, result):
    """RVO2 linearProgram3: least largest violation of the agent lines, obstacle lines hard."""
    distance = 0.0
    PP = np.empty((count, 2))
    PD = np.empty((count, 2))
    opt = np.empty(2)
    keep = np.empty(2)
    for i in range(begin, count):
        if _det(D[i, 0], D[i, 1], P[i, 0] - result[0], P[i, 1] - result[1]) > distance:
            m = 0
            for j in range(num_obst):
                PP[m] = P[j]
                PD[m] = D[j]
                m += 1
            for j in range(num_obst, i):
                den = _det(D[i, 0], D[i, 1], D[j, 0], D[j, 1])
                if abs(den) <= RVO_EPSILON:
                    if D[i, 0] * D[j, 0] + D[i, 1] * D[j, 1] > 0.0:
                        continue
                    px = 0.5 * (P[i, 0] + P[j, 0])
                    py = 0.5 * (P[i, 1] + P[j, 1])
                else:
                    t = _det(D[j, 0], D[j, 1], P[i, 0] - P[j, 0], P[i, 1] - P[j, 1]) / den
                    px = P[i, 0] + t * D[i, 0]
                    py = P[i, 1] + t * D[i, 1]
                dx = D[j, 0] - D[i, 0]
                dy = D[j, 1] - D[i, 1]
                norm = math.sqrt(dx * dx + dy * dy)
                if norm <= RVO_EPSILON:
                    continue
                PP[m, 0] = px
                PP[m, 1] = py
                PD[m, 0] = dx / norm
                PD[m, 1] = dy / norm
                m += 1
            keep[0] = result[0]
            keep[1] = result[1]
            opt[0] = -D[i, 1]
            opt[1] = D[i, 0]
            if _lp2(PP, PD, m, radius, opt, True, result) < m:
                result[0] = keep[0]
                result[1] = keep[1]
            distance = _det(D[i, 0], D[i, 1], P[i, 0] - result[0], P[i, 1] - result[1])


@numba.njit(cache=True)
def _solve(P, D, num_obst, radius, pref):
    result = np.zeros(2)
    count = P.shape[0]
    fail = _lp2(P, D, count, radius, pref, False, result)
    if fail < count:
        _lp3(P, D, count, num_obst, fail, radius, result)
    return result, fail


def orca_velocity(
    points: np.ndarray,
    directions: np.ndarray,
    max_speed: float,
    preferred: np.ndarray,
    num_obstacle_lines: int = 0,
) -> tuple[np.ndarray, bool]:
    """The permitted velocity closest to ``preferred`` (RVO2's computeNewVelocity).

    Parameters
    ----------
    points, directions : (L, 2) half-planes (`orca_halfplanes`), the first
        ``num_obstacle_lines`` of them static obstacles, which stay hard when infeasible.
    max_speed : m/s, radius of the speed disc.
    preferred : (2,) preferred velocity, m/s.

    Returns
    -------
    velocity : (2,) m/s.
    feasible : False when the 3-D program had to relax the agent half-planes.
    """
    P = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    D = np.ascontiguousarray(directions, dtype=np.float64).reshape(-1, 2)
    pref = np.ascontiguousarray(preferred, dtype=np.float64).reshape(2)
    result, fail = _solve(P, D, int(num_obstacle_lines), float(max_speed), pref)
    return result, bool(fail >= P.shape[0])
