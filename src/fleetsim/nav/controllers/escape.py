"""TrajectoryPlannerROS's escape: when no forward, in-place or sideways sample is legal, back
up slowly even where the map says it is blocked (base_local_planner's escape mode), with
fleetsim's departures: a back-up that turns the robot out of a gap it entered at a slant, an
escape that ends only where the robot can turn (toward the path's direction, with alignment),
and the way out of the padding when the global costmap guard refuses every back-up.
`fleetsim.nav.controllers.selection.choose_trajectory` calls it last.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from fleetsim.nav.controllers.lookahead import (
    _ahead_goal_dist,
    _ahead_goal_dist_turning,
    _aligning,
    _refused,
    _turns_toward,
    _wrap,
    path_heading,
)

if TYPE_CHECKING:
    from fleetsim.nav.controllers.trajectory_planner import TrajectoryPlanner


#: how many escape_reset_dist a robot that cannot turn in place backs up at most
ESCAPE_ROOM = 5.0


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
