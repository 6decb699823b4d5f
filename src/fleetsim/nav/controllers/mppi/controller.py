"""``nav2_mppi_controller::MPPIController`` as a move_base local planner.

Model Predictive Path Integral control (Williams et al.), as Nav2's controller does it. Each
control cycle (``compute_velocity_commands``):

1. goal check (Nav2's SimpleGoalChecker): within ``xy_goal_tolerance`` (latched when
   ``stateful``) and ``yaw_goal_tolerance`` of the plan's last pose the goal is reached and
   the robot stops; otherwise MPPI steers, the goal critics turning it to the goal yaw;
2. the plan is pruned to ``prune_distance`` m beyond its point nearest the robot, and its
   points on inscribed or lethal cells marked blocked;
3. ``iteration_count`` times: ``batch_size`` control sequences of ``time_steps`` steps are
   sampled around the current one (Gaussian noise, ``vx_std``/``vy_std``/``wz_std``, drawn
   once and kept unless ``regenerate_noises``), clamped to the velocity limits, made
   followable within the acceleration limits and integrated by the motion model every
   ``model_dt`` s (`kernels.rollouts`); with ``primitive_samples`` (a fleetsim addition,
   `primitives`) the batch's last rows are stand-still, straight, turn and turn-then-drive
   sequences instead; every critic scores the whole batch; the sequence becomes the samples'
   softmax average (``temperature``, with the control cost ``gamma``);
4. the command is the sequence's first control; the sequence is shifted by one control
   period (warm start) for the next cycle.

When every sample collides the optimiser is reset and tried again (``retry_attempt_limit``
times) before `NoValidTrajectory`. Randomness comes only from the generator handed in (the
runtime's, named for the plugin), so a seeded run gives the same commands.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fleetsim.nav.controllers.base import (
    EmptyPlan,
    LocalPlanner,
    NoValidTrajectory,
    VelocityCommand,
)
from fleetsim.nav.controllers.mppi.critic_kernels import COLLISION, strict_pose_cost
from fleetsim.nav.controllers.mppi.critics import Critic, CriticData
from fleetsim.nav.controllers.mppi.kernels import (
    MODEL_CODES,
    OMNI,
    integrated_poses,
    rollouts,
    shifted_sequence,
    softmax_sequence,
)
from fleetsim.nav.controllers.mppi.loading import load_mppi
from fleetsim.nav.controllers.mppi.params import AckermannConstraints, MPPIParams
from fleetsim.nav.controllers.mppi.path import blocked_points, furthest_reached, pruned_path
from fleetsim.nav.controllers.mppi.primitives import primitive_sequences, set_primitive_rows
from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE, Costmap2D
from fleetsim.nav.costmap.footprint import footprint_radii, outline_points
from fleetsim.nav.costmap.inflation_layer import squared_distances_to

PLUGIN = "nav2_mppi_controller::MPPIController"
#: m: a plan whose every point moved less than this is the last one re-expressed (a map->odom
#: correction), not a new plan
SAME_PLAN_SHIFT = 0.5


class MPPIController(LocalPlanner):
    """MPPI local planner on a local costmap (see the module doc).

    costmap : the local costmap's master grid. footprint : (K, 2) robot polygon, m.
    critics : the scoring critics, in order. rng : the generator all noise is drawn from.
    """

    Params = MPPIParams

    def __init__(
        self,
        costmap: Costmap2D,
        footprint: np.ndarray,
        params: MPPIParams,
        critics: list[Critic],
        rng: np.random.Generator,
        ackermann: AckermannConstraints | None = None,
    ) -> None:
        self.costmap = costmap
        self.params = p = params
        self.critics = critics
        self.rng = rng
        self.ackermann = ackermann or AckermannConstraints()
        self.footprint = np.asarray(footprint, dtype=np.float64)
        self.outline = outline_points(self.footprint, costmap.resolution)
        self.inscribed_radius, circumscribed = footprint_radii(self.footprint)
        # clearance (cells^2) beyond which no outline point reaches a lethal cell and below
        # which one is inside the footprint; a cell's diagonal of slack either way
        slack = math.sqrt(2.0)
        res = costmap.resolution
        self.outside2 = (circumscribed / res + slack) ** 2
        self.inside2 = max(self.inscribed_radius / res - slack, 0.0) ** 2
        self.uses_footprint = any(getattr(c.params, "consider_footprint", False) for c in critics)
        self.model = MODEL_CODES[p.motion_model]
        self.std = np.array([p.vx_std, p.vy_std if self.model == OMNI else 0.0, p.wz_std])
        self.limits = np.array(
            [p.vx_min, p.vx_max, p.vy_max, p.wz_max, p.ax_min, p.ax_max, p.ay_max, p.az_max, 1.0]
        )
        self.shift = max(1, round(1.0 / (p.controller_frequency * p.model_dt)))
        shape = (p.batch_size, p.time_steps, 3)
        self.controls = np.empty(shape)
        self.vels = np.empty(shape)
        self.poses = np.empty(shape)
        self.headings = np.empty((p.batch_size, p.time_steps, 2))
        self.primitives = (
            primitive_sequences(p.time_steps, p.model_dt, p.vx_max, p.wz_max)
            if p.primitive_samples
            else np.zeros((0, p.time_steps, 3))
        )
        self.plan = np.zeros((0, 3))
        self.local_plan = np.zeros((0, 3))
        self.reached_goal = False
        self.xy_tolerance_latch = False
        self._plan_start = 0
        self.clearance2 = np.full((1, 1), -1, dtype=np.int64)
        self.escape2 = -1.0
        self.reset()

    @classmethod
    def from_namespace(
        cls, node: Any, costmap_ros: Any, ns: dict | None, where: str = "MPPIController"
    ) -> MPPIController:
        params, ackermann, critics = load_mppi(ns, where)
        rng = node.runtime.rng(where)
        return cls(costmap_ros.costmap, costmap_ros.footprint, params, critics, rng, ackermann)

    def reset(self) -> None:
        """Zero control sequence, fresh noise (Nav2's optimizer reset)."""
        p = self.params
        self.sequence = np.zeros((p.time_steps, 3))
        self.noise = self._draw_noise()

    def _draw_noise(self) -> np.ndarray:
        p = self.params
        noise = np.zeros((p.batch_size, p.time_steps, 3))
        for a in range(3):
            if self.std[a] > 0.0:
                noise[:, :, a] = self.rng.normal(0.0, self.std[a], (p.batch_size, p.time_steps))
        return noise

    # -- the plugin interface ------------------------------------------------------------------
    def set_plan(self, plan: Any) -> None:
        poses = np.asarray(getattr(plan, "poses", plan), dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] not in (2, 3) or poses.shape[0] == 0:
            raise EmptyPlan(f"set_plan: a plan must be (N, 3) x, y, yaw poses, got {poses.shape}")
        if poses.shape[1] == 2:
            poses = np.concatenate([poses, np.zeros((poses.shape[0], 1))], axis=1)
        # move_base hands the same plan over again each cycle when the local costmap's frame
        # is not the global one (re-expressed in odom): Nav2 keeps its plan pruned up to the
        # robot, so the nearest-point search starts where it ended; starting it over at the
        # plan's first point would only search max_robot_pose_search_dist m of a long plan and
        # pin the robot there. A plan from the planner (another shape, or moved) starts at 0.
        again = poses.shape == self.plan.shape and bool(
            np.max(np.abs(poses[:, :2] - self.plan[:, :2]), initial=0.0) <= SAME_PLAN_SHIFT
        )
        same_goal = again or (
            self.plan.shape[0] > 0 and np.allclose(self.plan[-1], poses[-1], rtol=0.0, atol=1e-6)
        )
        self.plan = np.ascontiguousarray(poses)
        if not again:
            self._plan_start = 0
        if not same_goal:
            self.reached_goal = False
            self.xy_tolerance_latch = False
            self.reset()

    def is_goal_reached(self) -> bool:
        return self.reached_goal

    def compute_velocity_commands(self, pose, velocity) -> VelocityCommand:
        p = self.params
        if self.plan.shape[0] == 0:
            raise EmptyPlan("MPPIController: no plan; call set_plan first")
        robot = np.array([float(v) for v in pose])
        gx, gy, gyaw = self.plan[-1]
        if (
            self.xy_tolerance_latch
            or math.hypot(gx - robot[0], gy - robot[1]) <= p.xy_goal_tolerance
        ):
            self.xy_tolerance_latch = p.stateful
            if abs(math.remainder(gyaw - robot[2], 2 * math.pi)) <= p.yaw_goal_tolerance:
                self.reached_goal = True
                self.xy_tolerance_latch = False
                self.local_plan = np.zeros((0, 3))
                return VelocityCommand()
        m = self.costmap
        search = p.max_robot_pose_search_dist
        if search is None:
            search = max(m.size_x, m.size_y) * m.resolution / 2.0
        path, self._plan_start = pruned_path(
            self.plan, robot[0], robot[1], self._plan_start, search, p.prune_distance
        )
        blocked = blocked_points(m.costs, m.origin_x, m.origin_y, m.resolution, path)
        self.clearance2 = squared_distances_to(m.costs == LETHAL_OBSTACLE)
        self.escape2 = self._escape_clearance(robot)
        vel = np.array([float(v) for v in velocity])
        for _attempt in range(p.retry_attempt_limit + 1):
            data = self._optimize(robot, vel, path, blocked)
            if not data.fail:
                break
            self.reset()
        else:
            self.local_plan = np.zeros((0, 3))
            raise NoValidTrajectory(
                f"MPPIController: every one of {p.batch_size} sampled trajectories collides from "
                f"({robot[0]:.2f}, {robot[1]:.2f}, yaw {robot[2]:.2f}), after "
                f"{p.retry_attempt_limit} reset(s) (retry_attempt_limit)"
            )
        cmd = self.sequence[0].copy()
        self.local_plan = integrated_poses(self._followed(vel), robot, p.model_dt)
        self.sequence = shifted_sequence(self.sequence, self.shift)
        return VelocityCommand(float(cmd[0]), float(cmd[1]), float(cmd[2]))

    # -- optimisation ---------------------------------------------------------------------------
    def _escape_clearance(self, robot: np.ndarray) -> float:
        """The robot's clearance2 when its own pose counts as a collision by the footprint or
        inscribed rule (then samples may leave it without getting nearer to an obstacle; see
        `critic_kernels.pose_cost`), else -1."""
        m = self.costmap
        if self.clearance2.shape != m.costs.shape:
            # not computed for this costmap yet (the kernel below does not check bounds: a
            # stale grid would be read past its end)
            self.clearance2 = squared_distances_to(m.costs == LETHAL_OBSTACLE)
        use_fp = self.uses_footprint
        c, s = math.cos(robot[2]), math.sin(robot[2])
        args = (m.costs, self.clearance2, m.origin_x, m.origin_y, m.resolution, self.outline)
        here = strict_pose_cost(*args, use_fp, self.inside2, self.outside2, *robot[:2], c, s)
        cell = m.world_to_map(robot[0], robot[1])
        if here != COLLISION or cell is None:
            return -1.0
        return float(max(self.clearance2[cell[1], cell[0]], 0))

    def _optimize(self, robot, vel, path, blocked) -> CriticData:
        p = self.params
        for _ in range(p.iteration_count):
            if p.regenerate_noises:
                self.noise = self._draw_noise()
            if self.primitives.shape[0]:
                set_primitive_rows(self.noise, self.sequence, self.primitives)
            data = self._evaluate(self.sequence, self.noise, robot, vel, path, blocked)
            if data.fail:
                return data
            softmax_sequence(
                data.costs, self.controls, self.sequence, self.std, p.gamma, p.temperature
            )
            self._clamp_sequence()
        return data

    def _evaluate(self, sequence, noise, robot, vel, path, blocked) -> CriticData:
        """Roll the samples out and score them (the critics' costs in ``data.costs``)."""
        p = self.params
        rollouts(
            sequence, noise, robot, vel, self.limits, self.model, p.model_dt,
            self.ackermann.min_turning_r, self.controls, self.vels, self.poses, self.headings,
        )  # fmt: skip
        data = CriticData(
            poses=self.poses, headings=self.headings, vels=self.vels, robot=robot,
            goal=self.plan[-1], path=path,
            blocked=blocked, furthest=int(furthest_reached(self.poses, path)), dt=p.model_dt,
            limits=(p.vx_min, p.vx_max, p.vy_max, p.wz_max), model=self.model,
            min_turning_r=self.ackermann.min_turning_r, costmap=self.costmap,
            outline=self.outline, clearance2=self.clearance2, inside2=self.inside2,
            outside2=self.outside2, escape2=self.escape2,
            inscribed_radius=self.inscribed_radius, costs=np.zeros(p.batch_size),
        )  # fmt: skip
        for critic in self.critics:
            critic.score(data)
        return data

    def _clamp_sequence(self) -> None:
        p, s = self.params, self.sequence
        np.clip(s[:, 0], p.vx_min, p.vx_max, out=s[:, 0])
        if self.model == OMNI:
            np.clip(s[:, 1], -p.vy_max, p.vy_max, out=s[:, 1])
        else:
            s[:, 1] = 0.0
        np.clip(s[:, 2], -p.wz_max, p.wz_max, out=s[:, 2])
        r = self.ackermann.min_turning_r
        if self.model == MODEL_CODES["Ackermann"] and r > 0.0:
            bound = np.abs(s[:, 0]) / r
            np.clip(s[:, 2], -bound, bound, out=s[:, 2])

    def _followed(self, vel: np.ndarray) -> np.ndarray:
        """The optimal sequence's state velocities (the robot's first, then the controls)."""
        out = np.empty_like(self.sequence)
        out[0] = vel
        out[1:] = self.sequence[:-1]
        if self.model != OMNI:
            out[:, 1] = 0.0
        return out
