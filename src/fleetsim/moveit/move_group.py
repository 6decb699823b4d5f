"""``moveit_ros_move_group/move_group``: planning and execution for one robot's arm groups.

Reads ``robot_description``, ``robot_description_semantic``, ``robot_description_planning``
(joint_limits.yaml) and ``robot_description_kinematics`` from its namespace; from its private
namespace ``controller_list`` (or ``moveit_controller_manager`` =
``moveit_fake_controller_manager/MoveItFakeControllerManager`` for fake execution),
``<group>/default_planner_config`` (ompl_planning.yaml), ``allow_trajectory_execution`` and
``trajectory_execution/*``. Serves MoveIt's interfaces in its namespace: actions ``move_group``
and ``execute_trajectory``; services ``plan_kinematic_path``, ``get_planning_scene``,
``apply_planning_scene``, and ``compute_ik``, ``compute_fk``, ``compute_cartesian_path``
(``kinematics_services``); topics ``joint_states`` (in), ``planning_scene`` (in),
``trajectory_execution_event`` (in, "stop"), ``~display_planned_path`` (out). World geometry
and other robots come from the simulator when one runs; planning-scene objects are added with
``apply_planning_scene`` or ``planning_scene``.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from functools import partial

import numpy as np

from fleetsim.description.srdf import parse_srdf
from fleetsim.description.urdf import parse_urdf
from fleetsim.errors import FleetsimError, PlanningError
from fleetsim.moveit.execution import ExecutionManager
from fleetsim.moveit.frames import PlanningFrames
from fleetsim.moveit.kinematics_services import compute_cartesian_path, compute_fk, compute_ik
from fleetsim.moveit.pipeline import PlanFailure, PlanningPipeline
from fleetsim.moveit.planning_scene import PlanningSceneKeeper
from fleetsim.moveit.robot_model import RobotModel
from fleetsim.msgs import (
    moveit_msgs,
    sensor_msgs,
    std_msgs,
    trajectory_msgs,
)
from fleetsim.runtime import Node, param

E = moveit_msgs.MoveItErrorCodes
FAKE = "moveit_fake_controller_manager/MoveItFakeControllerManager"


def _standing(traj) -> bool:
    """A trajectory with nothing to move: no point, or one at its start time (a goal the start
    already met)."""
    points = traj.joint_trajectory.points
    return len(points) <= 1 and all(p.time_from_start.to_sec() == 0.0 for p in points)


@dataclass(frozen=True)
class MoveGroupParams:
    allow_trajectory_execution: bool = param(True, help="execute plans (else plan only)")
    moveit_controller_manager: str = param(
        "moveit_simple_controller_manager/MoveItSimpleControllerManager",
        help="or moveit_fake_controller_manager/MoveItFakeControllerManager",
    )
    controller_list: list = param([], help="[{name, action_ns, type, joints, default}]")
    initial: list = param(
        [], help="fake execution: [{group, pose}], the named poses the fake controllers start at"
    )
    trajectory_execution: dict = param({}, help="allowed_execution_duration_scaling, ...")
    max_safe_path_cost: float = param(1.0, help="accepted, unused")
    jiggle_fraction: float = param(0.05, help="accepted, unused")
    planning_plugin: str = param("ompl_interface/OMPLPlanner", help="only OMPL")
    request_adapters: str = param("", help="accepted; fleetsim always fixes bounds and times")
    start_state_max_bounds_error: float = param(0.1, unit="rad", help="FixStartStateBounds")
    publish_monitored_planning_scene: bool = param(True, help="accepted")
    capabilities: str = param("", help="accepted")


class MoveGroup(PlanningFrames, PlanningSceneKeeper, Node):
    Params = MoveGroupParams
    PARAM_NAMESPACES = ("planner_configs", "ompl", "sensors", "planning_pipelines")

    def __init__(self, runtime, name: str = "move_group", namespace: str = "/", **kw) -> None:
        super().__init__(runtime, name, namespace, **kw)
        urdf = self._text("robot_description")
        robot = parse_urdf(urdf, source=self.resolve_name("robot_description"))
        srdf = parse_srdf(
            self._text("robot_description_semantic"),
            self.resolve_name("robot_description_semantic"),
            robot,
        )
        planning = self.get_param("robot_description_planning", {}) or {}
        self.model = RobotModel(
            robot, srdf, planning, self.resolve_name("robot_description_semantic")
        )
        defaults = {}
        for g in self.model.group_names:
            v = self.get_param(f"~{g}/default_planner_config", None)
            if v:
                defaults[g] = str(v)
        self.pipeline = PlanningPipeline(self.model, self.rng, defaults)
        p = self.params
        fake = p.moveit_controller_manager == FAKE
        self.execution = ExecutionManager(self, p.controller_list, fake, p.trajectory_execution)
        if fake:
            self._fake_initial(p.initial)
        self.joint_positions: dict[str, float] = {}
        self.objects: dict[str, moveit_msgs.CollisionObject] = {}
        _ = self.tf_buffer  # listen to /tf from now on: targets in other frames go through it
        self.create_subscription(sensor_msgs.JointState, "joint_states", self._on_joints, 50)
        self.create_subscription(moveit_msgs.PlanningScene, "planning_scene", self._on_scene, 10)
        self.create_subscription(std_msgs.String, "trajectory_execution_event", self._on_event, 10)
        self.display_pub = self.create_publisher(
            moveit_msgs.DisplayTrajectory, "~display_planned_path"
        )
        self.move_action = self.create_action_server(
            moveit_msgs.MoveGroup, "move_group", goal_callback=self._on_move_goal,
            preempt_callback=lambda: self._preempt(self.move_action),
        )  # fmt: skip
        self.exec_action = self.create_action_server(
            moveit_msgs.ExecuteTrajectory, "execute_trajectory", goal_callback=self._on_exec_goal,
            preempt_callback=lambda: self._preempt(self.exec_action),
        )  # fmt: skip
        self.create_service(moveit_msgs.GetMotionPlan, "plan_kinematic_path", self._srv_plan)
        self.create_service(moveit_msgs.GetPositionIK, "compute_ik", partial(compute_ik, self))
        self.create_service(moveit_msgs.GetPositionFK, "compute_fk", partial(compute_fk, self))
        self.create_service(
            moveit_msgs.GetCartesianPath,
            "compute_cartesian_path",
            partial(compute_cartesian_path, self),
        )
        self.create_service(moveit_msgs.GetPlanningScene, "get_planning_scene", self._srv_get_scene)
        self.create_service(moveit_msgs.ApplyPlanningScene, "apply_planning_scene", self._srv_apply)
        self.get_logger().info("You can start planning now!")

    def _fake_initial(self, initial: list) -> None:
        """moveit_fake_controller_manager's ``initial`` (fake_controllers.yaml): each group
        starts at its named pose (else at zeros); a wrong group or pose is an error."""
        held: dict[str, float] = {}
        for k, entry in enumerate(initial):
            where = f"{self.full_name}/initial[{k}]"
            if not isinstance(entry, dict) or not {"group", "pose"} <= set(entry):
                raise PlanningError(f"{where}: expected {{group: ..., pose: ...}}, got {entry!r}")
            try:
                q = self.model.named_target(str(entry["group"]), str(entry["pose"]))
            except PlanningError as e:
                raise PlanningError(f"{where}: {e}") from None
            held.update(zip(self.model.active_joints(str(entry["group"])), map(float, q)))
        if held:
            self.execution.hold(list(held), list(held.values()))

    def _load_params(self):
        """Its parameters, without the keys MoveIt's launch files put beside them: each
        group's ompl settings (``<group>/default_planner_config``) and ros_controllers.yaml's
        controller and hardware entries (loaded whole for its ``controller_list``)."""
        values = self.runtime.params.get(self.full_name, {})
        extra = {
            k
            for k, v in (values.items() if isinstance(values, dict) else [])
            if isinstance(v, dict)
            and (
                "type" in v
                or "default_planner_config" in v
                or k in ("moveit_sim_hw_interface", "generic_hw_control_loop", "hardware_interface")
            )
        }
        self.PARAM_NAMESPACES = (*type(self).PARAM_NAMESPACES, *extra)
        return super()._load_params()

    def _text(self, key: str) -> str:
        value = self.get_param(key, None)
        if not isinstance(value, str) or not value.strip():
            raise PlanningError(
                f"{self.full_name}: parameter '{self.resolve_name(key)}' is not set; load the "
                "robot's URDF/SRDF (planning_context.launch) before move_group"
            )
        return value

    # ------------------------------------------------------------------ state
    def _on_joints(self, msg) -> None:
        for n, q in zip(msg.name, msg.position, strict=False):
            self.joint_positions[n] = float(q)

    def current(self, group: str) -> np.ndarray:
        joints = self.model.active_joints(group)
        missing = [j for j in joints if j not in self.joint_positions]
        if missing and not self.execution.fake:
            raise PlanFailure(
                E.ROBOT_STATE_STALE,
                f"Didn't receive robot state (joint angles) for {', '.join(missing)} on "
                f"{self.resolve_name('joint_states')}",
            )
        return np.array([self.joint_positions.get(j, 0.0) for j in joints])

    def start_state(self, req) -> np.ndarray:
        q = self.current(req.group_name)
        js = req.start_state.joint_state
        if len(js.name) and not req.start_state.is_diff:
            joints = self.model.active_joints(req.group_name)
            for n, v in zip(js.name, js.position, strict=False):
                if n in joints:
                    q[joints.index(n)] = v
        return q

    def physics_paused(self) -> bool:
        """Whether a simulator in this process has its physics paused (a trajectory then never
        moves, and its execution times out)."""
        from fleetsim.sim.node import Simulator

        return any(
            isinstance(n, Simulator) and n.engine.paused for n in self.runtime.graph.nodes.values()
        )

    def sync_world(self) -> None:
        """Copy the simulator's world near this robot into each group's collision scene."""
        from fleetsim.sim.node import Simulator

        sim = next((n for n in self.runtime.graph.nodes.values() if isinstance(n, Simulator)), None)
        if sim is None:
            return
        entry = next(
            (
                e
                for e in sim.engine.models.values()
                if e.kind == "robot" and e.namespace == self.namespace
            ),
            None,
        )
        if entry is None:
            return
        for ctx in self.pipeline.contexts():
            ctx.scene.set_world_from(sim.engine, entry.name)

    # ------------------------------------------------------------------ planning
    def plan(self, req):
        """MotionPlanResponse for a MotionPlanRequest (never raises for a bad request)."""
        res = moveit_msgs.MotionPlanResponse(group_name=req.group_name)
        try:
            ctx = self.pipeline.context(req.group_name)
            start = self.start_state(req)
            self.sync_world()
            if req.goal_constraints:
                req = copy.copy(req)
                req.goal_constraints = [self._goal_in_root(c) for c in req.goal_constraints]
            plan = self.pipeline.plan(req, start)
        except PlanFailure as e:
            self.get_logger().error("%s", e)
            res.error_code.val = e.code
            return res, str(e)
        except FleetsimError as e:
            self.get_logger().error("%s", e)
            res.error_code.val = E.FAILURE
            return res, str(e)
        res.trajectory_start.joint_state.name = list(ctx.joints)
        res.trajectory_start.joint_state.position = start
        res.trajectory, res.planning_time = plan.trajectory, plan.planning_time
        res.error_code.val = E.SUCCESS
        if _standing(plan.trajectory):
            self.get_logger().info(
                "%s: goal constraints are already satisfied; no need to plan or execute any "
                "motions", req.group_name,
            )  # fmt: skip
        elif plan.planner:
            self.get_logger().info(
                "%s: geometric::%s found a path in %.1f ms (%.1f ms with goal and timing)",
                req.group_name, plan.planner, 1e3 * plan.path_time, 1e3 * plan.planning_time,
            )  # fmt: skip
        else:
            self.get_logger().info(
                "%s: the straight joint-space motion is collision-free, so geometric::%s was "
                "not run (%.1f ms with goal and timing)",
                req.group_name, plan.requested, 1e3 * plan.planning_time,
            )  # fmt: skip
        self.display_pub.publish(
            moveit_msgs.DisplayTrajectory(
                trajectory=[plan.trajectory], trajectory_start=res.trajectory_start
            )
        )
        return res, ""

    def _srv_plan(self, req):
        res, _ = self.plan(req.motion_plan_request)
        return moveit_msgs.GetMotionPlanResponse(motion_plan_response=res)

    # ------------------------------------------------------------------ actions
    def _accept(self, server):
        """Accept ``server``'s pending goal, as the simple action server does, ending the one
        it replaces PREEMPTED with MoveIt's code (its trajectory stopped first); returns the
        goal message and its server-side handle, to which the goal's `_finisher` is bound."""
        if server.is_active():
            self.execution.stop("preempted by a new goal", E.PREEMPTED)
        preempted = server.type.Result()  # for a goal still active: its execution was over
        preempted.error_code.val = E.PREEMPTED
        return server.accept_new_goal(preempted), server.current

    def _finisher(self, server, handle, result):
        """``done(code, why)`` for the trajectory of goal ``handle``: ends that goal with
        ``result`` (its error code set), and nothing once another goal has replaced it."""

        def done(code, why):
            if server.current is not handle or not server.is_active():
                return
            result.error_code.val = code
            if code == E.SUCCESS:
                server.set_succeeded(result, "Solution was found and executed.")
            elif code == E.PREEMPTED:
                server.set_preempted(result, why)
            else:
                server.set_aborted(result, why)

        return done

    def _on_move_goal(self) -> None:
        goal, handle = self._accept(self.move_action)
        if goal.planning_options.planning_scene_diff.is_diff:
            self._apply(goal.planning_options.planning_scene_diff)
        res, text = self.plan(goal.request)
        result = moveit_msgs.MoveGroupResult(
            error_code=res.error_code, trajectory_start=res.trajectory_start,
            planned_trajectory=res.trajectory, planning_time=res.planning_time,
        )  # fmt: skip
        if res.error_code.val != E.SUCCESS:
            self.move_action.set_aborted(
                result, text or "No motion plan found. No execution attempted."
            )
            return
        if _standing(res.trajectory):  # MoveIt's words for nothing to do
            self.move_action.set_succeeded(
                result, "Requested path and goal constraints are already met."
            )
            return
        if goal.planning_options.plan_only or not self.params.allow_trajectory_execution:
            self.move_action.set_succeeded(result, "Motion plan was computed successfully.")
            return
        finish = self._finisher(self.move_action, handle, result)

        def done(code, why):
            if code == E.SUCCESS:
                result.executed_trajectory = res.trajectory
            finish(code, why)

        self.execution.execute(res.trajectory, self.joint_positions, done)

    def _on_exec_goal(self) -> None:
        goal, handle = self._accept(self.exec_action)
        result = moveit_msgs.ExecuteTrajectoryResult()
        done = self._finisher(self.exec_action, handle, result)
        traj = getattr(goal, "trajectory", None)
        if not isinstance(getattr(traj, "joint_trajectory", None), trajectory_msgs.JointTrajectory):
            done(E.INVALID_MOTION_PLAN, f"the goal's trajectory is not a RobotTrajectory: {traj!r}")
            return
        self.execution.execute(traj, self.joint_positions, done)

    def _preempt(self, server) -> None:
        if server.next is None and server.is_active():
            self.execution.stop("preempted", E.PREEMPTED)
            if server.is_active():
                r = server.type.Result()
                r.error_code.val = E.PREEMPTED
                server.set_preempted(r, "preempted")

    def _on_event(self, msg) -> None:
        if msg.data == "stop":
            self.execution.stop("stopped by trajectory_execution_event", E.PREEMPTED)
