"""The targets of ``MoveGroupCommander`` (moveit_commander's set_*_target calls): named
states and remembered joint values, joint values, positions and poses (with their frame, the
pose reference frame unless a PoseStamped gives one), orientations and random targets."""

from __future__ import annotations

import numpy as np

from fleetsim.errors import PlanningError
from fleetsim.msgs import geometry_msgs
from fleetsim.tf.quaternions import euler_from_quaternion, quaternion_from_euler


class MoveItCommanderException(PlanningError):
    """moveit_commander's exception, for bad targets and settings."""


class CommanderTargets:
    """The target part of `MoveGroupCommander`: it sets ``_target`` (joint values),
    ``_pose_target``, ``_orientation_target`` and ``_target_frame``, which its requests read."""

    def get_named_targets(self) -> list[str]:
        return list(self._model.named_targets(self._name)) + list(self._remembered)

    def get_named_target_values(self, target: str) -> dict[str, float]:
        values = self._named(target)
        return dict(zip(self._joints, map(float, values), strict=True))

    def _named(self, name: str) -> np.ndarray:
        if name in self._remembered:
            return self._remembered[name]
        try:
            return self._model.named_target(self._name, name)
        except PlanningError as e:
            raise MoveItCommanderException(str(e)) from None

    def set_named_target(self, name: str) -> None:
        self._target, self._pose_target = self._named(name).copy(), None

    def remember_joint_values(self, name: str, values=None) -> None:
        v = self.get_current_joint_values() if values is None else values
        self._remembered[name] = np.asarray(v, float)

    def get_remembered_joint_values(self) -> dict[str, list[float]]:
        return {k: list(map(float, v)) for k, v in self._remembered.items()}

    def forget_joint_values(self, name: str) -> None:
        self._remembered.pop(name, None)

    def set_joint_value_target(self, arg1, arg2=None, arg3=None) -> None:
        q = np.array(self._target, float)
        if isinstance(arg1, str) and arg2 is not None:
            arg1 = {arg1: arg2}
        if isinstance(arg1, dict):
            for j, v in arg1.items():
                if j not in self._joints:
                    raise MoveItCommanderException(
                        f"joint '{j}' is not in group '{self._name}' ({', '.join(self._joints)})"
                    )
                q[self._joints.index(j)] = v
        elif isinstance(arg1, geometry_msgs.Pose | geometry_msgs.PoseStamped):
            # moveit_commander's (pose, end_effector_link="", approx=False): MoveIt solves IK
            # for the pose, then plans in joints; with approx, an approximate solution is
            # accepted: here the position exactly, the orientation whatever the arm makes
            # there (what approximate IK gives an arm of fewer than six joints)
            ee, approx = "", False
            if isinstance(arg2, str):
                ee, approx = arg2, bool(arg3)
            elif arg2 is not None:
                approx = bool(arg2)
            self.set_pose_target(arg1, ee)
            if approx:
                self._orientation_target = None
            return
        elif hasattr(arg1, "name") and hasattr(arg1, "position"):  # JointState
            self.set_joint_value_target(dict(zip(arg1.name, arg1.position, strict=False)))
            return
        else:
            values = np.asarray(arg1, float)
            if values.shape != (len(self._joints),):
                raise MoveItCommanderException(
                    f"Expected {len(self._joints)} joint values for group '{self._name}', got "
                    f"{values.size}"
                )
            q = values
        try:
            self._model.check_within_bounds(self._name, q, "target")
        except PlanningError as e:
            raise MoveItCommanderException(
                f"Error setting joint target. Is the target within bounds? {e}"
            ) from None
        self._target, self._pose_target = q, None

    def get_joint_value_target(self) -> list[float]:
        return [float(v) for v in self._target]

    def set_position_target(self, xyz, end_effector_link: str = "") -> None:
        """The end effector's position, any orientation (the target for arms with fewer than
        six joints, such as the hunter's)."""
        if not (end_effector_link or self._ee):
            raise MoveItCommanderException("There is no end effector to set the pose for")
        if end_effector_link:
            self._ee = end_effector_link
        self._pose_target = np.asarray(xyz, float)[:3]
        self._orientation_target = None
        self._target_frame = self._ref_frame

    def set_pose_target(self, pose, end_effector_link: str = "") -> None:
        """Position and orientation (a Pose, PoseStamped, [x, y, z, roll, pitch, yaw] or
        [x, y, z, qx, qy, qz, qw]). The orientation is kept: a group with fewer than six joints
        reaches only the orientations its joints can make, and planning to any other fails
        with NO_IK_SOLUTION saying so (use ``set_position_target`` for the position alone)."""
        frame = self._ref_frame
        if isinstance(pose, geometry_msgs.PoseStamped):
            frame = pose.header.frame_id.lstrip("/") or frame
            pose = pose.pose
        if isinstance(pose, geometry_msgs.Pose):
            xyz = [pose.position.x, pose.position.y, pose.position.z]
            o = pose.orientation
            quat = np.array([o.x, o.y, o.z, o.w], float)
        else:
            values = np.asarray(list(pose), float)
            if values.shape not in ((6,), (7,)):
                raise MoveItCommanderException(
                    "Expected [x, y, z, r, p, y] or [x, y, z, qx, qy, qz, qw]"
                )
            xyz = values[:3]
            quat = values[3:] if values.size == 7 else quaternion_from_euler(*values[3:])
        if not np.linalg.norm(quat) > 0 or not np.all(np.isfinite(quat)):
            raise MoveItCommanderException(f"the pose's orientation {list(quat)} is not a rotation")
        self.set_position_target(xyz, end_effector_link)
        self._orientation_target = quat / np.linalg.norm(quat)
        self._target_frame = frame

    def clear_pose_targets(self) -> None:
        self._pose_target = self._orientation_target = None

    def clear_pose_target(self, end_effector_link: str = "") -> None:
        self.clear_pose_targets()

    def set_orientation_target(self, q, end_effector_link: str = "") -> None:
        """The end effector turned to ``q`` (x y z w, or roll pitch yaw, in the planning frame)
        where it is now."""
        here = self.get_current_pose(end_effector_link)  # in the planning frame
        q = list(q)
        if len(q) == 3:
            q = list(quaternion_from_euler(*q))
        if len(q) != 4:
            raise MoveItCommanderException("Expected [qx, qy, qz, qw] or [r, p, y]")
        # the position stays where it is (fleetsim's pose goals constrain the position too;
        # MoveIt leaves it free), both in the frame get_current_pose gave them in
        here.pose.orientation = geometry_msgs.Quaternion(*map(float, q))
        self.set_pose_target(here, end_effector_link)

    def set_rpy_target(self, rpy, end_effector_link: str = "") -> None:
        if len(rpy) != 3:
            raise MoveItCommanderException("Expected [roll, pitch, yaw]")
        self.set_orientation_target(rpy, end_effector_link)

    def get_current_rpy(self, end_effector_link: str = "") -> list[float]:
        o = self.get_current_pose(end_effector_link).pose.orientation
        return [float(v) for v in euler_from_quaternion([o.x, o.y, o.z, o.w])]

    def get_random_joint_values(self) -> list[float]:
        lim = self._model.limits(self._name)
        return [float(v) for v in self._rng.uniform(lim.lower, lim.upper)]

    def set_random_target(self) -> None:
        self.set_joint_value_target(self.get_random_joint_values())
