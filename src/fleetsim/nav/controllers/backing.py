"""TrajectoryPlannerROS's ``back_along_plan`` (a fleetsim addition, off by default; it acts
with ``alignment_scale`` > 0): a robot facing away from its plan turns toward it where it can
turn all the way, else backs along it. `fleetsim.nav.controllers.selection.choose_trajectory`
asks `toward_the_plan` after base_local_planner's choice, and `backing_on` first while the
robot is backing; both use the choice's own rules (rotation and escape ranking, the global
costmap guard).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from fleetsim.nav.controllers.escape import _escape_key
from fleetsim.nav.controllers.lookahead import (
    _ahead_goal_dist_turning,
    _least_heading_error,
    _refused,
    _wrap,
)
from fleetsim.nav.costmap.footprint import footprint_costs

if TYPE_CHECKING:
    from fleetsim.nav.controllers.trajectory_planner import TrajectoryPlanner


#: rad: a robot this far off the path's direction faces away from its plan (and backs along
#: it, `toward_the_plan`), until it is less than a quarter turn off (`backing_on`)
FACING_AWAY = 2.0 * math.pi / 3.0


def _facing_away(pose, direction: float | None, limit: float = FACING_AWAY) -> bool:
    """With alignment: whether the robot faces more than ``limit`` off the path's direction
    (see `toward_the_plan`). The band between a quarter turn and ``FACING_AWAY`` keeps a
    robot square to its plan from alternating: with one limit, a quarter turn, a lizi across
    the corridor's end (office, one lizi, seed 1) backed 2 cm, crossed it, drove 2 cm forward,
    and did so again for 240 s."""
    return direction is not None and abs(_wrap(pose[2] - direction)) > limit


def toward_the_plan(
    tp: TrajectoryPlanner, samples, costs, g: dict, dvth: float, pose, direction: float, best: int
) -> int:
    """``best``, base_local_planner's choice, or what replaces it for a robot facing away from
    its plan (`_facing_away`) and not blocked here (`_blocked_here`): `_replacement`. A
    back-up taken starts the backing (``backing_from``, `backing_on`)."""
    if not _facing_away(pose, direction) or _blocked_here(tp, pose):
        return best
    i = _replacement(tp, samples, costs, g, dvth, pose, direction, best)
    if i != best and samples[i, 0] < 0:
        tp.backing_from = (pose[0], pose[1])
    return i


def _replacement(
    tp: TrajectoryPlanner, samples, costs, g: dict, dvth: float, pose, direction: float, best: int
) -> int:
    """For a robot facing away from its plan (`_facing_away`), in place of ``best``,
    base_local_planner's choice, when that is a forward move that does not turn it within a
    quarter turn of the path's direction or an in-place rotation the way it cannot turn all
    the way (`_turning_way`): where it can turn all the way, the legal in-place rotation that
    way that looks best (in-place rotation's rule); else the clearest legal back-up
    (`_clearest_back_up`), which starts backing along the plan (`backing_on`). ``best``
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
    i = _clearest_back_up(tp, costs, g, dvth, direction)
    if i < 0:
        tp.backing_blocked_at = (pose[0], pose[1])
        return best
    return i


#: m: how far a robot facing away from its plan backs along it at most in one go
BACKING_ROOM = 3.0


def backing_on(tp: TrajectoryPlanner, costs, g: dict, dvth: float, pose, direction) -> int:
    """For a robot backing along its plan (``backing_from``, set by `toward_the_plan`): the
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
    i = _clearest_back_up(tp, costs, g, dvth, direction)
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


def _clearest_back_up(tp: TrajectoryPlanner, costs, g: dict, dvth: float, direction) -> int:
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
