"""Joint actuation for arms (``libgazebo_ros_control.so``): effort, velocity, position.

Every ``<transmission>`` joint gets a MuJoCo actuator by its hardware interface:
``EffortJointInterface`` a torque motor limited to the URDF effort limit, ``VelocityJointInterface``
a velocity servo, ``PositionJointInterface`` a position servo (stiffness from the effort limit).
Controllers (the arm issue's ros_control layer) call ``command(joint, value)``, either from
their own timers or, for loops that must run at the physics rate, from an update hook
(``add_update_hook``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from fleetsim.errors import SimulationError, did_you_mean
from fleetsim.runtime.params import param
from fleetsim.sim.plugins.base import ActuatorPlugin, joint_addresses, register, require_joint

DEFAULT_EFFORT = 100.0  # N m (or N), when the URDF gives no effort limit
KP_PER_EFFORT = 20.0  # position-servo stiffness per unit effort limit (1/rad)


@dataclass(frozen=True)
class GazeboRosControlParams:
    controlPeriod: float = param(0.0, unit="s", range=(0.0, None), help="0: every physics step")
    robotSimType: str = param("gazebo_ros_control/DefaultRobotHWSim", help="unused")
    legacyModeNS: bool = param(True, help="unused")
    robotParam: str = param("robot_description", help="unused")


def _mode(interface: str) -> str:
    for mode in ("Effort", "Velocity", "Position"):
        if mode in interface:
            return mode.lower()
    return ""


@register("libgazebo_ros_control.so")
class JointActuationPlugin(ActuatorPlugin):
    Params = GazeboRosControlParams

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        self.modes: dict[str, str] = {}
        for tr in ctx.robot.transmissions:
            for joint, interface in tr.joints:
                mode = _mode(interface)
                if not mode:
                    raise SimulationError(
                        f"{self.where}: transmission '{tr.name}' joint '{joint}' has hardware "
                        f"interface '{interface}'; use Effort/Velocity/PositionJointInterface"
                    )
                self.modes[require_joint(ctx, joint, f"transmission '{tr.name}'", spec.name)] = mode
        self.targets = dict.fromkeys(self.modes, 0.0)
        self.hooks: list = []

    def _effort(self, joint: str) -> float:
        lim = self.ctx.robot.joints[joint].limit
        return lim.effort if lim is not None and lim.effort > 0 else DEFAULT_EFFORT

    def build(self, spec, engine) -> None:
        for joint, mode in self.modes.items():
            a = spec.add_actuator(
                name=f"{self.ctx.model}/{self.name}/{joint}",
                target=f"{self.ctx.model}/{joint}",
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
            )
            effort = self._effort(joint)
            if mode == "effort":
                a.set_to_motor()
            elif mode == "velocity":
                a.set_to_velocity(kv=effort)
            else:
                kp = KP_PER_EFFORT * effort
                a.set_to_position(kp=kp, kv=2.0 * math.sqrt(kp) * 0.5)
            a.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            a.forcerange = [-effort, effort]

    def bind(self, engine) -> None:
        m = engine.model
        self.act = {
            j: mujoco.mj_name2id(
                m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{self.ctx.model}/{self.name}/{j}"
            )
            for j in self.modes
        }
        # each joint's qpos and dof addresses in this compile's model: `states` runs at the
        # physics rate under ros_control-style controllers (the hunter's arm: 250 Hz), where
        # looking each name up again cost ~2 us a joint a step
        qadr, dadr = joint_addresses(engine, self.ctx.model, list(self.modes))
        self._addr = list(zip(self.modes, qadr.tolist(), dadr.tolist(), strict=True))
        self._qadr, self._dadr = qadr, dadr
        self._index = {j: k for k, j in enumerate(self.modes)}
        self._addresses: dict[tuple[str, ...], tuple[np.ndarray, np.ndarray]] = {}

    def reset(self) -> None:
        self.targets = dict.fromkeys(self.modes, 0.0)

    def command(self, joint: str, value: float) -> None:
        """Set a joint's effort (N m), velocity (rad/s) or position (rad) target."""
        if joint not in self.modes:
            raise SimulationError(
                f"{self.where}: no actuated joint '{joint}'{did_you_mean(joint, self.modes)}"
            )
        if not math.isfinite(value):
            raise SimulationError(f"{self.where}: command for '{joint}' must be finite")
        self.targets[joint] = float(value)

    def add_update_hook(self, hook) -> None:
        """Call ``hook(plugin, engine, t)`` before every physics step, before the targets are
        applied: where ros_control-style controllers run, at the control period of
        gazebo_ros_control (PID loops over effort joints need the physics rate to be stable)."""
        self.hooks.append(hook)

    def control(self, engine, t: float) -> None:
        for hook in self.hooks:
            hook(self, engine, t)
        ctrl = engine.data.ctrl
        for j, v in self.targets.items():
            ctrl[self.act[j]] = v

    def states(self, engine) -> dict[str, tuple[float, float]]:
        """``{joint: (position, velocity)}`` of the actuated joints."""
        qpos, qvel = engine.data.qpos, engine.data.qvel
        return {j: (float(qpos[a]), float(qvel[v])) for j, a, v in self._addr}

    def addresses(self, joints) -> tuple[np.ndarray, np.ndarray]:
        """(J,) qpos and (J,) dof addresses of ``joints`` (actuated joints of this robot) in the
        bound model, for reading many joints with one indexing; kept per joint list until the
        next `bind` (a recompile, such as a spawn or a delete, moves them)."""
        key = tuple(joints)
        hit = self._addresses.get(key)
        if hit is None:
            k = [self._index[j] for j in joints]
            hit = self._addresses[key] = (self._qadr[k], self._dadr[k])
        return hit


__all__ = ["JointActuationPlugin"]
