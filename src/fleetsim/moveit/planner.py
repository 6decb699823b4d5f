"""Joint-space planning with OMPL (its official Python wheels), as MoveIt's OMPL interface.

The state space is the group's joints within their bounds; a state is valid when
``CollisionScene.is_valid`` says so; motions are checked at 0.2 % of the space's extent
(``longest_valid_segment_fraction``, finer than MoveIt's 1 %: 0.018 rad for the hunter, so that
its 34 mm tip plate cannot step through an obstacle between two checks). The planner is the
request's, else the group's ``default_planner_config`` from ompl_planning.yaml, else RRTConnect.
The solution is simplified (shortcutting) and returned as waypoints. When the straight motion
from start to goal is free, it is returned without running a planner, and the plan says so
(``Plan.planner`` empty). Failures are typed.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from fleetsim.errors import PlanningError

LONGEST_VALID_SEGMENT_FRACTION = 0.002
_SEEDED = False


class PlanFailure(PlanningError):
    """A request that could not be planned; ``code`` is a MoveItErrorCodes value."""

    def __init__(self, code: int, text: str) -> None:
        super().__init__(text)
        self.code = code


def planner_names() -> list[str]:
    from ompl import geometric as og

    return [
        n
        for n in ("RRTConnect", "RRT", "RRTstar", "PRM", "PRMstar", "KPIECE1", "BKPIECE1",
                  "LBKPIECE1", "EST", "BiEST", "SBL", "FMT", "BITstar", "InformedRRTstar")
        if hasattr(og, n)
    ]  # fmt: skip


#: MoveIt's ompl_planning.yaml names -> OMPL class names
ALIASES = {"KPIECE": "KPIECE1", "BKPIECE": "BKPIECE1", "LBKPIECE": "LBKPIECE1"}


@dataclass
class Plan:
    path: np.ndarray  # (N, J) waypoints, rad
    planning_time: float  # s (wall)
    planner: str  # the OMPL planner that found the path; "" when none ran (STRAIGHT_LINE)


#: how a plan whose straight joint-space motion was free (and no OMPL planner ran) is named
STRAIGHT_LINE = "straight joint-space motion (no OMPL planner run)"


def motion_is_valid(a, b, lower, upper, is_valid) -> bool:
    """Every state on the straight motion a -> b, at OMPL's checking resolution, is valid."""
    resolution = LONGEST_VALID_SEGMENT_FRACTION * float(np.linalg.norm(upper - lower))
    steps = max(1, int(np.ceil(np.linalg.norm(b - a) / resolution)))
    return all(is_valid(a + (b - a) * (k / steps)) for k in range(1, steps + 1))


def _quiet():
    from ompl import util as ou

    ou.setLogLevel(ou.LogLevel.LOG_WARN)


def plan_path(
    start: np.ndarray,
    goal: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    is_valid,
    planner: str = "RRTConnect",
    timeout: float = 5.0,
    attempts: int = 1,
    seed: int | None = None,
    try_straight: bool = True,
) -> Plan:
    """A collision-free joint path from ``start`` to ``goal`` (J,), simplified.

    With ``try_straight`` a free straight motion is returned without running the planner
    (``Plan.planner`` ""); without it the planner always runs, as in MoveIt.

    Raises ``PlanFailure`` with START_STATE_IN_COLLISION, GOAL_IN_COLLISION or PLANNING_FAILED.
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    from fleetsim.msgs.moveit_msgs import MoveItErrorCodes as E

    _quiet()
    name = ALIASES.get(planner, planner)
    if not hasattr(og, name) or name not in planner_names():
        raise PlanFailure(
            E.INVALID_GOAL_CONSTRAINTS,
            f"unknown planner '{planner}'; available: {', '.join(planner_names())}",
        )
    global _SEEDED
    if seed is not None and not _SEEDED:
        # OMPL seeds every planner's generator from one process-wide seed that can be set only
        # before the first sampler exists: the first request's seed fixes it for the process
        ou.RNG.setSeed(int(seed) % (2**31 - 1) + 1)
        _SEEDED = True
    if not is_valid(start):
        raise PlanFailure(E.START_STATE_IN_COLLISION, "the start state is in collision")
    if not is_valid(goal):
        raise PlanFailure(E.GOAL_IN_COLLISION, "the goal state is in collision")
    n = len(start)
    t0 = time.perf_counter()
    if try_straight and motion_is_valid(start, goal, lower, upper, is_valid):
        # the straight joint-space motion is free: what RRTConnect plus shortcutting would
        # return, without growing trees (a fleetsim shortcut; MoveIt always runs the planner)
        return Plan(np.array([start, goal], float), time.perf_counter() - t0, "")
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    space.setLongestValidSegmentFraction(LONGEST_VALID_SEGMENT_FRACTION)
    best = None
    for _ in range(max(1, attempts)):
        ss = og.SimpleSetup(space)
        ss.setStateValidityChecker(lambda s: is_valid(np.array([s[i] for i in range(n)])))
        a, b = space.allocState(), space.allocState()
        for i in range(n):
            a[i], b[i] = float(start[i]), float(goal[i])
        ss.setStartAndGoalStates(a, b)
        ss.setPlanner(getattr(og, name)(ss.getSpaceInformation()))
        remaining = timeout - (time.perf_counter() - t0)
        if remaining <= 0:
            break
        if not ss.solve(remaining) or not ss.haveExactSolutionPath():
            continue
        ss.simplifySolution()
        p = ss.getSolutionPath()
        path = np.array([[p.getState(k)[i] for i in range(n)] for k in range(p.getStateCount())])
        length = np.linalg.norm(np.diff(path, axis=0), axis=1).sum()
        if best is None or length < best[1]:
            best = (path, length)
    if best is None:
        raise PlanFailure(
            E.PLANNING_FAILED,
            f"{name} found no collision-free path within {timeout:g} s ({attempts} attempt(s))",
        )
    return Plan(best[0], time.perf_counter() - t0, name)
