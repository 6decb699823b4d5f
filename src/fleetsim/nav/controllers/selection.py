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
base_local_planner's.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

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


def _ahead_goal_dist(tp: TrajectoryPlanner, index: int) -> float | None:
    """Goal distance at the end of a rollout pushed ``heading_lookahead`` ahead, or None."""
    n = int(tp._steps[index])
    xr, yr, thr = tp._poses[index, n - 1]
    xr += tp.params.heading_lookahead * math.cos(thr)
    yr += tp.params.heading_lookahead * math.sin(thr)
    cell = tp.costmap.world_to_map(xr, yr)
    return None if cell is None else float(tp.goal_dist[cell[1], cell[0]])


def _ahead_goal_dist_turning(tp: TrajectoryPlanner, index: int) -> tuple[float, int] | None:
    """For an in-place rotation: the least goal distance ``heading_lookahead`` ahead of any
    pose of its rollout, and the first step that reaches it; None if none is on the map.

    Departure from base_local_planner, which looks ahead of the rollout's end only. With
    in-place rates sampled over sim_time's window a rollout can turn past a half turn, and its
    end then points anywhere: a burger 0.2 m from its goal with the goal 90 degrees to its
    left chose the rotation whose end, after 315 degrees to the right, pointed at the goal,
    and spun the long way round. Judged by the best heading it passes and how soon, the
    rotation toward the goal wins.
    """
    m = tp.costmap
    dist, step = _turning_lookahead(
        tp._poses[index],
        int(tp._steps[index]),
        tp.params.heading_lookahead,
        m.origin_x,
        m.origin_y,
        m.resolution,
        tp.goal_dist,
    )
    return None if step < 0 else (dist, step)


@njit(cache=True)
def _turning_lookahead(poses, n, look, ox, oy, res, goal_dist):
    """`_ahead_goal_dist_turning` over one rollout's first ``n`` poses, compiled (up to ~80
    poses x 40 rotations a control cycle): the least goal distance ``look`` m ahead of a pose
    on the map and the first step reaching it; step -1 when none is on the map. Cells as
    `Costmap2D.cells_of` (floor of the offset over the resolution)."""
    h, w = goal_dist.shape
    best, step = np.inf, -1
    for i in range(n):
        x = poses[i, 0] + look * math.cos(poses[i, 2])
        y = poses[i, 1] + look * math.sin(poses[i, 2])
        cx = math.floor((x - ox) / res)
        cy = math.floor((y - oy) / res)
        if cx < 0 or cy < 0 or cx >= w or cy >= h:
            continue
        d = goal_dist[cy, cx]
        if step < 0 or d < best:
            best, step = d, i
    return best, step


#: how many escape_reset_dist a robot that cannot turn in place backs up at most
ESCAPE_ROOM = 5.0
#: m: how far along its plan the point lies whose direction is "the path's direction"
PATH_HEADING_DIST = 0.75
#: rad: a robot this close to the path's direction counts as lined up with it
ALIGNED = 0.2


def _wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def path_heading(tp: TrajectoryPlanner, pose) -> float | None:
    """The direction (rad) from the robot to its plan ``PATH_HEADING_DIST`` ahead: from the
    plan point nearest the robot on, the first at least that far from it (else the last).
    None without a plan."""
    plan = tp.plan
    if plan.shape[0] == 0:
        return None
    d = np.hypot(plan[:, 0] - pose[0], plan[:, 1] - pose[1])
    i = int(np.argmin(d))
    far = np.flatnonzero(d[i:] >= PATH_HEADING_DIST)
    j = i + int(far[0]) if far.shape[0] else plan.shape[0] - 1
    if d[j] < 1e-9:
        return None
    return math.atan2(plan[j, 1] - pose[1], plan[j, 0] - pose[0])


def _aligning(tp: TrajectoryPlanner) -> bool:
    """Whether rotations and escapes are judged by the path's direction (``alignment_scale``
    > 0, a fleetsim addition; see `choose_trajectory`)."""
    return tp.params.alignment_scale > 0.0


