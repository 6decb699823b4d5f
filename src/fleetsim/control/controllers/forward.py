"""Single-joint and group controllers that follow a command topic.

- ``effort_controllers/JointPositionController``: a PID (``pid/{p,i,d,i_clamp}``) on one
  ``joint`` turns a position command (``std_msgs/Float64`` on ``command``) into effort, and
  publishes ``control_msgs/JointControllerState`` on ``state``.
- ``position_controllers/JointGroupPositionController`` (and the effort/velocity
  ``JointGroup*Controller`` forwards): ``std_msgs/Float64MultiArray`` on ``command``, one
  value per ``joints`` entry, written to the joints as they come.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fleetsim.control.controllers.base import Controller, register
from fleetsim.control.pid import Pid
from fleetsim.errors import ControlError
from fleetsim.msgs import control_msgs, std_msgs
from fleetsim.runtime import param


@dataclass(frozen=True)
class JointPositionControllerParams:
    joint: str = param("", help="the joint (required)")
    pid: dict = param({}, help="gains p, i, d, i_clamp")


@register("effort_controllers/JointPositionController")
class JointPositionController(Controller):
    Params = JointPositionControllerParams

    def __init__(self, runtime, name, namespace, *, hw, type_name) -> None:
        super().__init__(runtime, name, namespace, hw=hw, type_name=type_name)
        self.joint = self._require(self.params.joint, "joint")
        hw.check_joints([self.joint], "effort", self.full_name)
        self.pid = Pid.from_params(self._require(self.params.pid, "pid"), f"{self.full_name}/pid")
        self.lower, self.upper, _, _ = hw.limits(self.joint)
        self.target = 0.0
        self.state = control_msgs.JointControllerState()
        self.create_subscription(std_msgs.Float64, "~command", self._on_command, queue_size=1)
        self.state_pub = self.create_publisher(control_msgs.JointControllerState, "~state")
        self.create_timer(1.0 / 50.0, self._publish_state)

    def claimed(self) -> list[str]:
        return [self.joint]

    def _on_command(self, msg) -> None:
        if not math.isfinite(msg.data):
            self.get_logger().error("command %r is not finite; ignored", msg.data)
            return
        self.target = min(max(float(msg.data), self.lower), self.upper)  # enforceJointLimits

    def starting(self, t: float) -> None:
        self.target = float(self.hw.positions([self.joint])[0])
        self.pid.reset()

    def update(self, t: float, dt: float) -> None:
        q, qd = self.hw.states([self.joint])
        pos, vel = float(q[0]), float(qd[0])
        err = self.target - pos
        cmd = self.pid.compute(err, -vel, dt)
        self.hw.command(self.joint, cmd)
        s = self.state
        s.set_point, s.process_value, s.process_value_dot = self.target, pos, vel
        s.error, s.time_step, s.command = err, dt, cmd
        s.p, s.i, s.d, s.i_clamp = self.pid.p, self.pid.i, self.pid.d, self.pid.i_clamp

    def _publish_state(self) -> None:
        if self.running:
            self.state.header.stamp = self.now_msg()
            self.state_pub.publish(self.state)


@dataclass(frozen=True)
class JointGroupParams:
    joints: list = param([], help="the joints, in command order (required)")


@register(
    "position_controllers/JointGroupPositionController",
    "velocity_controllers/JointGroupVelocityController",
    "effort_controllers/JointGroupEffortController",
)
class JointGroupController(Controller):
    """Forwards each ``command`` value to its joint on the controller's interface."""

    Params = JointGroupParams

    def __init__(self, runtime, name, namespace, *, hw, type_name) -> None:
        super().__init__(runtime, name, namespace, hw=hw, type_name=type_name)
        self.joints = [str(j) for j in self._require(self.params.joints, "joints")]
        hw.check_joints(self.joints, self.interface, self.full_name)
        self.commands = np.zeros(len(self.joints))
        self.create_subscription(
            std_msgs.Float64MultiArray, "~command", self._on_command, queue_size=1
        )

    def claimed(self) -> list[str]:
        return list(self.joints)

    def _on_command(self, msg) -> None:
        data = np.asarray(msg.data, np.float64)
        if data.shape != (len(self.joints),) or not np.all(np.isfinite(data)):
            self.get_logger().error(
                "Dimension of command (%d) does not match number of joints (%d) or is not "
                "finite; not executing",
                data.size,
                len(self.joints),
            )
            return
        self.commands = data

    def starting(self, t: float) -> None:
        self.commands = (
            self.hw.positions(self.joints)
            if self.interface == "position"
            else np.zeros(len(self.joints))
        )

    def update(self, t: float, dt: float) -> None:
        for j, v in zip(self.joints, self.commands, strict=True):
            self.hw.command(j, float(v))


__all__ = ["ControlError", "JointGroupController", "JointPositionController"]
