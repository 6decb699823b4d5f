"""Joint state publisher (``libgazebo_ros_joint_state_publisher.so``).

Publishes position, velocity and actuator effort of the joints listed in ``jointName``
(comma-separated); with no list, every movable joint of the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fleetsim.runtime.params import param
from fleetsim.sim.plugins.base import (
    JointStateReading,
    SensorPlugin,
    joint_addresses,
    register,
    require_joint,
)


@dataclass(frozen=True)
class JointStateParams:
    jointName: str = param("", help="comma-separated joints; empty: every movable joint")
    updateRate: float = param(100.0, unit="Hz", range=(0.0, None), help="publish rate")
    topicName: str = param("joint_states", help="JointState topic")


@register("libgazebo_ros_joint_state_publisher.so")
class JointStatePlugin(SensorPlugin):
    Params = JointStateParams

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        names = [n.strip() for n in self.params.jointName.split(",") if n.strip()]
        if not names:
            names = [
                n
                for n, j in ctx.robot.joints.items()
                if j.type in ("revolute", "continuous", "prismatic")
            ]
        self.joints = [require_joint(ctx, n, "jointName", spec.name) for n in names]

    @property
    def update_rate(self) -> float:
        return self.params.updateRate

    def bind(self, engine) -> None:
        self.qadr, self.dadr = joint_addresses(engine, self.ctx.model, self.joints)

    def measure(self, engine, t: float) -> JointStateReading:
        return self.measure_each(engine, [self], t)[0]

    @classmethod
    def measure_each(cls, engine, plugins: list, t: float) -> list[JointStateReading]:
        """Joint states of many plugins from one gather, in the order of ``plugins``."""
        d = engine.data
        qadr = np.concatenate([p.qadr for p in plugins])
        dadr = np.concatenate([p.dadr for p in plugins])
        pos, vel, eff = d.qpos[qadr], d.qvel[dadr], d.qfrc_actuator[dadr]
        out = []
        a = 0
        for p in plugins:
            b = a + len(p.joints)
            out.append(
                JointStateReading(
                    t,
                    p.params.topicName,
                    list(p.joints),
                    pos[a:b],
                    vel[a:b],
                    eff[a:b],
                    p.ctx.namespace,
                )
            )
            a = b
        return out