def _least_heading_error(tp: TrajectoryPlanner, index: int, direction: float) -> float:
    """The least |heading - direction| (rad) over rollout ``index``'s poses."""
    n = max(int(tp._steps[index]), 1)
    return float(np.abs(_wrap(tp._poses[index, :n, 2] - direction)).min())


def _turns_toward(tp: TrajectoryPlanner, index: int, th: float, direction: float | None) -> bool:
    """Whether rollout ``index`` brings the robot nearer the path's direction (or it is
    lined up already)."""
    if direction is None:
        return True
    err = abs(_wrap(th - direction))
    return err <= ALIGNED or _least_heading_error(tp, index, direction) < err - 0.5 * ALIGNED


def _end_escape_when_clear(
    tp: TrajectoryPlanner, x: float, y: float, th: float, can_turn: bool = True
) -> None:
    """Stop escaping once the robot is escape_reset_dist or escape_reset_theta away from
    where the escape began.

    Departure from base_local_planner: the distance ends an escape only where an in-place
    rotation is legal (or after ``ESCAPE_ROOM`` times escape_reset_dist). In a gap barely
    wider than the robot, ROS backs up 0.1 m, drives the same 0.1 m forward into the spot where
    nothing is legal, and backs up again, for ever (the BARN timeouts); backing on, while the
    backward rollout is legal, until the robot can turn lets the in-place rotation that follows
    take it out of the gap."""
    ex, ey, eth = tp.escape_pose
    dth = abs((eth - th + math.pi) % (2 * math.pi) - math.pi)
    dist = math.hypot(x - ex, y - ey)
    reset = tp.params.escape_reset_dist
    if (
        (dist > reset and can_turn)
        or dist > ESCAPE_ROOM * reset
        or dth > tp.params.escape_reset_theta
    ):
        tp.escaping = False


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


def _escape_choice(tp: TrajectoryPlanner, costs: np.ndarray, g: dict, dvth: float) -> int:
    """The escape sample: ROS's straight back-up, or a legal back-up that turns the robot
    to face the way to the goal better (chosen by in-place rotation's rule: the least goal
    distance a heading_lookahead ahead of the rollout's end).

    Departure from base_local_planner, which only backs straight: a robot that entered a gap
    barely wider than itself at a slant (BARN world 105, the jackal 0.6 rad off the gap's
    axis) backs out straight, drives in again at the same slant and is wedged again; backing
    on a curve straightens it out of the gap as a driver's three-point turn does. With
    alignment, a look-ahead on an obstacle ties and the end heading against the path's
    direction decides.

    Rollouts the global costmap guard refuses (`global_guard`) are passed over; -1 when it
    refuses every one."""
    direction = path_heading(tp, tp._poses[g["escape"].start, 0]) if _aligning(tp) else None
    best = g["escape"].start
    best_key = _escape_key(tp, best, direction) if costs[best] >= 0 else None
    if _refused(tp, best):
        best, best_key = -1, None
    raw = tp._in_place_raw
    for k, i in enumerate(range(g["escape_turn"].start, g["escape_turn"].stop)):
        if costs[i] < 0 or -dvth <= raw[k] <= dvth:
            continue
        ki = _escape_key(tp, i, direction)
        if ki is not None and (best_key is None or ki < best_key) and not _refused(tp, i):
            best, best_key = i, ki
    return best


def _escape_key(tp: TrajectoryPlanner, i: int, direction: float | None):
    """How `_escape_choice` ranks back-up ``i`` (least first); None when its look-ahead is
    off the map."""
    ahead = _ahead_goal_dist(tp, i)
    if ahead is None:
        return None
    if direction is None:
        return (ahead,)
    # with alignment: a look-ahead onto an obstacle tells the headings nothing apart, the
    # heading at the end against the path's direction does
    n = max(int(tp._steps[i]), 1)
    size = float(tp.goal_dist.size)
    return (min(ahead, size), abs(_wrap(tp._poses[i, n - 1, 2] - direction)))


def _refused(tp: TrajectoryPlanner, index: int) -> bool:
    """Whether the global costmap guard (``global_costmap_check``, `global_guard`) refuses
    rollout ``index`` (as far as `GlobalCostmapGuard.checked_poses` looks)."""
    guard = tp.global_guard
    return guard is not None and guard.refuses(guard.checked_poses(tp, index))


