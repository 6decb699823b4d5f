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

import mujoco
import numpy as np

from fleetsim.description.srdf import parse_srdf
from fleetsim.description.urdf import parse_urdf
from fleetsim.errors import FleetsimError, PlanningError
from fleetsim.moveit.execution import ExecutionManager
from fleetsim.moveit.kinematics_services import compute_cartesian_path, compute_fk, compute_ik
from fleetsim.moveit.pipeline import PlanFailure, PlanningPipeline
from fleetsim.moveit.robot_model import RobotModel
from fleetsim.msgs import (
    geometry_msgs,
    moveit_msgs,
    sensor_msgs,
    shape_msgs,
    std_msgs,
    trajectory_msgs,
)
from fleetsim.runtime import Node, param
from fleetsim.tf.quaternions import quaternion_multiply
from fleetsim.tf.transforms import transform_points

E = moveit_msgs.MoveItErrorCodes
FAKE = "moveit_fake_controller_manager/MoveItFakeControllerManager"
_NO_TURN = np.array([0.0, 0.0, 0.0, 1.0])  # x y z w


def _standing(traj) -> bool:
    """A trajectory with nothing to move: no point, or one at its start time (a goal the start
    already met)."""
    points = traj.joint_trajectory.points
    return len(points) <= 1 and all(p.time_from_start.to_sec() == 0.0 for p in points)


SHAPES = {
    shape_msgs.SolidPrimitive.BOX: mujoco.mjtGeom.mjGEOM_BOX,
    shape_msgs.SolidPrimitive.SPHERE: mujoco.mjtGeom.mjGEOM_SPHERE,
    shape_msgs.SolidPrimitive.CYLINDER: mujoco.mjtGeom.mjGEOM_CYLINDER,
}


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


