"""What a scored rollout of TrajectoryPlannerROS says beyond its cost: the goal distance
``heading_lookahead`` ahead of it (base_local_planner's rule for rotations and back-ups, and
fleetsim's for a rotation judged over every pose it passes), its headings against the path's
direction (`path_heading`, the ``alignment_scale`` rules), and whether the global costmap guard
refuses it. Read by the choice (`fleetsim.nav.controllers.selection`), the escape
(`fleetsim.nav.controllers.escape`) and ``back_along_plan`` (`fleetsim.nav.controllers.backing`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

if TYPE_CHECKING:
    from fleetsim.nav.controllers.trajectory_planner import TrajectoryPlanner


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


def _refused(tp: TrajectoryPlanner, index: int) -> bool:
    """Whether the global costmap guard (``global_costmap_check``, `global_guard`) refuses
    rollout ``index`` (as far as `GlobalCostmapGuard.checked_poses` looks)."""
    guard = tp.global_guard
    return guard is not None and guard.refuses(guard.checked_poses(tp, index))
