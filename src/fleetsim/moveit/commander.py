"""``MoveGroupCommander`` with moveit_commander's names (``PlanningSceneInterface`` is in
``scene_interface``).

In process they talk to a ``move_group`` node through its action and services on a small node
of their own, and drive the runtime while they wait (``go()``, ``plan()``, ``execute()`` with
``wait=True``). ``runtime`` is the fleetsim ``Runtime`` the simulation lives in.
"""

from __future__ import annotations

import itertools
import math
import os
from typing import Any

import numpy as np

from fleetsim.errors import PlanningError
from fleetsim.moveit.commander_targets import CommanderTargets, MoveItCommanderException
from fleetsim.moveit.goal_constraints import joint_goal, pose_goal
from fleetsim.msgs import geometry_msgs, moveit_msgs, std_msgs, trajectory_msgs
from fleetsim.runtime import Node
from fleetsim.runtime import names as rnames
from fleetsim.tf.quaternions import (
    quaternion_multiply,
)
from fleetsim.tf.transforms import transform_points

E = moveit_msgs.MoveItErrorCodes
_ids = itertools.count(1)


class _Client:
    def __init__(self, runtime, ns: str) -> None:
        self.runtime = runtime
        self.ns = rnames.validate_namespace(ns or "/")
        self.node = Node(runtime, f"move_group_commander_{next(_ids)}", self.ns)
        self.move_group = self.runtime.graph.nodes.get(rnames.join(self.ns, "move_group"))

    def wait(self, until, timeout: float) -> None:
        if not until():
            self.runtime.run(duration=timeout, until=until)

    def call(self, name: str, srv_type, request):
        return self.runtime.graph.call_service(rnames.join(self.ns, name), srv_type, request)


