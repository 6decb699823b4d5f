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
        self.frames = (ctx.frame(p.frameName or "world"), ctx.frame(p.bodyName))

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
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, self.body, vel, 0)
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

    @classmethod
    def measure_batch(cls, engine, plugins: list, t: float) -> list:
        """Readings of many p3d plugins at once (world-frame ones vectorised).

        Noise is drawn in the order of ``plugins`` (relative-frame ones first), nine normals
        per noisy plugin, so the readings equal those of one-by-one measurement.
        """
        if not any(p.ref for p in plugins):
            return cls._world_readings(engine, plugins, t)
        out = {}
        for p in plugins:
            if p.ref:
                r = p.measure(engine, t)
                r.namespace = p.ctx.namespace
                out[id(p)] = r
        world = [p for p in plugins if not p.ref]
        if world:
            out.update(zip(map(id, world), cls._world_readings(engine, world, t)))
        return [out[id(p)] for p in plugins]

    @staticmethod
    def _layout(engine, plugins: list) -> tuple:
        """Body ids, root ids, offsets, offset quaternions and noise of ``plugins`` (kept in
        ``Engine.layouts`` until the next compile)."""
        cache = engine.layouts
        key = ("p3d", *map(id, plugins))
        lay = cache.get(key)
        if lay is None:
            n = len(plugins)
            b = np.fromiter((p.body for p in plugins), np.int64, n)
            sigma = np.fromiter((p.params.gaussianNoise for p in plugins), float, n)
            lay = cache[key] = (
                b,
                engine.model.body_rootid[b],
                np.array([p.params.xyzOffsets for p in plugins], float).reshape(n, 3),
                np.array([p.off_q for p in plugins], float).reshape(n, 4),
                sigma,
                np.flatnonzero(sigma > 0),
            )
        return lay

    @classmethod
    def _world_readings(cls, engine, plugins: list, t: float) -> list:
        """Readings of world-frame p3d plugins, vectorised over the plugins."""
        d = engine.data
        b, root, offsets, off_q, sigma, noisy = cls._layout(engine, plugins)
        pos = d.xpos[b] + offsets
        cvel = d.cvel[b]
        ang = cvel[:, :3]
        lever = d.xpos[b] - d.subtree_com[root]
        lin = cvel[:, 3:] + cross_products(ang, lever)
        quat = quats_multiplied(off_q, d.xquat[b])
        xyzw = quat[:, [1, 2, 3, 0]]
        if len(noisy):
            z = engine.rng.standard_normal(9 * len(noisy)).reshape(-1, 3, 3)
            s = sigma[noisy, None]
            pos[noisy] = pos[noisy] + s * z[:, 0]
            lin[noisy] = lin[noisy] + s * z[:, 1]
            ang = ang.copy()
            ang[noisy] = ang[noisy] + s * z[:, 2]
        return [
            OdometryReading(
                t,
                p.params.topicName,
                p.frames[0],
                p.frames[1],
                pi,
                qi,
                li,
                ai,
                False,
                sg * sg,
                p.ctx.namespace,
            )
            for p, pi, qi, li, ai, sg in zip(plugins, pos, xyzw, lin, ang, sigma.tolist())
        ]


def cross_products(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross products ``a x b`` of (N, 3) arrays (as ``np.cross``, without its
    overhead)."""
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=1)


def quats_multiplied(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products ``a * b`` of (N, 4) quaternion arrays (w, x, y, z)."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )
