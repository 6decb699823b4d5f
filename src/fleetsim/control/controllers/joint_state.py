"""``joint_state_controller/JointStateController``: the hardware's joints on ``joint_states``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fleetsim.control.controllers.base import Controller, register
from fleetsim.errors import ControlError
from fleetsim.msgs import sensor_msgs
from fleetsim.runtime import param


@dataclass(frozen=True)
class JointStateControllerParams:
    publish_rate: float = param(0.0, unit="Hz", range=(0.0, None), help="required; > 0")
    joints: list = param([], help="joints to publish; empty: every joint of the hardware")
    extra_joints: list = param([], help="[{name, position, velocity, effort}] published as given")


@register("joint_state_controller/JointStateController")
class JointStateController(Controller):
    Params = JointStateControllerParams

    def __init__(self, runtime, name, namespace, *, hw, type_name) -> None:
        super().__init__(runtime, name, namespace, hw=hw, type_name=type_name)
        if self.params.publish_rate <= 0:
            raise ControlError(f"{self.full_name}: Parameter 'publish_rate' not set (or not > 0)")
        self.joints = [str(j) for j in self.params.joints] or hw.joints
        hw.check_joints(self.joints, "state", self.full_name)
        self.extra = []
        for e in self.params.extra_joints:
            if not isinstance(e, dict) or "name" not in e:
                raise ControlError(f"{self.full_name}: extra_joints entries need a 'name': {e!r}")
            self.extra.append(e)
        # as ros_control: joint_states relative to the controller_manager's namespace
        self.pub = self.create_publisher(sensor_msgs.JointState, "joint_states", queue_size=10)
        self.create_timer(1.0 / self.params.publish_rate, self._publish)

    def _publish(self) -> None:
        if not self.running:
            return
        msg = sensor_msgs.JointState()
        msg.header.stamp = self.now_msg()
        msg.name = self.joints + [str(e["name"]) for e in self.extra]
        extra = [
            [float(e.get(k, 0.0)) for e in self.extra] for k in ("position", "velocity", "effort")
        ]
        q, qd = self.hw.states(self.joints)
        msg.position = np.concatenate([q, extra[0]])
        msg.velocity = np.concatenate([qd, extra[1]])
        msg.effort = np.concatenate([self.hw.efforts(self.joints), extra[2]])
        self.pub.publish(msg)
