"""The robot hardware ros_control sees in the simulator (gazebo_ros_control's DefaultRobotHWSim).

Its joints are those of the model's ``<transmission>`` elements, each with the one hardware
interface its transmission declares (effort, velocity or position). Reading gives positions and
velocities from the physics; writing sets the actuator targets of the ``libgazebo_ros_control.so``
plugin, which applies them before each physics step.
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.errors import ControlError, did_you_mean

INTERFACES = {
    "effort": "hardware_interface/EffortJointInterface",
    "velocity": "hardware_interface/VelocityJointInterface",
    "position": "hardware_interface/PositionJointInterface",
}


class SimRobotHW:
    """Joint handles onto one robot's actuation plugin.

    Parameters
    ----------
    plugin : the robot's ``JointActuationPlugin`` (``libgazebo_ros_control.so``).
    engine : the simulator's ``Engine``.
    """

    def __init__(self, plugin, engine) -> None:
        self.plugin = plugin
        self.engine = engine
        self.modes: dict[str, str] = dict(plugin.modes)
        self.robot = plugin.ctx.robot
        self.where = plugin.where

    @property
    def joints(self) -> list[str]:
        return list(self.modes)

    def check_joints(self, joints: list[str], interface: str, who: str) -> None:
        """Error unless every joint exists with ``interface`` ("effort", "position", ...)."""
        if not joints:
            raise ControlError(f"{who}: no joints given (parameter 'joints' or 'joint')")
        for j in joints:
            if j not in self.modes:
                raise ControlError(
                    f"{who}: joint '{j}' has no transmission in the robot's URDF"
                    f"{did_you_mean(j, self.modes)}; joints with transmissions: "
                    f"{', '.join(self.modes) or 'none'}"
                )
            if interface != "state" and self.modes[j] != interface:
                raise ControlError(
                    f"{who}: joint '{j}' is declared with {INTERFACES[self.modes[j]]} in its "
                    f"transmission, the controller needs {INTERFACES[interface]}"
                )

    def positions(self, joints: list[str]) -> np.ndarray:
        """(J,) joint positions (rad or m)."""
        return self.states(joints)[0]

    def states(self, joints: list[str]) -> tuple[np.ndarray, np.ndarray]:
        """(J,) positions and (J,) velocities from one read of the joints (a control step's).

        Trajectory controllers call this at the physics rate (250 Hz on the hunter's arm): the
        joints' addresses come from the plugin, which keeps them until its next bind."""
        qa, va = self.plugin.addresses(joints)
        d = self.engine.data
        return d.qpos[qa], d.qvel[va]

    def velocities(self, joints: list[str]) -> np.ndarray:
        """(J,) joint velocities (rad/s or m/s)."""
        return self.states(joints)[1]

    def efforts(self, joints: list[str]) -> np.ndarray:
        """(J,) actuator efforts applied in the last step (N m or N)."""
        d, m, out = self.engine.data, self.engine.model, []
        for j in joints:
            jid = self.engine.joint_id(self.plugin.ctx.model, j)
            out.append(float(d.qfrc_actuator[m.jnt_dofadr[jid]]))
        return np.array(out)

    def command(self, joint: str, value: float) -> None:
        """Set the joint's command on its interface (effort N m, velocity rad/s, position rad)."""
        self.plugin.command(joint, value)

    def limits(self, joint: str) -> tuple[float, float, float, float]:
        """``(lower, upper, velocity, effort)`` from the URDF; inf where it gives none."""
        j = self.robot.joints[joint]
        lim = j.limit
        if lim is None or j.type == "continuous":
            lo, hi = -math.inf, math.inf
        else:
            lo, hi = lim.lower, lim.upper
        vel = lim.velocity if lim is not None and lim.velocity > 0 else math.inf
        eff = lim.effort if lim is not None and lim.effort > 0 else math.inf
        return lo, hi, vel, eff
