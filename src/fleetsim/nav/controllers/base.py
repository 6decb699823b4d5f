"""The local planner plugin base class (nav_core::BaseLocalPlanner / nav2_core Controller).

A local planner is given the global plan with `set_plan`, then asked each control cycle for
``compute_velocity_commands(pose, velocity) -> VelocityCommand`` until `is_goal_reached`.
It raises `NoValidTrajectory` (a ControllerError) when it cannot move: move_base counts
those against ``controller_patience``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import NamedTuple

import numpy as np

from fleetsim.nav.errors import ControllerError


class VelocityCommand(NamedTuple):
    """A base velocity (geometry_msgs/Twist's linear.x, linear.y, angular.z): m/s, rad/s."""

    vx: float = 0.0
    vy: float = 0.0
    vtheta: float = 0.0


class NoValidTrajectory(ControllerError):
    """Every simulated trajectory collided, left the local map or lost the path."""


class EmptyPlan(ControllerError):
    """compute_velocity_commands was called without a plan (or the plan left the local map)."""


class LocalPlanner(ABC):
    """Base of local planners."""

    @abstractmethod
    def set_plan(self, plan: np.ndarray) -> None:
        """Take a new global plan: (N, 3) x, y, yaw (or (N, 2)) in the costmap's frame."""

    @abstractmethod
    def compute_velocity_commands(
        self, pose: tuple[float, float, float], velocity: tuple[float, float, float]
    ) -> VelocityCommand:
        """The command for this cycle, from the robot's pose and measured velocity."""

    @abstractmethod
    def is_goal_reached(self) -> bool:
        """Whether the robot is at the plan's end within the goal tolerances."""
