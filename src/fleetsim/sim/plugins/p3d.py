"""Ground-truth pose (``libgazebo_ros_p3d.so``): a body's true pose and twist as Odometry.

``frameName`` is the frame the pose is given in: the world (``world``, ``/world``, ``map``,
``/map``: the world frame equals the map frame) or a link of the same model. Offsets are applied
as in Gazebo (``xyzOffsets`` added to the position, ``rpyOffsets`` composed on the orientation),
then Gaussian noise of std ``gaussianNoise`` is added to position and velocities.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.runtime.params import param
from fleetsim.sim.build import quat_from_rpy
from fleetsim.sim.plugins.base import OdometryReading, SensorPlugin, register, require_link

WORLD_FRAMES = ("world", "/world", "map", "/map", "")


@dataclass(frozen=True)
class P3dParams:
    bodyName: str = param("", help="link whose pose is reported (required)")
    topicName: str = param("", help="Odometry topic (required)")
    frameName: str = param("world", help="reference frame: the world or a link of the model")
    xyzOffsets: tuple[float, float, float] = param(
        (0.0, 0.0, 0.0), unit="m", aliases=("xyzOffset",), help="position offset"
    )
    rpyOffsets: tuple[float, float, float] = param(
        (0.0, 0.0, 0.0), unit="rad", aliases=("rpyOffset",), help="orientation offset"
    )
    gaussianNoise: float = param(0.0, unit="m", range=(0.0, None), help="noise std")
    updateRate: float = param(0.0, unit="Hz", range=(0.0, None), help="0: every physics step")


@register("libgazebo_ros_p3d.so")
class P3dPlugin(SensorPlugin):
    Params = P3dParams

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        p = self.params
        if not p.topicName:
            raise SimulationError(f"{self.where}: parameter 'topicName' is required")
        require_link(ctx, p.bodyName, "bodyName", spec.name)
        self.ref_link = None if p.frameName in WORLD_FRAMES else p.frameName
        if self.ref_link is not None:
            require_link(ctx, self.ref_link, "frameName", spec.name)
        self.off_q = quat_from_rpy(*p.rpyOffsets)

    @property
    def update_rate(self) -> float:
        return self.params.updateRate

    def bind(self, engine) -> None:
        self.body = engine.link_id(self.ctx.model, self.params.bodyName)
        self.ref = engine.link_id(self.ctx.model, self.ref_link) if self.ref_link is not None else 0

    def measure(self, engine, t: float) -> OdometryReading:
        d, m = engine.data, engine.model
        pos = d.xpos[self.body].copy()
        q = d.xquat[self.body].copy()
        vel = np.zeros(6)
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, self.body, vel, 0)
        lin, ang = vel[3:].copy(), vel[:3].copy()
        if self.ref:
            qi = np.zeros(4)
            mujoco.mju_negQuat(qi, d.xquat[self.ref])
            for v in (lin, ang):
                mujoco.mju_rotVecQuat(v, v.copy(), qi)
            rel = np.zeros(3)
            mujoco.mju_rotVecQuat(rel, pos - d.xpos[self.ref], qi)
            pos = rel
            qq = np.zeros(4)
            mujoco.mju_mulQuat(qq, qi, q)
            q = qq
        pos = pos + np.asarray(self.params.xyzOffsets)
        qq = np.zeros(4)
        mujoco.mju_mulQuat(qq, self.off_q, q)
        sigma = self.params.gaussianNoise
        if sigma > 0:
            pos = pos + sigma * engine.rng.standard_normal(3)
            lin = lin + sigma * engine.rng.standard_normal(3)
            ang = ang + sigma * engine.rng.standard_normal(3)
        return OdometryReading(
            t,
            self.params.topicName,
            self.ctx.frame(self.params.frameName or "world"),
            self.ctx.frame(self.params.bodyName),
            pos,
            np.array([*qq[1:], qq[0]]),
            lin,
            ang,
            publish_tf=False,
            covariance=sigma * sigma,
        )
