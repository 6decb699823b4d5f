"""TrajectoryPlanner::createTrajectories: the velocity samples and the choice among them.

All samples (forward, strafing, in-place, sideways, escape) are scored in one batch; the
choice then replays base_local_planner's order and tie rules, including its oscillation
flags (``stuck_left`` / ``stuck_right`` ...) and escape mode, kept on the planner.

With ``alignment_scale`` > 0 (a fleetsim addition, off by default) rotations and escapes also
weigh the path's direction (`path_heading`): an in-place rotation whose look-ahead lands on an
obstacle is judged by how near it comes to that direction, and an escaping robot turns only
toward it, else backs on (`_escape_can_turn`); with ``back_along_plan`` too (another fleetsim
addition, off by default) a robot facing away from its plan turns toward it where it can turn
all the way, else backs along it (`_toward_the_plan`). With 0 every choice is
base_local_planner's.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from fleetsim.nav.costmap.footprint import footprint_costs

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
    if tp.backing_from is not None:
        i = _backing_on(tp, costs, g, dvth, pose, direction)
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
    if backs and best_cost >= 0 and _facing_away(pose, direction) and not _blocked_here(tp, pose):
        i = _toward_the_plan(tp, samples, costs, g, dvth, pose, direction, best)
        if i != best and samples[i, 0] < 0:
            tp.backing_from = (pose[0], pose[1])
        best, best_cost = i, costs[i]
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


#: rad: a robot this far off the path's direction faces away from its plan (and backs along
#: it, `_toward_the_plan`), until it is less than a quarter turn off (`_backing_on`)
FACING_AWAY = 2.0 * math.pi / 3.0


def _facing_away(pose, direction: float | None, limit: float = FACING_AWAY) -> bool:
    """With alignment: whether the robot faces more than ``limit`` off the path's direction
    (see `_toward_the_plan`). The band between a quarter turn and ``FACING_AWAY`` keeps a
    robot square to its plan from alternating: with one limit, a quarter turn, a lizi across
    the corridor's end (office, one lizi, seed 1) backed 2 cm, crossed it, drove 2 cm forward,
    and did so again for 240 s."""
    return direction is not None and abs(_wrap(pose[2] - direction)) > limit


def _toward_the_plan(
    tp: TrajectoryPlanner, samples, costs, g: dict, dvth: float, pose, direction: float, best: int
) -> int:
    """For a robot facing away from its plan (`_facing_away`), in place of ``best``,
    base_local_planner's choice, when that is a forward move that does not turn it within a
    quarter turn of the path's direction or an in-place rotation the way it cannot turn all
    the way (`_turning_way`): where it can turn all the way, the legal in-place rotation that
    way that looks best (in-place rotation's rule); else the clearest legal back-up
    (`_clearest_back_up`), which starts backing along the plan (`_backing_on`). ``best``
    when there is neither, or it needs no replacing.

    Departure from base_local_planner, which takes any legal forward rollout before turning
    or backing up. A lizi that had come along a room's wall, its centre 0.25 m from it (the
    circumscribed radius: no room to turn in place), with its plan going back through the
    door behind it, drove 2 m forward along the wall into the room's corner, backed out
    0.5 m, and did so again for 1000 s (office, two lizis, seed 1). Backing along the plan
    until it can turn all the way toward it turns it round where there is room; stopping
    where the first rollout of a turn is legal, it turns a little, at a door's post, and
    backs again, to and fro. The back-up kept clearest of obstacles is taken: the footprint
    check lets the outline sit on the cell next to a wall's, and a lizi backing straight along
    a corridor wall at a slant scraped it (office, one lizi, seed 1)."""
    vx, vy, vth = samples[best]
    quarter = 0.5 * math.pi
    turning = vx == 0.0 and vy == 0.0 and vth != 0.0
    if not turning and not (vx > 0.0 and _least_heading_error(tp, best, direction) > quarter):
        return best
    way, rotation = _turning_way(tp, costs, g, dvth, pose, direction)
    if turning and way and (vth > 0) == (way > 0):
        return best
    if way:
        return rotation
    i = _clearest_back_up(tp, costs, g, dvth)
    if i < 0:
        tp.backing_blocked_at = (pose[0], pose[1])
        return best
    return i


#: m: how far a robot facing away from its plan backs along it at most in one go
BACKING_ROOM = 3.0


def _backing_on(tp: TrajectoryPlanner, costs, g: dict, dvth: float, pose, direction) -> int:
    """For a robot backing along its plan (``backing_from``, set by `_toward_the_plan`): the
    back-up to go on with (`_clearest_back_up`), or -1 (and the backing ends) once it faces
    the plan, can turn all the way to it (`_turning_way`), has backed ``BACKING_ROOM`` m, or
    has no legal back-up. Backing a cycle at a time and deciding afresh, the robot went back
    and forth a centimetre a cycle between the forward move and the back-up (office, two
    lizis, seed 1, in a door)."""
    bx, by = tp.backing_from
    if (
        not _facing_away(pose, direction, 0.5 * math.pi)
        or math.hypot(pose[0] - bx, pose[1] - by) > BACKING_ROOM
        or _turning_way(tp, costs, g, dvth, pose, direction)[0]
    ):
        tp.backing_from = None
        return -1
    i = _clearest_back_up(tp, costs, g, dvth)
    if i < 0:
        tp.backing_from = None
        tp.backing_blocked_at = (pose[0], pose[1])
    return i


#: m: how far a robot whose backing along its plan was blocked moves base_local_planner's
#: way before it backs along its plan again
BLOCKED_ROOM = 0.5


def _blocked_here(tp: TrajectoryPlanner, pose) -> bool:
    """Whether backing along the plan was blocked within ``BLOCKED_ROOM`` of the robot: then
    base_local_planner's choice stands. In a corner with no room behind (office, one lizi,
    seed 1: the west end of the corridor), backing 2 cm and driving 2 cm forward by turns
    held a lizi for 240 s; driving on base_local_planner's way it turns round where there is
    room."""
    at = tp.backing_blocked_at
    if at is None:
        return False
    if math.hypot(pose[0] - at[0], pose[1] - at[1]) > BLOCKED_ROOM:
        tp.backing_blocked_at = None
        return False
    return True


def _clearest_back_up(tp: TrajectoryPlanner, costs, g: dict, dvth: float) -> int:
    """Among the legal back-ups (straight, or turning as the escape's), the one whose
    rollout keeps the robot's centre on the cheapest cells (the highest inflation cost it
    meets: inflation falls with the distance from obstacles), then as the escape ranks them
    (`_escape_choice`); -1 when none is legal. The footprint check lets the outline sit on the
    cell next to a wall's: a lizi backing straight along a corridor wall at a slant scraped it
    (office, one lizi, seed 1), where a back-up that turns parallel to it keeps clear."""
    m = tp.costmap
    h, w = m.costs.shape
    candidates = [g["escape"].start] + [
        i
        for k, i in enumerate(range(g["escape_turn"].start, g["escape_turn"].stop))
        if not -dvth <= tp._in_place_raw[k] <= dvth
    ]
    direction = path_heading(tp, tp._poses[g["escape"].start, 0])
    best, best_key = -1, None
    for i in candidates:
        if costs[i] < 0 or _refused(tp, i):
            continue
        n = max(int(tp._steps[i]), 1)
        cx = np.floor((tp._poses[i, :n, 0] - m.origin_x) / m.resolution).astype(np.int64)
        cy = np.floor((tp._poses[i, :n, 1] - m.origin_y) / m.resolution).astype(np.int64)
        if cx.min() < 0 or cy.min() < 0 or cx.max() >= w or cy.max() >= h:
            continue
        rank = _escape_key(tp, i, direction)
        if rank is None:
            continue
        key = (int(m.costs[cy, cx].max()), rank)
        if best_key is None or key < best_key:
            best, best_key = i, key
    return best


def _turning_way(tp: TrajectoryPlanner, costs, g: dict, dvth: float, pose, direction: float):
    """The way the robot turns toward the path's direction, and the in-place rotation to do
    it with: a way a full turn is legal (`_turn_room`) in which some in-place rotation's
    rollout is legal too, the one that looks best by in-place rotation's rule; (0, -1) when
    there is none (a full turn can be legal where every rollout of the sampled rates, 0.6 rad
    or more, overshoots into an obstacle: turning that way would never start)."""
    raw = tp._in_place_raw
    for way in _turn_room(tp, pose, direction):
        chosen, chosen_key = -1, None
        for k, i in enumerate(range(g["in_place"].start, g["in_place"].stop)):
            v = raw[k]
            if costs[i] < 0 or -dvth <= v <= dvth or (v > 0) != (way > 0):
                continue
            ahead = _ahead_goal_dist_turning(tp, i)
            if ahead is None:
                continue
            key = (min(ahead[0], float(tp.goal_dist.size)), _least_heading_error(tp, i, direction))
            if (chosen_key is None or key < chosen_key) and not _refused(tp, i):
                chosen, chosen_key = i, key
        if chosen >= 0:
            return way, chosen
    return 0, -1


#: rad: the heading step of `_turn_room`'s check
TURN_STEP = 0.05


def _turn_room(tp: TrajectoryPlanner, pose, direction: float) -> list[int]:
    """The ways the robot can turn in place from its heading to ``direction`` with its
    footprint legal on the local costmap all the way: +1 (counter-clockwise), -1, the
    shorter way first."""
    m = tp.costmap
    x, y, th = pose
    short = _wrap(direction - th)
    ways = []
    for turn in (short, short - math.copysign(2.0 * math.pi, short)):
        n = max(math.ceil(abs(turn) / TURN_STEP), 1)
        headings = th + turn * np.arange(1, n + 1) / n
        poses = np.column_stack([np.full(n, x), np.full(n, y), headings])
        fc = footprint_costs(m.costs, m.origin_x, m.origin_y, m.resolution, tp.outline, poses)
        if np.all(fc >= 0):
            ways.append(1 if turn > 0 else -1)
    return ways


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
