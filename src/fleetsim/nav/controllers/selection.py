"""TrajectoryPlanner::createTrajectories: the velocity samples and the choice among them.

All samples (forward, strafing, in-place, sideways, escape) are scored in one batch; the
choice then replays base_local_planner's order and tie rules, including its oscillation
flags (``stuck_left`` / ``stuck_right`` ...) and escape mode, kept on the planner.

With ``alignment_scale`` > 0 (a fleetsim addition, off by default) rotations and escapes also
weigh the path's direction (`path_heading`): an in-place rotation whose look-ahead lands on an
obstacle is judged by how near it comes to that direction, and an escaping robot turns only
toward it, else backs on (`_escape_can_turn`); with ``back_along_plan`` too (another fleetsim
addition, off by default) a robot facing away from its plan turns toward it where it can turn
all the way, else backs along it (`fleetsim.nav.controllers.backing`). With 0 every choice is
base_local_planner's. What a rollout says beyond its cost is read in
`fleetsim.nav.controllers.lookahead`; the escape, taken last, is `fleetsim.nav.controllers.escape`.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from fleetsim.nav.controllers import backing
from fleetsim.nav.controllers.escape import (
    _end_escape_when_clear,
    _escape,
    _escape_choice,
    _padding_way_out,
)
from fleetsim.nav.controllers.lookahead import (
    _ahead_goal_dist,
    _ahead_goal_dist_turning,
    _aligning,
    _least_heading_error,
    _refused,
    _turns_toward,
    path_heading,
)

if TYPE_CHECKING:
    from fleetsim.nav.controllers.trajectory_planner import TrajectoryPlanner


def velocity_samples(
    tp: TrajectoryPlanner, pose, vel
) -> tuple[np.ndarray, dict[str, slice], float]:
    """Every sample, grouped: (S, 3) (vx, vy, vtheta), the group slices, and the in-place
    samples' dvtheta."""
    p = tp.params
    x, y = pose[0], pose[1]
    max_vx = p.max_vel_x
    if tp.plan.shape[0]:
        gx, gy = tp.plan[-1, 0], tp.plan[-1, 1]
        max_vx = min(max_vx, math.hypot(gx - x, gy - y) / p.sim_time)
    window = tp.sim_period if p.dwa else p.sim_time
    max_vx = max(min(max_vx, vel[0] + p.acc_lim_x * window), p.min_vel_x)
    min_vx = max(p.min_vel_x, vel[0] - p.acc_lim_x * window)
    max_vth = min(p.max_vel_theta, vel[2] + p.acc_lim_theta * window)
    min_vth = max(p.min_vel_theta, vel[2] - p.acc_lim_theta * window)
    dvx = (max_vx - min_vx) / (p.vx_samples - 1) if p.vx_samples > 1 else 0.0
    dvth = (max_vth - min_vth) / (p.vtheta_samples - 1) if p.vtheta_samples > 1 else 0.0
    in_place_lo, in_place_dvth = min_vth, dvth
    if p.dwa:
        in_place_lo, in_place_dvth = _in_place_window(p, vel[2])
    layout = tp._sample_layout
    if layout is None or layout[0] is not p:
        layout = tp._sample_layout = _sample_layout(p)
    _, holonomic, y_vels, groups = layout
    samples, tp._in_place_raw = _sample_table(
        int(p.vx_samples), int(p.vtheta_samples), float(min_vx), float(dvx), float(min_vth),
        float(dvth), float(in_place_lo), float(in_place_dvth), float(p.min_in_place_vel_theta),
        holonomic, y_vels, float(p.escape_vel),
    )  # fmt: skip
    return samples, groups, in_place_dvth


def _sample_layout(p) -> tuple:
    """What of the sample table depends on the parameters only: (the parameters, holonomic,
    the sideways rates (K,), the group slices)."""
    holonomic = bool(p.holonomic_robot)
    y_vels = np.asarray(p.y_vels if holonomic else (), dtype=np.float64)
    groups: dict[str, slice] = {}
    n = 0
    for name, k in (
        ("forward", p.vx_samples * p.vtheta_samples),
        ("strafe", 2 if holonomic else 0),
        ("in_place", p.vtheta_samples),
        ("sideways", y_vels.shape[0]),
        ("escape", 1),
        ("escape_turn", p.vtheta_samples),
    ):
        groups[name] = slice(n, n + k)
        n += k
    return p, holonomic, y_vels, groups


