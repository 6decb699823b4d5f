"""``robot_state_publisher``: tf for every link of a robot from ``joint_states``.

Reads ``robot_description`` (URDF text, found by searching up from the node's namespace as
``urdf::Model::initParam`` does), publishes fixed joints once on the latched ``/tf_static`` and
the movable joints named in each ``joint_states`` message on ``/tf``, stamped with the message's
stamp. Frames get the robot's ``tf_prefix`` (``lizi1/base_link``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fleetsim.description.kinematics import (
    FIXED,
    child_transforms_from_joint_positions,
    joint_arrays,
)
from fleetsim.description.model import Robot
from fleetsim.description.urdf import parse_urdf
from fleetsim.errors import ParameterError
from fleetsim.msgs import sensor_msgs
from fleetsim.runtime import Node, param
from fleetsim.tf._msgs import make_transform_stamped
from fleetsim.tf.broadcaster import StaticTransformBroadcaster, TransformBroadcaster


@dataclass(frozen=True)
class RobotStatePublisherParams:
    publish_frequency: float = param(
        50.0, unit="Hz", range=(0.0, None), help="max rate of /tf for each joint"
    )
    ignore_timestamp: bool = param(
        False, help="publish every joint_states message, not only at publish_frequency"
    )
    use_tf_static: bool = param(True, help="fixed joints once on latched /tf_static")


def robot_description_text(node: Node, key: str = "robot_description") -> tuple[str, str]:
    """The URDF text of ``robot_description`` (searched up the namespace) and its full name."""
    found = node.search_param(key)
    if found is None:
        raise ParameterError(
            f"{node.full_name}: parameter '{key}' not found in {node.namespace} or above; "
            f'set it to the URDF text (<param name="{key}" command="xacro FILE"/>)'
        )
    text = node.runtime.params.get(found)
    if not isinstance(text, str) or "<robot" not in text:
        shown = repr(text)[:80]
        raise ParameterError(
            f"{node.full_name}: parameter {found} must hold URDF XML text, got {shown}; a file "
            'path is not accepted (use command="xacro FILE" or textfile="FILE")'
        )
    return text, found


class RobotStatePublisher(Node):
    """The robot_state_publisher node (ROS package ``robot_state_publisher``)."""

    Params = RobotStatePublisherParams

    def __init__(self, runtime, name: str = "robot_state_publisher", namespace="/", **kw):
        super().__init__(runtime, name, namespace, **kw)
        text, where = robot_description_text(self)
        self.robot: Robot = parse_urdf(text, source=f"parameter {where}")
        joints = list(self.robot.joints.values())
        self._xyz, self._quat, self._axes, self._kinds = joint_arrays(joints)
        self._index = {j.name: i for i, j in enumerate(joints)}
        self._joints = joints
        # tf_prefix is read once, as ROS's robot_state_publisher reads it at start-up: resolving
        # it for every joint of every joint_states message was half of this node's time
        self._frames = [(self.frame(j.parent), self.frame(j.child)) for j in joints]
        self._last_stamp: dict[str, int] = {}
        self.tf = TransformBroadcaster(self)
        self.tf_static = StaticTransformBroadcaster(self)
        self.publish_fixed_transforms()
        if not self.params.use_tf_static and self.params.publish_frequency > 0:
            self.create_timer(1.0 / self.params.publish_frequency, self.publish_fixed_transforms)
        self.create_subscription(sensor_msgs.JointState, "joint_states", self.on_joint_states)

    def _transforms(self, idx: np.ndarray, positions: np.ndarray, stamp):
        trans, rot = child_transforms_from_joint_positions(
            self._xyz[idx], self._quat[idx], self._axes[idx], self._kinds[idx], positions
        )
        return [
            make_transform_stamped(*self._frames[i], stamp, t, q)
            for i, t, q in zip(idx.tolist(), trans.tolist(), rot.tolist())
        ]

    def publish_fixed_transforms(self) -> None:
        idx = np.flatnonzero(self._kinds == FIXED)
        if idx.size == 0:
            return
        msgs = self._transforms(idx, np.zeros(idx.size), self.now_msg())
        if self.params.use_tf_static:
            self.tf_static.send_transform(msgs)
        else:
            self.tf.send_transform(msgs)

    def on_joint_states(self, msg) -> None:
        if len(msg.name) != len(msg.position):
            self.get_logger().warning(
                f"joint_states with {len(msg.name)} names and {len(msg.position)} positions; "
                "ignored"
            )
            return
        values = dict(zip(msg.name, np.asarray(msg.position, dtype=np.float64)))
        for j in self._joints:  # mimic joints follow their leader
            if j.mimic is not None and j.mimic.joint in values and j.name not in values:
                values[j.name] = j.mimic.multiplier * values[j.mimic.joint] + j.mimic.offset
        stamp_ns = msg.header.stamp.to_nsec()
        interval = 0 if self.params.publish_frequency <= 0 else 1e9 / self.params.publish_frequency
        chosen, positions = [], []
        for name, pos in values.items():
            i = self._index.get(name)
            if i is None or self._kinds[i] == FIXED:
                continue
            last = self._last_stamp.get(name)
            if not self.params.ignore_timestamp and last is not None and stamp_ns < last + interval:
                continue
            self._last_stamp[name] = stamp_ns
            chosen.append(i)
            positions.append(pos)
        if chosen:
            self.tf.send_transform(
                self._transforms(np.array(chosen), np.array(positions), msg.header.stamp)
            )