class MoveGroupCommander(CommanderTargets):
    """moveit_commander.MoveGroupCommander(name, robot_description, ns, wait_for_servers)."""

    def __init__(
        self,
        name: str,
        robot_description: str = "robot_description",
        ns: str = "",
        wait_for_servers: float = 5.0,
        *,
        runtime=None,
        connect: str | None = None,
    ) -> None:
        """``runtime``: the simulation's Runtime in this process; without one, the commander
        joins a simulation in another process over the Zenoh bridge (``connect``: its locator,
        default ``$FLEETSIM_ZENOH`` or tcp/127.0.0.1:7447)."""
        if runtime is None:
            from fleetsim.moveit.remote import RemoteSession

            self._c = RemoteSession(
                connect or os.environ.get("FLEETSIM_ZENOH"), ns, wait_for_servers
            )
        else:
            self._c = _Client(runtime, ns)
        mg = self._c.move_group
        if mg is None:
            raise MoveItCommanderException(
                f"no move_group node in namespace {self._c.ns}; launch move_group.launch first"
            )
        self._mg = mg
        self._model = mg.model
        try:
            self._model.check_group(name)
        except PlanningError as e:
            raise MoveItCommanderException(f"Group '{name}' was not found. {e}") from None
        self._name = name
        self._joints = self._model.active_joints(name)
        self._target = self.get_current_joint_values_or_zero()
        self._pose_target: np.ndarray | None = None
        self._orientation_target: np.ndarray | None = None  # x y z w, with _pose_target
        self._remembered: dict[str, np.ndarray] = {}
        self._vs, self._as = self._model.default_scaling()
        self._planning_time = 5.0
        self._attempts = 1
        self._planner_id = ""
        self._joint_tol, self._pos_tol, self._orient_tol = 1e-4, 1e-4, 1e-3
        self._ref_frame = ""  # pose targets' frame; empty: the planning frame
        # set_random_target: the commander's node's stream (a run's seed makes it repeat)
        self._rng = getattr(self._c.node, "rng", None) or np.random.default_rng(0)
        self._target_frame = ""
        self._ee = self._model.end_effector_link(name)
        node = self._c.node
        self._move = node.create_action_client(moveit_msgs.MoveGroup, "move_group")
        self._exec = node.create_action_client(moveit_msgs.ExecuteTrajectory, "execute_trajectory")
        self._event = node.create_publisher(std_msgs.String, "trajectory_execution_event")
        self._timeout_margin = 30.0

    # ------------------------------------------------------------------ introspection
    def get_name(self) -> str:
        return self._name

    def get_active_joints(self) -> list[str]:
        return list(self._joints)

    def get_joints(self) -> list[str]:
        return list(self._joints)

    def get_variable_count(self) -> int:
        return len(self._joints)

    def get_planning_frame(self) -> str:
        """A virtual joint's parent frame, else the robot's root link (MoveIt's model frame)."""
        if hasattr(self._mg, "planning_frame"):  # in process: move_group's own
            return self._mg.planning_frame
        vj = self._model.srdf.virtual_joints
        return self._mg.frame(vj[0].parent_frame if vj else self._model.robot.root_link())

    def set_pose_reference_frame(self, reference_frame: str) -> None:
        """The frame of pose targets and Cartesian waypoints given without one (default: the
        planning frame); move_group transforms them through tf."""
        self._ref_frame = str(reference_frame).lstrip("/")

    def get_pose_reference_frame(self) -> str:
        return self._ref_frame or self.get_planning_frame()

    def get_end_effector_link(self) -> str:
        return self._ee

    def set_end_effector_link(self, link: str) -> None:
        self._ee = link

    def has_end_effector_link(self) -> bool:
        return bool(self._ee)

    def get_current_joint_values(self) -> list[float]:
        from fleetsim.moveit.planner import PlanFailure

        try:
            return [float(v) for v in self._mg.current(self._name)]
        except PlanFailure as e:
            raise MoveItCommanderException(str(e)) from None

    def get_current_joint_values_or_zero(self) -> np.ndarray:
        return np.array([self._mg.joint_positions.get(j, 0.0) for j in self._joints])

    def get_current_pose(self, end_effector_link: str = "") -> geometry_msgs.PoseStamped:
        link = end_effector_link or self._ee
        ctx = self._mg.pipeline.context(self._name)
        pos, quat = ctx.kin.link_pose(np.array(self.get_current_joint_values()), link)
        frame = self._mg.frame(self._model.robot.root_link())  # where the kinematics are
        planning = self.get_planning_frame()
        if planning != frame and hasattr(self._mg, "frame_transform"):  # in process: tf
            from fleetsim.moveit.planner import PlanFailure

            try:
                tf = self._mg.frame_transform(planning, frame)
            except PlanFailure as e:
                raise MoveItCommanderException(str(e)) from None
            if tf is not None:
                pos = transform_points(*tf, [pos])[0]
                quat = quaternion_multiply(tf[1], quat)
            frame = planning
        ps = geometry_msgs.PoseStamped()
        ps.header.frame_id = frame
        ps.pose.position = geometry_msgs.Point(*map(float, pos))
        ps.pose.orientation = geometry_msgs.Quaternion(*map(float, quat))
        return ps

    # ------------------------------------------------------------------ settings
    def set_start_state_to_current_state(self) -> None:
        """Plans start from the current state (the only start fleetsim's commander uses)."""

    def allow_replanning(self, value: bool) -> None:
        """Accepted: fleetsim's move_group does not replan when the scene changes."""

    def set_max_velocity_scaling_factor(self, value: float) -> None:
        self._vs = self._scaling(value, "velocity")

    def set_max_acceleration_scaling_factor(self, value: float) -> None:
        self._as = self._scaling(value, "acceleration")

    @staticmethod
    def _scaling(value: float, what: str) -> float:
        if not (0 < value <= 1) or not math.isfinite(value):
            raise MoveItCommanderException(
                f"Expected value in the range from 0 to 1 for scaling factor ({what}), got {value}"
            )
        return float(value)

    def set_planning_time(self, seconds: float) -> None:
        self._planning_time = float(seconds)

    def get_planning_time(self) -> float:
        return self._planning_time

    def set_num_planning_attempts(self, n: int) -> None:
        self._attempts = int(n)

    def set_planner_id(self, planner_id: str) -> None:
        self._planner_id = planner_id

    def get_planner_id(self) -> str:
        return self._planner_id

    def set_goal_tolerance(self, value: float) -> None:
        self._joint_tol = self._pos_tol = float(value)

    def set_goal_joint_tolerance(self, value: float) -> None:
        self._joint_tol = float(value)

    def set_goal_position_tolerance(self, value: float) -> None:
        self._pos_tol = float(value)

    def set_goal_orientation_tolerance(self, value: float) -> None:
        self._orient_tol = float(value)

    def get_goal_orientation_tolerance(self) -> float:
        return self._orient_tol

    def get_goal_joint_tolerance(self) -> float:
        return self._joint_tol

    def get_goal_position_tolerance(self) -> float:
        return self._pos_tol

    # ------------------------------------------------------------------ motion
    def _request(self) -> moveit_msgs.MotionPlanRequest:
        req = moveit_msgs.MotionPlanRequest(
            group_name=self._name, planner_id=self._planner_id,
            num_planning_attempts=self._attempts, allowed_planning_time=self._planning_time,
            max_velocity_scaling_factor=self._vs, max_acceleration_scaling_factor=self._as,
        )  # fmt: skip
        if self._pose_target is not None:
            c = pose_goal(
                self._ee, self._pose_target, self._orientation_target, self._pos_tol,
                self._orient_tol, frame_id=self._target_frame,
            )  # fmt: skip
        else:
            c = joint_goal(self._joints, self._target, self._joint_tol)
        req.goal_constraints = [c]
        return req

    def _send(self, client, goal, wait: bool):
        if not client.wait_for_server():
            raise MoveItCommanderException(f"no action server at {client.name}")
        h = client.send_goal(goal)
        if wait:
            self._c.wait(
                lambda: h.result is not None,
                self._planning_time + self._timeout_margin + self._expected(goal),
            )
        return h

    @staticmethod
    def _expected(goal) -> float:
        traj = getattr(goal, "trajectory", None)
        if traj is not None and traj.joint_trajectory.points:
            return traj.joint_trajectory.points[-1].time_from_start.to_sec() * 1.2 + 1.0
        return 600.0

    def plan(self, joints=None):
        """``(success, RobotTrajectory, planning_time, MoveItErrorCodes)``."""
        if joints is not None:
            self._set_any(joints)
        goal = moveit_msgs.MoveGroupGoal(request=self._request())
        goal.planning_options.plan_only = True
        h = self._send(self._move, goal, True)
        r = h.result or moveit_msgs.MoveGroupResult()
        if h.result is None:
            r.error_code.val = E.TIMED_OUT
        return r.error_code.val == E.SUCCESS, r.planned_trajectory, r.planning_time, r.error_code

    def go(self, joints=None, wait: bool = True) -> bool:
        if joints is not None:
            self._set_any(joints)
        goal = moveit_msgs.MoveGroupGoal(request=self._request())
        self._last = self._send(self._move, goal, wait)
        if not wait:
            return True
        r = self._last.result
        return r is not None and r.error_code.val == E.SUCCESS

    def execute(self, plan_msg, wait: bool = True) -> bool:
        traj = plan_msg
        if isinstance(plan_msg, tuple):
            raise MoveItCommanderException(
                "execute() takes a RobotTrajectory; plan() returns (success, trajectory, "
                "planning_time, error_code) since MoveIt 1.1 (Noetic): execute(plan[1])"
            )
        if isinstance(plan_msg, trajectory_msgs.JointTrajectory):
            traj = moveit_msgs.RobotTrajectory(joint_trajectory=plan_msg)
        elif not isinstance(plan_msg, moveit_msgs.RobotTrajectory):
            raise MoveItCommanderException(
                f"Expected value of type RobotTrajectory, got {type(plan_msg).__name__}"
            )
        h = self._send(self._exec, moveit_msgs.ExecuteTrajectoryGoal(trajectory=traj), wait)
        self._last = h
        return not wait or (h.result is not None and h.result.error_code.val == E.SUCCESS)

    def compute_cartesian_path(
        self, waypoints, eef_step: float, jump_threshold=0.0, avoid_collisions=True,
        path_constraints=None,
    ):  # fmt: skip
        """``(RobotTrajectory, fraction)``: the end effector along straight lines from where it
        is through ``waypoints`` (Poses in the planning frame) in steps of ``eef_step`` m;
        fraction is -1.0 on an error, as MoveIt's. Both moveit_commander signatures: up to
        1.1.14 ``(waypoints, eef_step, jump_threshold, avoid_collisions)``, from 1.1.15
        ``(waypoints, eef_step, avoid_collisions)``. Arms with fewer than six joints follow the
        waypoints' positions only (``fleetsim.moveit.cartesian``)."""
        if isinstance(jump_threshold, bool):  # the 1.1.15 signature
            jump_threshold, avoid_collisions = 0.0, jump_threshold
        if path_constraints is not None:
            raise MoveItCommanderException("path constraints are not supported by fleetsim")
        if not eef_step > 0:
            raise MoveItCommanderException(f"eef_step must be > 0 m, got {eef_step}")
        poses = [w.pose if isinstance(w, geometry_msgs.PoseStamped) else w for w in waypoints]
        if not all(isinstance(w, geometry_msgs.Pose) for w in poses):
            raise MoveItCommanderException("waypoints must be geometry_msgs Poses")
        frames = {
            w.header.frame_id.lstrip("/")
            for w in waypoints
            if isinstance(w, geometry_msgs.PoseStamped) and w.header.frame_id
        }
        if len(frames) > 1:
            raise MoveItCommanderException(
                f"waypoints in several frames ({', '.join(sorted(frames))}): give them in one"
            )
        req = moveit_msgs.GetCartesianPathRequest(
            group_name=self._name, link_name=self._ee, waypoints=poses, max_step=float(eef_step),
            jump_threshold=float(jump_threshold), avoid_collisions=bool(avoid_collisions),
        )  # fmt: skip
        req.header.frame_id = frames.pop() if frames else self.get_pose_reference_frame()
        res = self._c.call("compute_cartesian_path", moveit_msgs.GetCartesianPath, req)
        if res.error_code.val != E.SUCCESS:
            return res.solution, -1.0
        return res.solution, float(res.fraction)

    def stop(self) -> None:
        self._event.publish(std_msgs.String("stop"))

    def last_result(self) -> Any:
        """The last go()/execute() action result (fleetsim addition: its error code and text)."""
        h = getattr(self, "_last", None)
        return (h.result, h.text) if h is not None else (None, "")

    def _set_any(self, joints) -> None:
        if isinstance(joints, str):
            self.set_named_target(joints)
        elif isinstance(joints, geometry_msgs.Pose | geometry_msgs.PoseStamped):
            self.set_pose_target(joints)
        else:
            self.set_joint_value_target(joints)
