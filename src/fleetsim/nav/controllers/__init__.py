"""Local planners (base_local_planner's TrajectoryPlannerROS: trajectory rollout and DWA)."""

from fleetsim.nav.controllers.base import (
    EmptyPlan,
    LocalPlanner,
    NoValidTrajectory,
    VelocityCommand,
)
from fleetsim.nav.controllers.trajectory_params import TrajectoryPlannerParams
from fleetsim.nav.controllers.trajectory_planner import TrajectoryPlanner

__all__ = [
    "EmptyPlan",
    "LocalPlanner",
    "NoValidTrajectory",
    "TrajectoryPlanner",
    "TrajectoryPlannerParams",
    "VelocityCommand",
]
