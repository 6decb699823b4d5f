"""Typed navigation failures (Nav2's ``planner_exceptions``), all `FleetsimError` subclasses.

move_base turns a planner failure into an aborted goal whose text is ``str(error)``, so each
message gives the pose and the reason.
"""

from __future__ import annotations

from fleetsim.errors import FleetsimError


class MapError(FleetsimError):
    """A map YAML or image that cannot be read or written, or a malformed occupancy grid."""


class CostmapError(FleetsimError):
    """A costmap or layer set up with values it cannot use (footprint, sizes, plugins)."""


class PlannerError(FleetsimError):
    """Base of global planner failures."""


class StartOccupied(PlannerError):
    """The robot's start cell is lethal in the planning costmap."""


class GoalOccupied(PlannerError):
    """The goal (and every cell within ``default_tolerance``) is in an obstacle."""


class StartOutsideMap(PlannerError):
    """The robot is outside the planning costmap."""


class GoalOutsideMap(PlannerError):
    """The goal is outside the planning costmap (or the planner window)."""


class NoPathFound(PlannerError):
    """The potential never reached the goal, or the path could not be extracted."""


class PlannerTimeout(PlannerError):
    """The propagation used its whole cycle budget before reaching the goal."""


class ControllerError(FleetsimError):
    """Base of local planner failures (no valid trajectory, empty plan)."""


def pose_text(x: float, y: float, yaw: float | None = None) -> str:
    """``(x, y)`` or ``(x, y, yaw)`` formatted for messages, in metres and radians."""
    if yaw is None:
        return f"({x:.3f}, {y:.3f})"
    return f"({x:.3f}, {y:.3f}, yaw {yaw:.3f})"
