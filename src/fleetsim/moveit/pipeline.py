"""The planning pipeline: a MotionPlanRequest in, a timed RobotTrajectory out.

Per group it keeps the kinematics and collision scene; a request's goal (joint constraints, or
a position constraint solved by IK) is checked, planned with OMPL and timed with toppra within
the joint limits times the request's scaling factors (MoveIt's FixStartStateBounds and
AddTimeParameterization adapters included). Failures carry MoveItErrorCodes values.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from fleetsim.errors import PlanningError
from fleetsim.moveit.collision import CollisionScene
from fleetsim.moveit.kinematics import Kinematics
from fleetsim.moveit.planner import ALIASES, PlanFailure, plan_path
from fleetsim.moveit.robot_model import RobotModel
from fleetsim.moveit.timing import time_parameterize
from fleetsim.msgs import moveit_msgs, trajectory_msgs
from fleetsim.msgs.builtin_interfaces import Duration

E = moveit_msgs.MoveItErrorCodes
START_STATE_MAX_BOUNDS_ERROR = 0.1  # rad: FixStartStateBounds pulls this much back inside
IK_ATTEMPTS = 20


@dataclass
class PlanResult:
    """A planned, timed trajectory and what it took.

    Attributes
    ----------
    trajectory : moveit_msgs RobotTrajectory.
    planning_time : s (wall), the whole request: goal IK, path planning, time parameterisation
        (MoveIt's ``planning_time`` also counts its request adapters).
    planner : the OMPL planner that found the path, or "" when the straight joint-space
        motion was free and none ran.
    path_time : s (wall) spent on the path alone (the OMPL solve, or the straight-line check).
    requested : the planner the request asked for (its planner_id, else the group's default).
    """

    trajectory: object
    planning_time: float
    planner: str
    path_time: float
    requested: str


class GroupContext:
    """What planning needs for one group: joints, limits, kinematics, collision scene."""

    def __init__(self, model: RobotModel, group: str) -> None:
        self.group = group
        self.joints = model.active_joints(group)
        self.limits = model.limits(group)
        self.kin = Kinematics(model.robot, self.joints, self.limits.lower, self.limits.upper)
        self.scene = CollisionScene(self.kin, model.links(group), model.srdf.disabled_collisions)
        self.tip = model.end_effector_link(group)


class PlanningPipeline:
    def __init__(self, model: RobotModel, rng: np.random.Generator, default_planner: dict) -> None:
        self.model = model
        self.rng = rng
        self.default_planner = default_planner  # group -> default_planner_config
        self.groups: dict[str, GroupContext] = {}
        self.objects: dict[str, list] = {}  # planning-scene objects: id -> geoms

    def context(self, group: str) -> GroupContext:
        try:
            self.model.check_group(group)
        except PlanningError as e:
            raise PlanFailure(E.INVALID_GROUP_NAME, str(e)) from None
        if not self.model.active_joints(group):
            raise PlanFailure(E.INVALID_GROUP_NAME, f"group '{group}' has no joints to plan for")
        if group not in self.groups:
            ctx = GroupContext(self.model, group)
            for oid, geoms in self.objects.items():
                ctx.scene.add_object(oid, geoms)
            self.groups[group] = ctx
        return self.groups[group]

    def set_object(self, oid: str, geoms: list) -> None:
        """Add or replace a collision object in every group's scene."""
        self.objects[oid] = geoms
        for ctx in self.groups.values():
            ctx.scene.add_object(oid, geoms)

    def remove_object(self, oid: str) -> None:
        self.objects.pop(oid, None)
        for ctx in self.groups.values():
            if oid in ctx.scene.objects:
                ctx.scene.remove_object(oid)

    def contexts(self):
        return self.groups.values()

    # ------------------------------------------------------------------ goals
    def goal_from_constraints(self, ctx: GroupContext, c, start: np.ndarray) -> np.ndarray:
        if c.joint_constraints:
            q = start.copy()
            for jc in c.joint_constraints:
                if jc.joint_name not in ctx.joints:
                    raise PlanFailure(
                        E.INVALID_GOAL_CONSTRAINTS,
                        f"joint '{jc.joint_name}' is not in group '{ctx.group}' "
                        f"({', '.join(ctx.joints)})",
                    )
                q[ctx.joints.index(jc.joint_name)] = jc.position
            try:
                self.model.check_within_bounds(ctx.group, q, "goal")
            except PlanningError as e:
                raise PlanFailure(E.INVALID_GOAL_CONSTRAINTS, str(e)) from None
            return q
        if c.position_constraints or c.orientation_constraints:
            return self._pose_goal(ctx, c, start)
        raise PlanFailure(
            E.INVALID_GOAL_CONSTRAINTS, "the goal has no joint, position or orientation constraint"
        )

    @staticmethod
    def _already_met(ctx: GroupContext, c, start: np.ndarray, goal: np.ndarray) -> bool:
        """Whether ``start`` satisfies the goal constraints ``c``: every joint within its
        constraint's tolerances, or for a pose goal the IK's first seed, the start itself,
        already within the goal's tolerance (the IK returns it unchanged)."""
        if not c.joint_constraints:
            return bool(np.array_equal(goal, start))
        for jc in c.joint_constraints:
            d = start[ctx.joints.index(jc.joint_name)] - jc.position
            if not -abs(jc.tolerance_below) - 1e-12 <= d <= abs(jc.tolerance_above) + 1e-12:
                return False
        return True

    def _pose_goal(self, ctx: GroupContext, c, start: np.ndarray) -> np.ndarray:
        """Joint values for a position constraint, with an orientation constraint on the same
        link if one is given (MoveIt's pose goal), through IK."""
        if not c.position_constraints:
            raise PlanFailure(
                E.INVALID_GOAL_CONSTRAINTS,
                "an orientation constraint without a position constraint: fleetsim's IK needs "
                "the link's position too (set_pose_target gives both)",
            )
        pc = c.position_constraints[0]
        link = pc.link_name or ctx.tip
        region = pc.constraint_region
        if not region.primitive_poses:
            raise PlanFailure(E.INVALID_GOAL_CONSTRAINTS, "position constraint has no region")
        p = region.primitive_poses[0].position
        target = np.array([p.x, p.y, p.z])
        tol = region.primitives[0].dimensions[0] if region.primitives else 1e-3
        quat, angle_tol = None, 1e-3
        if c.orientation_constraints:
            oc = c.orientation_constraints[0]
            if (oc.link_name or ctx.tip) != link:
                raise PlanFailure(
                    E.INVALID_GOAL_CONSTRAINTS,
                    f"the orientation constraint is on '{oc.link_name}', the position constraint "
                    f"on '{link}': a pose goal constrains one link",
                )
            o = oc.orientation
            quat = np.array([o.x, o.y, o.z, o.w])
            if not np.linalg.norm(quat) > 0:
                raise PlanFailure(
                    E.INVALID_GOAL_CONSTRAINTS, "the orientation constraint's quaternion is zero"
                )
            tols = [
                t
                for t in (
                    oc.absolute_x_axis_tolerance,
                    oc.absolute_y_axis_tolerance,
                    oc.absolute_z_axis_tolerance,
                )
                if t > 0
            ]
            angle_tol = max(min(tols), 1e-4) if tols else 1e-3
        try:
            q = self.ik(
                ctx, link, target, start, tolerance=max(float(tol), 1e-4),
                orientation=quat, angle_tolerance=angle_tol,
            )  # fmt: skip
        except PlanningError as e:
            raise PlanFailure(E.INVALID_LINK_NAME, str(e)) from None
        if q is not None:
            return q
        where = f"({target[0]:.3f}, {target[1]:.3f}, {target[2]:.3f})"
        # move_group gives the goal in the root link's frame, whatever frame it came in
        frame = f"{self.model.robot.root_link()}'s frame"
        if quat is None:
            raise PlanFailure(
                E.NO_IK_SOLUTION,
                f"no collision-free IK solution puts '{link}' at {where} in {frame}",
            )
        if self.ik(ctx, link, target, start, tolerance=max(float(tol), 1e-4)) is None:
            # not the orientation: the position itself is out of reach (or only in collision)
            raise PlanFailure(
                E.NO_IK_SOLUTION,
                f"no collision-free IK solution puts '{link}' at {where} in {frame}, "
                "whatever its orientation: the position is out of the arm's reach or in "
                "collision",
            )
        q_txt = ", ".join(f"{v:.3f}" for v in quat / np.linalg.norm(quat))
        few = (
            f"; group '{ctx.group}' has {len(ctx.joints)} joints, fewer than the 6 an arbitrary "
            "orientation needs: give a position target (set_position_target) or an orientation "
            "the arm can make"
            if len(ctx.joints) < 6
            else ""
        )
        raise PlanFailure(
            E.NO_IK_SOLUTION,
            f"no collision-free IK solution puts '{link}' at {where} turned to "
            f"(x y z w) ({q_txt}) in {frame}{few}",
        )

    def ik(
        self, ctx: GroupContext, link: str, target, start, tolerance=1e-3,
        orientation=None, angle_tolerance=1e-3,
    ):  # fmt: skip
        seeds = [start] + [
            self.rng.uniform(ctx.limits.lower, ctx.limits.upper) for _ in range(IK_ATTEMPTS)
        ]
        return ctx.kin.pose_ik(
            link, target, orientation, seeds, tolerance, angle_tolerance, valid=ctx.scene.is_valid
        )

    # ------------------------------------------------------------------ planning
    def plan(self, req, start: np.ndarray) -> PlanResult:
        """The timed trajectory for a MotionPlanRequest from ``start`` (J,)."""
        t0 = time.perf_counter()
        ctx = self.context(req.group_name)
        lim = ctx.limits
        over = np.maximum(lim.lower - start, start - lim.upper)
        if np.any(over > START_STATE_MAX_BOUNDS_ERROR):
            j = ctx.joints[int(np.argmax(over))]
            raise PlanFailure(E.START_STATE_INVALID, f"start state: joint '{j}' out of bounds")
        start = np.clip(start, lim.lower, lim.upper)
        if not req.goal_constraints:
            raise PlanFailure(E.INVALID_GOAL_CONSTRAINTS, "the request has no goal constraints")
        goal = self.goal_from_constraints(ctx, req.goal_constraints[0], start)
        if self._already_met(ctx, req.goal_constraints[0], start, goal):
            # move_group: "Goal constraints are already satisfied. No need to plan or execute
            # any motions": the trajectory is the start alone, at rest (a plan's caller finds
            # a point in it; timing a zero-length path fails in toppra)
            return PlanResult(
                self.timed_trajectory(ctx, start[None, :], 1.0, 1.0),
                time.perf_counter() - t0, "", 0.0, "",
            )  # fmt: skip
        vs = _scaling(req.max_velocity_scaling_factor)
        acs = _scaling(req.max_acceleration_scaling_factor)
        planner = req.planner_id or self.default_planner.get(ctx.group) or "RRTConnect"
        planner = planner.split("kConfigDefault")[0] or "RRTConnect"
        timeout = req.allowed_planning_time if req.allowed_planning_time > 0 else 5.0
        seed = int(self.rng.integers(1, 2**31 - 1))
        p = plan_path(
            start,
            goal,
            lim.lower,
            lim.upper,
            ctx.scene.is_valid,
            planner,
            timeout,
            max(1, req.num_planning_attempts),
            seed,
        )
        path = p.path
        if np.abs(path[-1] - goal).max() > 1e-6:
            path = np.vstack([path, goal])
        return PlanResult(
            self.timed_trajectory(ctx, path, vs, acs),
            time.perf_counter() - t0,
            p.planner,
            p.planning_time,
            ALIASES.get(planner, planner),
        )

    def timed_trajectory(self, ctx: GroupContext, path: np.ndarray, vs: float, acs: float):
        """A RobotTrajectory through ``path`` (N, J) within the group's limits x scaling."""
        lim = ctx.limits
        t, pos, vel, acc = time_parameterize(path, lim.max_velocity, lim.max_acceleration, vs, acs)
        traj = moveit_msgs.RobotTrajectory()
        jt = traj.joint_trajectory
        jt.joint_names = list(ctx.joints)
        jt.points = [
            trajectory_msgs.JointTrajectoryPoint(
                positions=pos[k], velocities=vel[k], accelerations=acc[k],
                time_from_start=Duration.from_sec(float(t[k])),
            )
            for k in range(len(t))
        ]  # fmt: skip
        return traj


def _scaling(v: float) -> float:
    """Scaling outside (0, 1] falls back to 1.0, as MoveIt's time parameterisation does."""
    return v if 0 < v <= 1 and math.isfinite(v) else 1.0