class MoveGroup(Node):
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

    # ------------------------------------------------------------------ frames
    @property
    def root_frame(self) -> str:
        """The robot's root link, tf-prefixed: the frame the kinematics work in."""
        return self.frame(self.model.robot.root_link())

    @property
    def planning_frame(self) -> str:
        """MoveIt's planning frame: a virtual joint's parent frame (``odom`` for a planar
        one), else the robot's root link; a target or object without a frame is in it."""
        vj = self.model.srdf.virtual_joints
        return self.frame(vj[0].parent_frame) if vj else self.root_frame

    def _same_as_root(self, frame: str) -> str:
        """The root link's frame for a *fixed* virtual joint's parent frame (``world`` in
        the Setup Assistant's configs): MoveIt's model holds that transform, identity, and no
        one publishes it on tf; a planar or floating one's parent is looked up through tf."""
        vj = self.model.srdf.virtual_joints
        if vj and vj[0].type == "fixed" and frame == self.frame(vj[0].parent_frame):
            return self.root_frame
        return frame

    def frame_transform(self, target: str, source: str):
        """``(t (3,), q (4,) x y z w)`` of frame ``source`` in ``target`` through tf (either
        empty: the planning frame); None when they are the same frame. A frame tf does not
        know fails with MoveIt's FRAME_TRANSFORM_FAILURE."""
        target = self._same_as_root(target.lstrip("/") or self.planning_frame)
        source = self._same_as_root(source.lstrip("/") or self.planning_frame)
        if target == source:
            return None
        try:
            tf = self.tf_buffer.lookup_transform(target, source, 0.0).transform
        except FleetsimError as e:
            raise PlanFailure(
                E.FRAME_TRANSFORM_FAILURE,
                f"Unable to transform from frame '{source}' to frame '{target}': {e}",
            ) from None
        t, q = tf.translation, tf.rotation
        return np.array([t.x, t.y, t.z]), np.array([q.x, q.y, q.z, q.w])

    def pose_in_root(self, frame: str, position, orientation=None):
        """A pose given in ``frame`` (x y z, and x y z w or None) in the root link's frame."""
        tf = self.frame_transform(self.root_frame, frame)
        if tf is None:
            return np.asarray(position, float), orientation
        pos = transform_points(*tf, [position])[0]
        if orientation is not None:
            orientation = quaternion_multiply(tf[1], orientation)
        return pos, orientation

    def _goal_in_root(self, c):
        """A copy of goal constraints ``c`` with its position and orientation constraints in
        the root link's frame (the pose goal's frame: its header's, else the planning frame)."""
        if not (c.position_constraints or c.orientation_constraints):
            return c
        c = copy.deepcopy(c)
        for pc in c.position_constraints:
            for pose in pc.constraint_region.primitive_poses:
                p = pose.position
                pos, _ = self.pose_in_root(pc.header.frame_id, [p.x, p.y, p.z])
                pose.position = geometry_msgs.Point(*map(float, pos))
            pc.header.frame_id = self.root_frame
        for oc in c.orientation_constraints:
            o = oc.orientation
            tf = self.frame_transform(self.root_frame, oc.header.frame_id)
            if tf is not None:
                q = quaternion_multiply(tf[1], [o.x, o.y, o.z, o.w])
                oc.orientation = geometry_msgs.Quaternion(*map(float, q))
            oc.header.frame_id = self.root_frame
        return c

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
        if server.is_active():  # planned only, or its execution already over
            r = server.type.Result()
            r.error_code.val = E.PREEMPTED
            server.set_preempted(
                r,
                "This goal was canceled because another goal was received by the simple "
                "action server",
            )
        return server.accept_new_goal(), server.current

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

    # ------------------------------------------------------------------ planning scene
    def _on_scene(self, msg) -> None:
        self._apply(msg)

    def _apply(self, scene) -> bool:
        for obj in scene.world.collision_objects:
            if obj.operation == moveit_msgs.CollisionObject.REMOVE:
                ids = [obj.id] if obj.id else list(self.objects)
                for oid in ids:
                    self.objects.pop(oid, None)
                    self.pipeline.remove_object(oid)
                continue
            geoms, poses = [], []
            try:
                placed = self.frame_transform(self.root_frame, obj.header.frame_id)
            except PlanFailure as e:  # MoveIt: "Unknown frame", and the object is not added
                self.get_logger().error("collision object '%s': %s", obj.id, e)
                return False
            for prim, pose in zip(obj.primitives, obj.primitive_poses, strict=False):
                if prim.type not in SHAPES:
                    self.get_logger().error(
                        "collision object '%s': unsupported shape %d", obj.id, prim.type
                    )
                    return False
                d = np.asarray(prim.dimensions, float)
                size = {
                    mujoco.mjtGeom.mjGEOM_BOX: d[:3] / 2 if len(d) >= 3 else None,
                    mujoco.mjtGeom.mjGEOM_SPHERE: np.array([d[0], 0, 0]) if len(d) >= 1 else None,
                    mujoco.mjtGeom.mjGEOM_CYLINDER: np.array([d[1], d[0] / 2, 0])
                    if len(d) >= 2
                    else None,
                }[SHAPES[prim.type]]
                if size is None:
                    self.get_logger().error("collision object '%s': too few dimensions", obj.id)
                    return False
                pos = np.array([pose.position.x, pose.position.y, pose.position.z])
                o = pose.orientation
                q = np.array([o.x, o.y, o.z, o.w]) if (o.w or o.x or o.y or o.z) else _NO_TURN
                if placed is not None:  # from the object's frame into the root link's
                    pos = transform_points(*placed, [pos])[0]
                    q = quaternion_multiply(placed[1], q)
                geoms.append((int(SHAPES[prim.type]), size, pos, np.array([q[3], *q[:3]])))
                poses.append(
                    geometry_msgs.Pose(
                        position=geometry_msgs.Point(*map(float, pos)),
                        orientation=geometry_msgs.Quaternion(*map(float, q)),
                    )
                )
            # kept as placed, in the root link's frame (get_planning_scene answers with it;
            # an object given in odom would otherwise come back in odom, as of when it came)
            stored = copy.deepcopy(obj)
            stored.header.frame_id, stored.primitive_poses = self.root_frame, poses
            self.objects[obj.id] = stored
            self.pipeline.set_object(obj.id, geoms)
        return True

    def _srv_get_scene(self, req):
        scene = moveit_msgs.PlanningScene(name="(noname)", robot_model_name=self.model.srdf.name)
        scene.robot_state.joint_state.name = list(self.joint_positions)
        scene.robot_state.joint_state.position = np.array(list(self.joint_positions.values()))
        scene.world.collision_objects = list(self.objects.values())
        return moveit_msgs.GetPlanningSceneResponse(scene=scene)

    def _srv_apply(self, req):
        return moveit_msgs.ApplyPlanningSceneResponse(success=self._apply(req.scene))