def _padding_way_out(tp: TrajectoryPlanner, costs: np.ndarray, g: dict, dvth: float) -> int:
    """With every escape refused by the global costmap guard: the in-place rotation or forward
    move illegal only because of the padding (its rollout, as far as the guard looks, keeps
    the body itself off the lethal cells of both costmaps) that looks best by in-place
    rotation's rule (least goal distance ``heading_lookahead`` ahead); -1 if none.

    A fleetsim addition, part of ``global_costmap_check``: a robot wedged within its padding
    of obstacles in front, with the one behind known only to the global costmap, stood
    pinned where ROS would have backed into it (office seed 6: a hunter by a desk for 126 s
    until explore gave up), as navfn's way out frees a robot whose centre is inscribed."""
    guard = tp.global_guard
    if guard is None:
        return -1
    best, best_key = -1, None
    raw = tp._in_place_raw
    candidates = [
        (i, True) for k, i in enumerate(range(g["in_place"].start, g["in_place"].stop))
        if not -dvth <= raw[k] <= dvth
    ] + [(i, False) for i in range(g["forward"].start, g["forward"].stop)]  # fmt: skip
    for i, turning in candidates:
        if costs[i] != -1.0:  # legal ones were refused already; -2: no way to the goal
            continue
        if turning:
            ahead = _ahead_goal_dist_turning(tp, i)
        else:
            d = _ahead_goal_dist(tp, i)
            ahead = None if d is None else (d, 0)
        if ahead is None or (best_key is not None and ahead >= best_key):
            continue
        if guard.body_clear(guard.checked_poses(tp, i)):
            best, best_key = i, ahead
    return best


def _escape_can_turn(tp: TrajectoryPlanner, costs: np.ndarray, g: dict, pose) -> bool:
    """Whether a legal in-place rotation lets the escape end: any one (base_local_planner's
    escape ends after escape_reset_dist), or with alignment only one that turns the robot
    toward the path's direction. A jackal wedged in a gap entered 0.6 rad off its axis could
    turn only further off it (BARN world 45); ending the escape there, it turned away, drove in
    at a slant again and backed out again for 90 s."""
    legal = [i for i in range(g["in_place"].start, g["in_place"].stop) if costs[i] >= 0]
    if not _aligning(tp):
        return bool(legal)
    direction = path_heading(tp, pose)
    return any(_turns_toward(tp, i, pose[2], direction) for i in legal)


def choose_trajectory(tp: TrajectoryPlanner, pose, vel):
    """The chosen sample, its cost and its batch index (cost < 0: nothing legal)."""
    samples, g, dvth = velocity_samples(tp, pose, vel)
    costs = tp._score(samples, pose, vel)
    best, best_cost = -1, -1.0
    direction = path_heading(tp, pose) if _aligning(tp) else None
    backs = direction is not None and tp.params.back_along_plan
    if backs:
        from fleetsim.nav.controllers import backing  # it uses this module's rules

        if tp.backing_from is not None:
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


def _escape(tp: TrajectoryPlanner, costs, g: dict, dvth: float, samples, pose, i: int):
    """Take escape sample ``i`` (`_escape_choice`): enter or keep escape mode, end it when
    clear; returns the sample, its cost (1.0 for a blind one) and ``i``."""
    cost = float(costs[i])
    x, y, th = pose
    if math.hypot(x - tp.prev[0], y - tp.prev[1]) > tp.params.oscillation_reset_dist:
        tp._reset_oscillation_flags()
    if not tp.escaping and cost > -2.0:
        tp.escape_pose = (x, y, th)
        tp.escaping = True
    # backing on is for a robot wedged where it cannot turn, and only while the map says the
    # backward rollout is free (the escape itself is taken blind)
    can_turn = _escape_can_turn(tp, costs, g, pose) or cost < 0.0
    _end_escape_when_clear(tp, x, y, th, can_turn)
    if cost == -1.0:
        cost = 1.0
    return tuple(samples[i]), cost, i
