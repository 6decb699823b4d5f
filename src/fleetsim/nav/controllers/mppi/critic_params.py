"""Each MPPI critic's parameters (``MPPIController/<Critic>/``), Nav2's names and defaults."""

from __future__ import annotations

import math
from dataclasses import dataclass

from fleetsim.runtime import param


def _weight(default: float):
    return param(default, range=(0.0, None), help="weight of the critic's term")


def _power():
    return param(1, range=(1, None), help="power applied to the term")


def _threshold(default: float, meaning: str):
    return param(default, unit="m", range=(0.0, None), help=meaning)


@dataclass(frozen=True)
class ConstraintCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(4.0)
    cost_power: int = _power()


@dataclass(frozen=True)
class GoalCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(5.0)
    cost_power: int = _power()
    threshold_to_consider: float = _threshold(1.4, "robot-goal distance below which it scores")


@dataclass(frozen=True)
class GoalAngleCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(3.0)
    cost_power: int = _power()
    threshold_to_consider: float = _threshold(0.5, "robot-goal distance below which it scores")


@dataclass(frozen=True)
class CostCriticParams:
    enabled: bool = param(True, help="score with this critic")
    consider_footprint: bool = param(False, help="footprint cost (else the centre cell's)")
    cost_weight: float = _weight(3.81)
    cost_power: int = _power()
    critical_cost: float = param(300.0, range=(0.0, None), help="added per pose near collision")
    near_collision_cost: int = param(253, range=(0, 254), help="cost from which critical_cost")
    collision_cost: float = param(1000000.0, range=(0.0, None), help="cost of a collision")
    near_goal_distance: float = _threshold(0.5, "no preferential term this near the goal")
    inflation_layer_name: str = param("", help="inflation layer read (the last if empty)")
    trajectory_point_step: int = param(2, range=(1, None), help="points skipped between checks")


@dataclass(frozen=True)
class ObstaclesCriticParams:
    enabled: bool = param(True, help="score with this critic")
    consider_footprint: bool = param(False, help="footprint cost (else the centre cell's)")
    critical_weight: float = param(20.0, range=(0.0, None), help="weight within the margin")
    repulsion_weight: float = param(1.5, range=(0.0, None), help="weight within inflation")
    cost_power: int = _power()
    collision_cost: float = param(10000.0, range=(0.0, None), help="cost of a collision")
    collision_margin_distance: float = param(
        0.10, unit="m", range=(0.0, None), help="clearance below which the critical term applies"
    )
    near_goal_distance: float = _threshold(0.5, "no repulsion this near the goal")
    inflation_radius: float = param(0.55, unit="m", range=(0.0, None), help="as the costmap's")
    cost_scaling_factor: float = param(10.0, range=(1e-9, None), help="as the costmap's")
    inflation_layer_name: str = param("", help="inflation layer read (the last if empty)")


@dataclass(frozen=True)
class PathAlignCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(10.0)
    cost_power: int = _power()
    threshold_to_consider: float = _threshold(0.5, "robot-goal distance below which it stops")
    offset_from_furthest: int = param(20, range=(0, None), help="path points reached before use")
    trajectory_point_step: int = param(4, range=(1, None), help="points skipped between checks")
    max_path_occupancy_ratio: float = param(
        0.07, range=(0.0, 1.0), help="blocked fraction of the path above which it stops"
    )
    use_path_orientations: bool = param(False, help="also penalise yaw off the path's")


@dataclass(frozen=True)
class PathFollowCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(5.0)
    cost_power: int = _power()
    offset_from_furthest: int = param(6, range=(0, None), help="target path points ahead")
    threshold_to_consider: float = _threshold(1.4, "robot-goal distance below which it stops")


@dataclass(frozen=True)
class PathAngleCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(2.2)
    cost_power: int = _power()
    offset_from_furthest: int = param(4, range=(0, None), help="target path points ahead")
    threshold_to_consider: float = _threshold(0.5, "robot-goal distance below which it stops")
    max_angle_to_furthest: float = param(
        math.pi / 4, unit="rad", range=(0.0, None), help="heading error from which it scores"
    )
    forward_preference: bool = param(True, help="the robot has a forward direction")


@dataclass(frozen=True)
class PreferForwardCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(5.0)
    cost_power: int = _power()
    threshold_to_consider: float = _threshold(0.5, "robot-goal distance below which it stops")


@dataclass(frozen=True)
class TwirlingCriticParams:
    enabled: bool = param(True, help="score with this critic")
    cost_weight: float = _weight(10.0)
    cost_power: int = _power()
