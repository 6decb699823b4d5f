"""Ground-truth pose (``libgazebo_ros_p3d.so``): a body's true pose and twist as Odometry.

``frameName`` is the frame the pose is given in: the world (``world``, ``/world``, ``map``,
``/map``: the world frame equals the map frame) or a link of the same model. Offsets are applied
as in Gazebo (``xyzOffsets`` added to the position, ``rpyOffsets`` composed on the orientation),
then Gaussian noise of std ``gaussianNoise`` is added to position and velocities.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numba
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
        st = world_states(d.xpos, d.xquat, d.cvel, d.subtree_com, b, root, offsets, off_q)
        pos, xyzw, lin, ang = st[:, 0:3], st[:, 3:7], st[:, 7:10], st[:, 10:13]
        if len(noisy):
            z = engine.rng.standard_normal(9 * len(noisy)).reshape(-1, 3, 3)
            s = sigma[noisy, None]
            pos[noisy] = pos[noisy] + s * z[:, 0]
            lin[noisy] = lin[noisy] + s * z[:, 1]
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


@numba.njit(cache=True)
def world_states(xpos, xquat, cvel, subtree_com, b, root, offsets, off_q):
    """Pose and twist of bodies ``b`` for world-frame p3d plugins, (B, 13): position + offset
    (3), orientation ``off_q * xquat`` as x, y, z, w (4), linear velocity at the body's origin
    (``v + w x (xpos - subtree_com[root])``, 3) and angular velocity (3), all in the world.

    The NumPy batch it replaces did the same operations in the same order (row-wise cross
    product, Hamilton product); compiled, as at 100 Hz per robot that batch's two dozen
    small-array calls cost ~40 us each time."""
    n = b.shape[0]
    out = np.empty((n, 13))
    for i in range(n):
        k, r = b[i], root[i]
        w0, w1, w2 = cvel[k, 0], cvel[k, 1], cvel[k, 2]
        l0 = xpos[k, 0] - subtree_com[r, 0]
        l1 = xpos[k, 1] - subtree_com[r, 1]
        l2 = xpos[k, 2] - subtree_com[r, 2]
        out[i, 0] = xpos[k, 0] + offsets[i, 0]
        out[i, 1] = xpos[k, 1] + offsets[i, 1]
        out[i, 2] = xpos[k, 2] + offsets[i, 2]
        aw, ax, ay, az = off_q[i, 0], off_q[i, 1], off_q[i, 2], off_q[i, 3]
        bw, bx, by, bz = xquat[k, 0], xquat[k, 1], xquat[k, 2], xquat[k, 3]
        out[i, 6] = aw * bw - ax * bx - ay * by - az * bz
        out[i, 3] = aw * bx + ax * bw + ay * bz - az * by
        out[i, 4] = aw * by - ax * bz + ay * bw + az * bx
        out[i, 5] = aw * bz + ax * by - ay * bx + az * bw
        out[i, 7] = cvel[k, 3] + (w1 * l2 - w2 * l1)
        out[i, 8] = cvel[k, 4] + (w2 * l0 - w0 * l2)
        out[i, 9] = cvel[k, 5] + (w0 * l1 - w1 * l0)
        out[i, 10] = w0
        out[i, 11] = w1
        out[i, 12] = w2
    return out
