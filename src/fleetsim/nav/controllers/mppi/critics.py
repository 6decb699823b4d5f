"""MPPI's critics, found by their Nav2 names (``critics: [CostCritic, GoalCritic, ...]``).

Each critic adds ``(cost_weight * term) ** cost_power`` to every sample's cost, with its term
from `critic_kernels`, and only in the situations Nav2's critic scores (near or far from the
goal, path tracked far enough, ...). A collision adds ``collision_cost`` instead; when every
sample collides the cost critics raise `CriticData.fail`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from fleetsim.nav.controllers.mppi import critic_kernels as k
from fleetsim.nav.controllers.mppi import critic_params as cp
from fleetsim.nav.controllers.mppi.path import target_index


@dataclass
class CriticData:
    """What the critics read in one optimisation step (all in the costmap's frame)."""

    poses: np.ndarray  # (B, T, 3) sampled trajectories
    headings: np.ndarray  # (B, T, 2) cos, sin of their yaws
    vels: np.ndarray  # (B, T, 3) their state velocities
    robot: np.ndarray  # (3,) robot pose
    goal: np.ndarray  # (3,) the plan's last pose
    path: np.ndarray  # (N, 3) pruned local path
    blocked: np.ndarray  # (N,) bool path points in collision
    furthest: int  # path index reached furthest by any trajectory
    dt: float
    limits: tuple  # vx_min, vx_max, vy_max, wz_max
    model: int
    min_turning_r: float
    costmap: object  # Costmap2D
    outline: np.ndarray  # (M, 2) footprint outline points
    clearance2: np.ndarray  # (H, W) squared cells to the nearest lethal cell (-1: none)
    inside2: float  # clearance2 below which a lethal cell is inside the footprint
    outside2: float  # clearance2 above which no footprint reaches a lethal cell
    inscribed_radius: float
    fail: bool = False
    escape2: float = -1.0  # the robot's clearance2 when its own pose collides (else -1)
    costs: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def goal_distance(self) -> float:
        return math.hypot(self.goal[0] - self.robot[0], self.goal[1] - self.robot[1])


class Critic(ABC):
    """Base of critics: ``Params`` is the critic's parameter dataclass."""

    Params: type = object

    def __init__(self, params) -> None:
        self.params = params

    def add(self, data: CriticData, term: np.ndarray) -> None:
        p = self.params
        data.costs += (p.cost_weight * term) ** p.cost_power

    @abstractmethod
    def score(self, data: CriticData) -> None:
        """Add this critic's cost of every sampled trajectory to ``data.costs``."""


class ConstraintCritic(Critic):
    Params = cp.ConstraintCriticParams

    def score(self, data):
        vx_min, vx_max, vy_max, _ = data.limits
        term = k.constraint_terms(
            data.vels, vx_min, vx_max, vy_max, data.model, data.min_turning_r, data.dt
        )
        self.add(data, term)


def _collided(data: CriticData, hit: np.ndarray, collision_cost: float) -> None:
    data.costs[hit] += collision_cost
    if hit.all():
        data.fail = True


def _grid(data: CriticData, consider_footprint: bool):
    """The costmap arguments of `k.pose_cost` after the poses."""
    m = data.costmap
    return (
        m.costs, data.clearance2, m.origin_x, m.origin_y, m.resolution, data.outline,
        consider_footprint, data.inside2, data.outside2, data.escape2,
    )  # fmt: skip


class CostCritic(Critic):
    Params = cp.CostCriticParams

    def score(self, data):
        p = self.params
        near_goal = data.goal_distance < p.near_goal_distance
        term, hit = k.cost_terms(
            data.poses, data.headings, *_grid(data, p.consider_footprint), p.trajectory_point_step,
            float(p.near_collision_cost), p.critical_cost, near_goal,
        )  # fmt: skip
        # Nav2 normalises costs (0..254) by 254
        term = np.where(hit, 0.0, term)
        data.costs += (p.cost_weight / 254.0 * term) ** p.cost_power
        _collided(data, hit, p.collision_cost)


class ObstaclesCritic(Critic):
    Params = cp.ObstaclesCriticParams

    def score(self, data):
        p = self.params
        near_goal = data.goal_distance < p.near_goal_distance
        critical, repulsive, hit = k.obstacle_terms(
            data.poses, data.headings, *_grid(data, p.consider_footprint), data.inscribed_radius,
            p.cost_scaling_factor, p.collision_margin_distance, p.inflation_radius, near_goal,
        )  # fmt: skip
        ok = ~hit
        data.costs[ok] += (p.critical_weight * critical[ok]) ** p.cost_power + (
            p.repulsion_weight * repulsive[ok]
        ) ** p.cost_power
        _collided(data, hit, p.collision_cost)


class GoalCritic(Critic):
    Params = cp.GoalCriticParams

    def score(self, data):
        if data.goal_distance >= self.params.threshold_to_consider:
            return
        self.add(data, k.goal_terms(data.poses, data.goal[0], data.goal[1]))


class GoalAngleCritic(Critic):
    Params = cp.GoalAngleCriticParams

    def score(self, data):
        if data.goal_distance >= self.params.threshold_to_consider:
            return
        self.add(data, k.goal_angle_terms(data.poses, data.goal[2]))


class PathAlignCritic(Critic):
    Params = cp.PathAlignCriticParams

    def score(self, data):
        p = self.params
        n = data.path.shape[0]
        if data.goal_distance < p.threshold_to_consider or n < 2:
            return
        if data.furthest < p.offset_from_furthest:
            return
        if data.blocked.sum() / n > p.max_path_occupancy_ratio:
            return
        term = k.path_align_terms(
            data.poses, data.path, ~data.blocked, p.trajectory_point_step, p.use_path_orientations
        )
        self.add(data, term)


class PathFollowCritic(Critic):
    Params = cp.PathFollowCriticParams

    def score(self, data):
        p = self.params
        if data.goal_distance < p.threshold_to_consider or data.path.shape[0] < 2:
            return
        i = target_index(data.furthest, p.offset_from_furthest, data.blocked)
        self.add(data, k.path_follow_terms(data.poses, data.path[i, 0], data.path[i, 1]))


class PathAngleCritic(Critic):
    Params = cp.PathAngleCriticParams

    def score(self, data):
        p = self.params
        if data.goal_distance < p.threshold_to_consider or data.path.shape[0] < 2:
            return
        i = target_index(data.furthest, p.offset_from_furthest, data.blocked)
        tx, ty = data.path[i, 0], data.path[i, 1]
        x, y, yaw = data.robot
        off = abs(math.remainder(math.atan2(ty - y, tx - x) - yaw, 2 * math.pi))
        if not p.forward_preference:
            off = min(off, math.pi - off)
        if off < p.max_angle_to_furthest:
            return
        self.add(data, k.path_angle_terms(data.poses, tx, ty, p.forward_preference))


class PreferForwardCritic(Critic):
    Params = cp.PreferForwardCriticParams

    def score(self, data):
        if data.goal_distance < self.params.threshold_to_consider:
            return
        self.add(data, k.reverse_terms(data.vels, data.dt))


class TwirlingCritic(Critic):
    Params = cp.TwirlingCriticParams

    def score(self, data):
        self.add(data, k.twirl_terms(data.vels))


#: Nav2 critic name -> class (one line per critic, as pluginlib's plugin list)
CRITICS: dict[str, type[Critic]] = {
    "ConstraintCritic": ConstraintCritic,
    "CostCritic": CostCritic,
    "ObstaclesCritic": ObstaclesCritic,
    "GoalCritic": GoalCritic,
    "GoalAngleCritic": GoalAngleCritic,
    "PathAlignCritic": PathAlignCritic,
    "PathFollowCritic": PathFollowCritic,
    "PathAngleCritic": PathAngleCritic,
    "PreferForwardCritic": PreferForwardCritic,
    "TwirlingCritic": TwirlingCritic,
}