@njit(cache=True)
def _sample_table(nx, nth, min_vx, dvx, min_vth, dvth, in_lo, in_d, mn, holonomic, y_vels, esc):
    """`velocity_samples`' table in createTrajectories' order, compiled (every control cycle of
    every robot; its ~15 NumPy calls cost ~30 us): forward (each vx first with vtheta 0, then
    the sweep ``min_vth + j dvth``), two strafes when ``holonomic``, rotations in place at
    ``in_lo + j in_d`` raised to ``mn`` (signed), sideways moves at ``y_vels``, the escape at
    ``esc``, and backing at ``esc`` with the in-place rates (their raw rates are returned
    too). Each value is the same float operation as NumPy's ``lo + arange(n) * d``."""
    n_side = y_vels.shape[0]
    size = nx * nth + (2 if holonomic else 0) + nth + n_side + 1 + nth
    out = np.zeros((size, 3))
    raw = np.empty(nth)
    k = 0
    for i in range(nx):
        vx = min_vx + i * dvx
        for j in range(nth):
            out[k, 0] = vx
            if j > 0:
                out[k, 2] = min_vth + (j - 1) * dvth
            k += 1
    if holonomic:
        out[k, 0], out[k, 1] = 0.1, 0.1
        out[k + 1, 0], out[k + 1, 1] = 0.1, -0.1
        k += 2
    for j in range(nth):
        v = in_lo + j * in_d
        raw[j] = v
        if v > 0:  # np.maximum(v, mn) and np.minimum(v, -mn), ties (signed zeros) included
            out[k, 2] = v if v > mn else mn
        else:
            out[k, 2] = v if v < -mn else -mn
        k += 1
    for j in range(n_side):
        out[k, 1] = y_vels[j]
        k += 1
    out[k, 0] = esc
    k += 1
    for j in range(nth):
        out[k, 0] = esc
        out[k, 2] = raw[j]
        k += 1
    return out, raw


def _in_place_window(p, vth: float) -> tuple[float, float]:
    """The in-place rotation rates sampled with ``dwa``: the window of ``sim_time``, not of one
    control period, as its lowest rate and its spacing.

    Departure from base_local_planner, which samples them in DWA's window of one period.
    A robot already turning faster than it can stop in one period then has only rotations
    the same way to choose from (the slowest one even raised to min_in_place_vel_theta, faster
    than it turns now): wedged at a gap with every forward rollout illegal it spun past the
    heading it needed, and back (BARN world 141, heading swinging 0.4-2.0 rad for 85 s). The
    rollouts still start from the robot's velocity within the acceleration limits, so a
    rotation the other way is checked as the base would brake into it."""
    lo = max(p.min_vel_theta, vth - p.acc_lim_theta * p.sim_time)
    hi = min(p.max_vel_theta, vth + p.acc_lim_theta * p.sim_time)
    d = (hi - lo) / (p.vtheta_samples - 1) if p.vtheta_samples > 1 else 0.0
    return lo, d


def _bookkeep(tp: TrajectoryPlanner, sample, pose) -> None:
    """Oscillation flags and escape reset after a legal choice."""
    vx, vy, vth = sample
    x, y, th = pose
    if not vx > 0:
        if vth < 0:
            if tp.rotating_right:
                tp.stuck_right = True
            tp.rotating_right = True
        elif vth > 0:
            if tp.rotating_left:
                tp.stuck_left = True
            tp.rotating_left = True
        elif vy > 0:
            if tp.strafe_right:
                tp.stuck_right_strafe = True
            tp.strafe_right = True
        elif vy < 0:
            if tp.strafe_left:
                tp.stuck_left_strafe = True
            tp.strafe_left = True
        tp.prev = (x, y)
    if math.hypot(x - tp.prev[0], y - tp.prev[1]) > tp.params.oscillation_reset_dist:
        tp._reset_oscillation_flags()
    _end_escape_when_clear(tp, x, y, th)


