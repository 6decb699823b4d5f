"""The global planner plugin base class (nav_core::BaseGlobalPlanner / nav2_core GlobalPlanner).

A planner is configured with the global costmap it plans on and answers
``create_plan(start, goal) -> Path`` or raises one of the typed failures in
`fleetsim.nav.errors` (StartOutsideMap, GoalOutsideMap, StartOccupied, GoalOccupied,
NoPathFound, PlannerTimeout).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.nav.errors import (
    GoalOccupied,
    GoalOutsideMap,
    NoPathFound,
    PlannerError,
    PlannerTimeout,
    StartOccupied,
    StartOutsideMap,
)

__all__ = [
    "GlobalPlanner",
    "GoalOccupied",
    "GoalOutsideMap",
    "NoPathFound",
    "Path",
    "PlannerError",
    "PlannerTimeout",
    "StartOccupied",
    "StartOutsideMap",
]


@dataclass(frozen=True)
class Path:
    """A planned path: poses (N, 3) x, y (m), yaw (rad) in ``frame_id``, start first."""

    poses: np.ndarray
    frame_id: str = "map"

    def __len__(self) -> int:
        return int(self.poses.shape[0])

    @property
    def length(self) -> float:
        """Path length along its poses, m."""
        d = np.diff(self.poses[:, :2], axis=0)
        return float(np.hypot(d[:, 0], d[:, 1]).sum())


class GlobalPlanner(ABC):
    """Base of global planners: holds the costmap; subclasses implement `create_plan`."""

    def __init__(self, costmap: Costmap2D, frame_id: str = "map") -> None:
        self.costmap = costmap
        self.frame_id = frame_id

    def set_costmap(self, costmap: Costmap2D) -> None:
        """Plan on another grid from now on (the global costmap after a resize)."""
        self.costmap = costmap

    @abstractmethod
    def create_plan(self, start: tuple[float, ...], goal: tuple[float, ...]) -> Path:
        """A path from ``start`` (x, y, yaw) to ``goal`` (x, y, yaw), both in ``frame_id``."""
