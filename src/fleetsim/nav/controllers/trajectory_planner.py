"""base_local_planner's TrajectoryPlannerROS: trajectory rollout and DWA.

Each cycle (``compute_velocity_commands``):

1. the global plan is cut to the local costmap (points from the first within half the map's
   size of the robot, while they stay within it) and, with ``prune_plan``, points more than
   1 m behind the robot are dropped;
2. within ``xy_goal_tolerance`` of the goal the robot stops (within its acceleration limits)
   and then rotates in place to the goal yaw;
3. otherwise the path and goal distance maps are computed and every velocity sample is rolled
   out and scored in one batch (`rollout.trajectory_costs`):
   ``pdist_scale * path_dist + gdist_scale * goal_dist + occdist_scale * occ_cost``
   (distances in cells, or metres with ``meter_scoring``), plus, with ``alignment_scale``
   (a fleetsim addition, off by default), ``alignment_scale * path_dist`` of the point
   ``forward_point_distance`` ahead of the rollout's end: dwa_local_planner's alignment cost;
4. the best is chosen as TrajectoryPlanner::createTrajectories does: forward samples
   (``vx_samples`` x ``vtheta_samples``), holonomic strafes, rotations in place towards open
   space (with oscillation flags), sideways moves, and finally backing up at ``escape_vel``
   (on a curve that turns the robot towards its way when one is legal, a departure from
   ROS; see `selection`).

Rollout velocities: ``[vx - acc_lim_x * T, vx + acc_lim_x * T]`` within ``[min_vel_x,
max_vel_x]`` (likewise theta), with T = ``sim_time``, or the control period when ``dwa``.
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np
from numba import njit

from fleetsim.nav.controllers.base import (
    EmptyPlan,
    LocalPlanner,
    NoValidTrajectory,
    VelocityCommand,
)
from fleetsim.nav.controllers.map_grid import distances_from_targets, plan_cells_in_map
from fleetsim.nav.controllers.rollout import (
    footprint_cost_bounds_near,
    num_steps_of,
    reach_offsets,
    trajectory_costs,
)
from fleetsim.nav.controllers.selection import choose_trajectory
from fleetsim.nav.controllers.trajectory_params import TrajectoryPlannerParams
from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_at, outline_points, polygon_cells
from fleetsim.runtime import load_params


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def _sign(v: float) -> float:
    return 1.0 if v > 0 else (-1.0 if v < 0 else 0.0)


def circling_hint(p: TrajectoryPlannerParams) -> str:
    """A warning when no forward rollout can end near the goal, else "".

    The slowest forward rollout covers ``min_vel_x * sim_time``. Closer to the goal than half
    of that, every forward rollout ends farther from it than the robot already is, so rotating
    in place scores best; when ``xy_goal_tolerance`` is smaller than that band the robot turns
    on the spot short of its goal and never arrives (ROS's base_local_planner does the same).
    """
    reach = p.min_vel_x * p.sim_time
    if reach / 2 <= p.xy_goal_tolerance:
        return ""
    return (
        f"min_vel_x {p.min_vel_x:g} m/s over sim_time {p.sim_time:g} s rolls out "
        f"{reach:.2f} m, more than twice xy_goal_tolerance {p.xy_goal_tolerance:g} m: near the "
        f"goal every forward rollout overshoots it, so the robot may turn in place about "
        f"{reach / 2:.2f} m short of its goal and never arrive; set xy_goal_tolerance >= "
        f"{reach / 2:.2f} or lower min_vel_x or sim_time"
    )


class TrajectoryPlanner(LocalPlanner):
    """Trajectory rollout / DWA local planner on a local costmap.

    costmap : the local costmap's master grid (read each cycle, may roll).
    footprint : (K, 2) padded robot polygon, m (the costmap's ``footprint``).
    """

    Params = TrajectoryPlannerParams

    def __init__(
        self,
        costmap: Costmap2D,
        footprint: np.ndarray,
        params: TrajectoryPlannerParams | None = None,
    ) -> None:
        self.costmap = costmap
        self.params = p = params or TrajectoryPlannerParams()
        self.footprint = np.asarray(footprint, dtype=np.float64)
        self.outline = outline_points(self.footprint, costmap.resolution)
        self.reach = reach_offsets(self.outline, costmap.resolution)
        self.sim_period = 1.0 / p.controller_frequency
        self.angular_sim_granularity = p.angular_sim_granularity or p.sim_granularity
        scale = costmap.resolution if p.meter_scoring else 1.0
        self.scales = np.array([p.pdist_scale, p.gdist_scale, p.occdist_scale]) * scale
        self.plan = np.zeros((0, 3))
        self.local_plan = np.zeros((0, 3))  # the chosen trajectory's poses
        self.reached_goal = False
        self.xy_tolerance_latch = False
        self.rotating_to_goal = False
        self._reset_oscillation_flags()
        self.escaping = False
        self.prev = (0.0, 0.0)
        self.escape_pose = (0.0, 0.0, 0.0)
        #: (x, y) where a robot facing away from its plan began backing along it, or None
        #: (selection's `_toward_the_plan`, with alignment)
        self.backing_from: tuple[float, float] | None = None
        #: (x, y) where such backing found no legal back-up, or None
        self.backing_blocked_at: tuple[float, float] | None = None
        self._sample_layout: tuple | None = None  # see selection.velocity_samples
        #: a `GlobalCostmapGuard` (move_base sets it with ``global_costmap_check``), or None
        self.global_guard = None

    @classmethod
    def from_namespace(
        cls,
        costmap: Costmap2D,
        footprint: np.ndarray,
        ns: dict[str, Any] | None,
        where: str = "TrajectoryPlannerROS",
    ) -> TrajectoryPlanner:
        params = load_params(TrajectoryPlannerParams, ns, where)
        hint = circling_hint(params)
        if hint:
            logging.getLogger("fleetsim.nav").warning("%s: %s", where, hint)
        if params.back_along_plan and params.alignment_scale <= 0.0:
            logging.getLogger("fleetsim.nav").warning(
                "%s: back_along_plan is true but alignment_scale is 0: it has no effect (it "
                "judges the robot's heading by the path's direction, which the alignment cost "
                "defines); set alignment_scale > 0 (e.g. 0.6, as the hunter's file)",
                where,
            )
        return cls(costmap, footprint, params)

    def _reset_oscillation_flags(self) -> None:
        self.rotating_left = self.rotating_right = False
        self.strafe_left = self.strafe_right = False
        self.stuck_left = self.stuck_right = False
        self.stuck_left_strafe = self.stuck_right_strafe = False

    # -- the plugin interface ------------------------------------------------------------------
    def set_plan(self, plan: Any) -> None:
        poses = np.asarray(getattr(plan, "poses", plan), dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] not in (2, 3):
            raise EmptyPlan(f"set_plan: a plan must be (N, 3) x, y, yaw poses, got {poses.shape}")
        if poses.shape[1] == 2:
            poses = np.concatenate([poses, np.zeros((poses.shape[0], 1))], axis=1)
        # plain floats: np.allclose costs ~20 us, and move_base hands the plan over on every
        # control cycle when the local costmap's frame is not the plan's
        same_goal = (
            self.plan.shape[0] > 0
            and poses.shape[0] > 0
            and all(abs(d) <= 1e-6 for d in (self.plan[-1] - poses[-1]).tolist())
        )
        self.plan = poses
        if not same_goal:
            # ROS resets these on every setPlan; with move_base replanning at
            # planner_frequency, a new plan can arrive before every control cycle and the
            # reached flag would never survive to move_base's check. A replan to the same
            # goal keeps them.
            self.reached_goal = False
            self.xy_tolerance_latch = False
            self.backing_from = self.backing_blocked_at = None

    def is_goal_reached(self) -> bool:
        return self.reached_goal

    def compute_velocity_commands(self, pose, velocity) -> VelocityCommand:
        p = self.params
        x, y, yaw = (float(v) for v in pose)
        vel = tuple(float(v) for v in velocity)
        if self.plan.shape[0] == 0:
            raise EmptyPlan("TrajectoryPlannerROS: no plan; call set_plan first")
        local = self._plan_in_window(x, y)
        if p.prune_plan:
            local = self._pruned(local, x, y)
        if local.shape[0] == 0:
            raise EmptyPlan(
                f"TrajectoryPlannerROS: the plan does not pass within the local costmap around "
                f"({x:.2f}, {y:.2f})"
            )
        gx, gy, gyaw = self.plan[-1]
        if self.xy_tolerance_latch or math.hypot(gx - x, gy - y) <= p.xy_goal_tolerance:
            if p.latch_xy_goal_tolerance:
                self.xy_tolerance_latch = True
            if abs(_wrap(gyaw - yaw)) <= p.yaw_goal_tolerance:
                self.rotating_to_goal = False
                self.xy_tolerance_latch = False
                self.reached_goal = True
                return VelocityCommand()
            self._update_maps(local, (x, y, yaw), vel)
            stopped = abs(vel[2]) <= 1e-2 and abs(vel[0]) <= 1e-2 and abs(vel[1]) <= 1e-2
            if not self.rotating_to_goal and not stopped:
                return self._stop_with_acc_limits((x, y, yaw), vel)
            self.rotating_to_goal = True
            return self._rotate_to_goal((x, y, yaw), vel, gyaw)
        self._update_maps(local, (x, y, yaw), vel)
        best, cost = self._find_best((x, y, yaw), vel)
        if cost < 0:
            self.local_plan = np.zeros((0, 3))
            why = "the footprint collides or leaves the local map on every sample"
            if self.global_guard is not None and self.global_guard.refused:
                why += f"; {self.global_guard.refused}"
            raise NoValidTrajectory(
                f"TrajectoryPlannerROS: no valid trajectory from ({x:.2f}, {y:.2f}, yaw "
                f"{yaw:.2f}): {why}"
            )
        return VelocityCommand(*best)

    # -- plan handling --------------------------------------------------------------------------
    def _plan_in_window(self, x: float, y: float) -> np.ndarray:
        m = self.costmap
        thr = max(m.size_x * m.resolution / 2.0, m.size_y * m.resolution / 2.0) ** 2
        i, j = _window_of(self.plan, x, y, thr)
        return self.plan[i:j]

    def _pruned(self, local: np.ndarray, x: float, y: float) -> np.ndarray:
        """Drop points until the first within 1 m of the robot (base_local_planner prunePlan)."""
        k, cut = _prune_of(local, self.plan, x, y)
        if k < 0:
            return local
        self.plan = self.plan[cut:]
        return local[k:]

    def _update_maps(
        self, local: np.ndarray, pose: tuple[float, float, float], vel=(0.0, 0.0, 0.0)
    ) -> None:
        m = self.costmap
        no_cells = np.zeros(m.costs.shape, dtype=bool)
        polygon = footprint_at(self.footprint, *pose)
        passable = no_cells
        if self._obstacle_near(polygon):  # else the cells under the robot change nothing
            passable = np.zeros(m.costs.shape, dtype=bool)
            rows, cols = polygon_cells(m, polygon)
            passable[rows, cols] = True
        targets = plan_cells_in_map(m, local[:, :2])
        self.plan_cells = targets
        self.path_dist = distances_from_targets(m.costs, targets, passable)
        goal = targets[-1:] if targets.shape[0] else targets
        self.goal_dist = distances_from_targets(m.costs, goal, no_cells)
        self.final_goal = self.plan[-1, :2].copy()
        # rollouts reach at most the top speed times sim_time from the robot (+ a cell or two)
        p = self.params
        top = max(abs(p.max_vel_x), abs(p.min_vel_x), abs(p.escape_vel), math.hypot(vel[0], vel[1]))
        if p.holonomic_robot and p.y_vels:
            top = max(top, max(abs(float(v)) for v in p.y_vels))
        radius = math.ceil(top * p.sim_time / m.resolution) + 2
        cx = math.floor((pose[0] - m.origin_x) / m.resolution)
        cy = math.floor((pose[1] - m.origin_y) / m.resolution)
        self.cost_bounds = footprint_cost_bounds_near(m.costs, self.reach, cx, cy, radius)

    def _obstacle_near(self, polygon: np.ndarray) -> bool:
        """Whether a cell the MapGrid treats as an obstacle (cost >= INSCRIBED) lies in the
        polygon's bounding box, grown by a cell (the only cells `polygon_cells` can return)."""
        m = self.costmap
        return _obstacle_in_box(
            np.ascontiguousarray(polygon, dtype=np.float64),
            m.origin_x,
            m.origin_y,
            m.resolution,
            m.costs,
        )

    # -- scoring ----------------------------------------------------------------------------------
    def _score(self, samples: np.ndarray, pose, vel) -> np.ndarray:
        p, m = self.params, self.costmap
        samples = np.ascontiguousarray(samples, dtype=np.float64)
        steps = num_steps_of(
            samples, p.sim_time, p.sim_granularity, self.angular_sim_granularity, p.heading_scoring
        )
        self._poses = np.empty((samples.shape[0], int(steps.max()), 3))
        self._steps = steps
        self._samples = samples
        return trajectory_costs(
            samples,
            np.asarray(pose, dtype=np.float64),
            np.asarray(vel, dtype=np.float64),
            np.array([p.acc_lim_x, p.acc_lim_y, p.acc_lim_theta]),
            p.sim_time,
            steps,
            m.costs,
            np.array(m.origin),
            m.resolution,
            self.outline,
            self.path_dist,
            self.goal_dist,
            self.scales,
            np.array([1.0 if p.heading_scoring else 0.0, p.heading_scoring_timestep]),
            self.plan_cells,
            p.simple_attractor,
            self.final_goal,
            self._poses,
            self.cost_bounds,
            self._alignment(pose),
        )

    def _alignment(self, pose) -> np.ndarray:
        """(weight per cell, forward distance m) of the alignment cost for this cycle.

        Off within ``forward_point_distance`` of the goal, as in dwa_local_planner (near the
        goal the point ahead passes it and every heading would be penalised)."""
        p = self.params
        weight = p.alignment_scale * (self.costmap.resolution if p.meter_scoring else 1.0)
        if weight > 0.0 and self.plan.shape[0]:
            gx, gy = self.plan[-1, 0], self.plan[-1, 1]
            if math.hypot(gx - pose[0], gy - pose[1]) <= p.forward_point_distance:
                weight = 0.0
        return np.array([weight, p.forward_point_distance])

    def check_trajectory(self, pose, vel, sample) -> bool:
        """Whether one command's rollout is legal (TrajectoryPlanner::checkTrajectory)."""
        return bool(self._score(np.array([sample]), pose, vel)[0] >= 0)

    def _stop_with_acc_limits(self, pose, vel) -> VelocityCommand:
        p, dt = self.params, self.sim_period
        cmd = (
            _sign(vel[0]) * max(0.0, abs(vel[0]) - p.acc_lim_x * dt),
            _sign(vel[1]) * max(0.0, abs(vel[1]) - p.acc_lim_y * dt),
            _sign(vel[2]) * max(0.0, abs(vel[2]) - p.acc_lim_theta * dt),
        )
        if self.check_trajectory(pose, vel, cmd):
            return VelocityCommand(*cmd)
        raise NoValidTrajectory("TrajectoryPlannerROS: cannot stop without a collision")

    def _rotate_to_goal(self, pose, vel, goal_yaw: float) -> VelocityCommand:
        p = self.params
        ang = _wrap(goal_yaw - pose[2])
        lo, hi, mn = p.min_vel_theta, p.max_vel_theta, p.min_in_place_vel_theta

        def clamp(v: float) -> float:
            return min(hi, max(mn, v)) if v > 0.0 else max(lo, min(-mn, v))

        v = clamp(ang)
        max_acc = abs(vel[2]) + p.acc_lim_theta * self.sim_period
        min_acc = abs(vel[2]) - p.acc_lim_theta * self.sim_period
        v = _sign(v) * min(max(abs(v), min_acc), max_acc)
        v = _sign(v) * min(math.sqrt(2 * p.acc_lim_theta * abs(ang)), abs(v))
        v = clamp(v)
        if self.check_trajectory(pose, vel, (0.0, 0.0, v)):
            return VelocityCommand(0.0, 0.0, v)
        raise NoValidTrajectory("TrajectoryPlannerROS: cannot rotate to the goal yaw in place")

    def _find_best(self, pose, vel) -> tuple[tuple[float, float, float], float]:
        if self.global_guard is not None:
            self.global_guard.begin_cycle()
        (vx, vy, vth), cost, index = choose_trajectory(self, pose, vel)
        self.local_plan = self._poses[index, : max(int(self._steps[index]), 0)].copy()
        if cost < 0:
            self.local_plan = np.zeros((0, 3))
        return (vx, vy, vth), cost


@njit(cache=True)
def _obstacle_in_box(polygon, ox, oy, res, costs):
    """`TrajectoryPlanner._obstacle_near`'s test, compiled (it runs every control cycle)."""
    h, w = costs.shape
    x0 = y0 = 1 << 62
    x1 = y1 = -(1 << 62)
    for i in range(polygon.shape[0]):
        cx = math.floor((polygon[i, 0] - ox) / res)
        cy = math.floor((polygon[i, 1] - oy) / res)
        x0, x1 = min(x0, cx), max(x1, cx)
        y0, y1 = min(y0, cy), max(y1, cy)
    x0, x1 = max(x0 - 1, 0), min(x1 + 2, w)
    y0, y1 = max(y0 - 1, 0), min(y1 + 2, h)
    for y in range(y0, y1):
        for x in range(x0, x1):
            if costs[y, x] >= 253:
                return True
    return False


@njit(cache=True)
def _window_of(plan, x, y, thr):
    """`TrajectoryPlanner._plan_in_window`'s bounds, compiled (every control cycle of every
    robot; the NumPy version's whole-plan temporaries cost ~25 us): the plan's slice
    ``[i, j)`` from its first point within ``sqrt(thr)`` m of (x, y) while points stay so;
    ``(0, 0)`` when none is."""
    n = plan.shape[0]
    i = 0
    while i < n and not (plan[i, 0] - x) ** 2 + (plan[i, 1] - y) ** 2 <= thr:
        i += 1
    if i == n:
        return 0, 0
    j = i
    while j < n and (plan[j, 0] - x) ** 2 + (plan[j, 1] - y) ** 2 <= thr:
        j += 1
    return i, j


@njit(cache=True)
def _prune_of(local, plan, x, y):
    """`TrajectoryPlanner._pruned`'s indices, compiled: the first point ``k`` of ``local``
    within 1 m of (x, y) (-1: none) and the first point of ``plan`` nearest to it (where the
    pruned plan starts)."""
    k = -1
    for i in range(local.shape[0]):
        if (local[i, 0] - x) ** 2 + (local[i, 1] - y) ** 2 < 1.0:
            k = i
            break
    if k < 0:
        return -1, 0
    px, py = local[k, 0], local[k, 1]
    best, cut = np.inf, 0
    for i in range(plan.shape[0]):
        d = (plan[i, 0] - px) ** 2 + (plan[i, 1] - py) ** 2
        if d < best:
            best, cut = d, i
    return k, cut