def choose_trajectory(tp: TrajectoryPlanner, pose, vel):
    """The chosen sample, its cost and its batch index (cost < 0: nothing legal)."""
    samples, g, dvth = velocity_samples(tp, pose, vel)
    costs = tp._score(samples, pose, vel)
    best, best_cost = -1, -1.0
    direction = path_heading(tp, pose) if _aligning(tp) else None
    backs = direction is not None and tp.params.back_along_plan
    if backs and tp.backing_from is not None:
        i = backing.backing_on(tp, costs, g, dvth, pose, direction)
        if i >= 0:
            _bookkeep(tp, samples[i], pose)
            return tuple(samples[i]), float(costs[i]), i

    if not tp.escaping:  # the first sample of least legal cost among forward and strafe
        first = costs[g["forward"].start : g["strafe"].stop]
        legal = first >= 0
        while legal.any():
            i = g["forward"].start + int(np.argmin(np.where(legal, first, np.inf)))
            if not _refused(tp, i):
                best, best_cost = i, costs[i]
                break
            legal[i - g["forward"].start] = False  # the next best, as if this one were illegal
    heading: tuple = (math.inf, 0)  # rotations: (goal distance, step) ahead
    raw = tp._in_place_raw
    size = float(tp.goal_dist.size)
    for k, i in enumerate(range(g["in_place"].start, g["in_place"].stop)):
        v = raw[k]
        ok = costs[i] >= 0 and (best_cost < 0 or costs[i] <= best_cost or samples[best, 1] != 0.0)
        if ok and direction is not None and tp.escaping:
            # escaping with alignment: a rotation away from the path's direction is no way
            # out of a gap entered at a slant; back on instead (see `_escape_can_turn`)
            ok = _turns_toward(tp, i, pose[2], direction)
        if ok and (v > dvth or v < -dvth):
            ahead = _ahead_goal_dist_turning(tp, i)
            if ahead is not None and direction is not None:
                # a look-ahead on an obstacle (distance >= the map's size) says nothing: then
                # the rotation that comes nearest the path's direction, soonest
                d, step = ahead
                ahead = (min(d, size), _least_heading_error(tp, i, direction), step)
            free_side = (v < 0 and not tp.stuck_left) or (v > 0 and not tp.stuck_right)
            if ahead is not None and ahead < heading and free_side and not _refused(tp, i):
                best, best_cost = i, costs[i]
                heading = ahead
    heading_dist = heading[0]
    if backs and best_cost >= 0:
        best = backing.toward_the_plan(tp, samples, costs, g, dvth, pose, direction, best)
        best_cost = costs[best]
    if best_cost >= 0:
        _bookkeep(tp, samples[best], pose)
        return tuple(samples[best]), float(best_cost), best
    for i in range(g["sideways"].start, g["sideways"].stop):
        vy = samples[i, 1]
        if costs[i] >= 0 and (best_cost < 0 or costs[i] <= best_cost):
            ahead = _ahead_goal_dist(tp, i)
            free_side = (vy > 0 and not tp.stuck_left_strafe) or (
                vy < 0 and not tp.stuck_right_strafe
            )
            if ahead is not None and ahead < heading_dist and free_side and not _refused(tp, i):
                best, best_cost = i, costs[i]
                heading_dist = ahead
    if best_cost >= 0:
        _bookkeep(tp, samples[best], pose)
        return tuple(samples[best]), float(best_cost), best
    # back up slowly, even if the map says it is blocked (unless the global costmap knows
    # better: `global_guard`)
    i = _escape_choice(tp, costs, g, dvth)
    if i < 0:
        j = _padding_way_out(tp, costs, g, dvth)
        if j < 0:
            return (0.0, 0.0, 0.0), -1.0, g["escape"].start
        _bookkeep(tp, samples[j], pose)
        return tuple(samples[j]), 1.0, j
    return _escape(tp, costs, g, dvth, samples, pose, i)
