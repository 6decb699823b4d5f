"""Differential drive (``libgazebo_ros_diff_drive.so``) and the shared wheeled-drive logic.

The wheels are real MuJoCo hinge joints rolling on friction contacts, each driven by a velocity
actuator in a PI speed servo limited to the plugin's torque (``sim.drives.DriveBatch`` runs the
servos of all drives at once, before every physics step). Encoder
odometry integrates the wheel angle increments, so it drifts and slips as a real base does;
``odometrySource world`` reports the model's true world pose instead (Gazebo's default).
A ``Twist`` with NaN or infinite components is ignored with a warning and the robot stops; a
robot whose commands stop for ``commandTimeout`` seconds stops (fleetsim addition, 0 disables).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace

import mujoco
import numba
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.runtime.params import param
from fleetsim.sim.contacts import frictionless_wheels
from fleetsim.sim.drives import rotor_armature
from fleetsim.sim.plugins.base import (
    DrivePlugin,
    OdometryReading,
    Plugin,
    SensorPlugin,
    TransformsReading,
    joint_addresses,
    register,
    require_joint,
)
from fleetsim.sim.plugins.joint_state import JointStatePlugin

_log = logging.getLogger("fleetsim.sim.drive")
SERVO_TIME = 0.05  # s, time constant of the wheel speed servo (a motor controller's lag)


@dataclass(frozen=True)
class DiffDriveParams:
    leftJoint: str = param("left_joint", help="left wheel joint")
    rightJoint: str = param("right_joint", help="right wheel joint")
    wheelSeparation: float = param(0.34, unit="m", range=(0.0, None), help="wheel track")
    wheelDiameter: float = param(0.15, unit="m", range=(0.0, None), help="wheel diameter")
    wheelTorque: float = param(5.0, unit="N m", range=(0.0, None), help="max wheel torque")
    wheelAcceleration: float = param(
        0.0, unit="m/s^2", range=(0.0, None), help="wheel speed ramp, 0: unlimited"
    )
    commandTopic: str = param("cmd_vel", help="Twist command topic")
    odometryTopic: str = param("odom", help="Odometry topic")
    odometryFrame: str = param("odom", help="odometry frame (tf_prefix applied)")
    robotBaseFrame: str = param("base_footprint", help="child frame of the odometry")
    odometrySource: str = param(
        "world",
        choices=("world", "encoder"),
        help="world: true pose; encoder: integrated wheel angles",
    )
    publishOdomTF: bool = param(True, help="broadcast odom -> base on /tf")
    publishTf: bool = param(True, help="legacy switch for publishOdomTF")
    publishWheelTF: bool = param(
        False, help="broadcast each wheel's transform from its parent link on /tf at updateRate"
    )
    publishWheelJointState: bool = param(
        False, help="publish the two wheels' joint states on joint_states at updateRate"
    )
    legacyMode: bool = param(True, help="unused (wheel sign convention)")
    updateRate: float = param(100.0, unit="Hz", range=(0.0, None), help="odometry rate")
    commandTimeout: float = param(
        0.5,
        unit="s",
        range=(0.0, None),
        help="stop when no command arrives for this long (0: never)",
    )
    rosDebugLevel: str = param("na", help="unused")


class WheeledDrive(DrivePlugin):
    """Shared logic of the diff-drive and skid-steer plugins (``left``/``right`` joint lists)."""

    left: list[str]
    right: list[str]
    torque: float
    accel: float
    encoder: bool
    publish_tf: bool
    # give the drive wheels a held rotor (``drives.rotor_armature``): skid steer needs it to
    # scrub as Coulomb friction does; a diff drive's wheels roll without scrubbing and keep
    # their bare inertia, so its torque limit bounds the acceleration of the robot alone
    held_rotor: bool = False

    def _setup(self) -> None:
        p = self.params
        for j, key in zip(self.left + self.right, self.joint_params):
            require_joint(self.ctx, j, key, self.name)
        self.frames = (self.ctx.frame(p.odometryFrame), self.ctx.frame(p.robotBaseFrame))
        self.kv = 1.0  # N m s/rad, set from the robot's mass in bind()
        self.sep = p.wheelSeparation
        self.radius = p.wheelDiameter / 2
        self.cmd = (0.0, 0.0)
        self.last_cmd_t = -math.inf
        self.batch = None  # the engine's DriveBatch while bound (holds the live state)
        self.slot = -1
        self.reset()

    def reset(self) -> None:
        self.cmd = (0.0, 0.0)
        self.speed = (0.0, 0.0)  # wheel surface speed targets, m/s (left, right)
        self.integral = [0.0] * (len(self.left) + len(self.right))
        self.pose = (0.0, 0.0, 0.0)  # encoder odometry x, y, yaw in the odom frame
        self.prev_angles: tuple[float, float] | None = None
        self.prev_t: float | None = None
        self.twist = (0.0, 0.0)

    def build(self, spec, engine) -> None:
        if self.held_rotor:
            self._set_rotor_armature(spec)
        # traction only on the floor: a spinning wheel climbed walls and other robots as a tread
        frictionless_wheels(
            [spec.joint(f"{self.ctx.model}/{j}").parent for j in self.left + self.right]
        )
        for j in self.left + self.right:
            a = spec.add_actuator(
                name=f"{self.ctx.model}/{self.name}/{j}",
                target=f"{self.ctx.model}/{j}",
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
            )
            a.set_to_velocity(kv=1.0)  # gain set in bind()
            # no forcerange: a force-limited actuator loses its implicit damping term and goes
            # unstable on light wheels; the torque limit is applied on the target instead

    def _set_rotor_armature(self, spec) -> None:
        """Give the drive wheels their motors' reflected inertia (``drives.rotor_armature``)."""
        robot = self.ctx.robot
        mass = sum(
            link.inertial.mass
            for link in robot.links.values()
            if link.inertial is not None and link.inertial.mass > 0
        )
        joints = [spec.joint(f"{self.ctx.model}/{j}") for j in self.left + self.right]
        mu = max(
            (
                float(g.friction[0])
                for j in joints
                for g in j.parent.geoms
                if g.contype or g.conaffinity
            ),
            default=1.0,
        )
        arm = rotor_armature(
            mass,
            self.radius,
            len(joints),
            mu,
            float(np.linalg.norm(spec.option.gravity)),
            spec.option.timestep,
        )
        for j in joints:
            j.armature = max(float(j.armature), arm)

    def bind(self, engine) -> None:
        m = engine.model
        self.act = np.array(
            [
                mujoco.mj_name2id(
                    m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{self.ctx.model}/{self.name}/{j}"
                )
                for j in self.left + self.right
            ],
            np.int64,
        )
        self.qadr, dadr = joint_addresses(engine, self.ctx.model, self.left + self.right)
        self.root = engine.root_body(self.ctx.model)
        # wheel speed servo gain: the inertia each wheel drives (its share of the robot's mass
        # at the wheel radius) over the servo time constant; stiffer gains rock light robots
        m = engine.model
        mass = float(m.body_subtreemass[self.root])
        n = len(self.left) + len(self.right)
        inertia = mass * self.radius**2 / n + float(m.dof_armature[dadr].mean())
        self.kv = max(inertia / SERVO_TIME, 1e-6)
        for a in self.act:
            m.actuator_gainprm[a, 0] = self.kv
            m.actuator_biasprm[a, 2] = -self.kv
        self.nl = len(self.left)
        self.wheels = [(int(a), int(v)) for a, v in zip(self.act, dadr)]
        self.q_left = [int(a) for a in self.qadr[: self.nl]]
        self.q_right = [int(a) for a in self.qadr[self.nl :]]

    def command(self, vx: float, wz: float, t: float) -> None:
        if not (math.isfinite(vx) and math.isfinite(wz)):
            _log.warning("%s: ignoring non-finite command (%s, %s); stopping", self.where, vx, wz)
            vx = wz = 0.0
        self.cmd = (float(vx), float(wz))
        self.last_cmd_t = t
        if self.batch is not None:
            self.batch.set_command(self.slot, self.cmd[0], self.cmd[1], t)

    @property
    def update_rate(self) -> float:
        return self.params.updateRate

    def measure(self, engine, t: float) -> OdometryReading:
        return self.measure_each(engine, [self], t)[0]

    @classmethod
    def measure_each(cls, engine, plugins: list, t: float) -> list[OdometryReading]:
        """Odometry of many bound drives at once (encoder odometry in one compiled step), in
        the order of ``plugins``; each reading equals what ``measure`` returns for it."""
        batch = engine.drives
        enc = [p for p in plugins if p.encoder]
        parts = {}
        if enc:
            if any(p.batch is not batch for p in enc):
                p = next(p for p in enc if p.batch is not batch)
                raise SimulationError(f"{p.where}: the drive is not spawned in this engine")
            slots = np.fromiter((p.slot for p in enc), np.int64, len(enc))
            out = batch.encoder_odometry(slots, t)
            rows = zip(out[:, 0:3], out[:, 3:7], out[:, 7:10], out[:, 10:13])
            parts = dict(zip(map(id, enc), rows))
        true = [p for p in plugins if not p.encoder]
        if true:
            roots = np.fromiter((p.root for p in true), np.int64, len(true))
            pos, quat, lin, ang = true_odometries(engine.model, engine.data, roots)
            parts.update(zip(map(id, true), zip(pos, quat, lin, ang)))
        readings = []
        for p in plugins:
            pos, quat, lin, ang = parts[id(p)]
            readings.append(
                OdometryReading(
                    t,
                    p.params.odometryTopic,
                    p.frames[0],
                    p.frames[1],
                    pos,
                    quat,
                    lin,
                    ang,
                    p.publish_tf,
                    namespace=p.ctx.namespace,
                )
            )
        return readings


@register("libgazebo_ros_diff_drive.so")
class DiffDrivePlugin(WheeledDrive):
    Params = DiffDriveParams
    joint_params = ("leftJoint", "rightJoint")

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        p = self.params
        self.left, self.right = [p.leftJoint], [p.rightJoint]
        self.torque = p.wheelTorque
        self.accel = p.wheelAcceleration
        self.encoder = p.odometrySource == "encoder"
        self.publish_tf = p.publishOdomTF and p.publishTf
        self._geometry_checked = False  # once: every spawn rebinds every plugin
        self._setup()

    def companions(self) -> list[Plugin]:
        """With ``publishWheelJointState``, a joint state publisher of the two wheels on
        ``joint_states`` at ``updateRate``, as gazebo_ros_diff_drive's (which publishes their
        positions; velocities and efforts come along here), so robot_state_publisher places
        the wheels without a joint_state_publisher node (turtlebot3_gazebo's launch files).
        With ``publishWheelTF``, the wheels' transforms on ``/tf`` at the same rate."""
        p = self.params
        out: list[Plugin] = []
        if p.publishWheelJointState:
            joints = {"jointName": f"{p.leftJoint}, {p.rightJoint}", "topicName": "joint_states"}
            spec = replace(
                self.spec,
                name=f"{self.spec.name}/wheel_joint_states",
                params={**joints, "updateRate": str(p.updateRate)},
            )
            out.append(JointStatePlugin(self.ctx, spec))
        if p.publishWheelTF:
            out.append(WheelTfPlugin(self, p.updateRate))
        return out

    def bind(self, engine) -> None:
        super().bind(engine)
        if not self._geometry_checked:
            self._geometry_checked = True
            self._check_geometry(engine)

    def _check_geometry(self, engine) -> None:
        """Warn when ``wheelSeparation`` or ``wheelDiameter`` is far (more than
        `GEOMETRY_TOLERANCE`) from the model's own: the wheel joints' distance along the axle,
        the wheel's collision cylinder or sphere. Gazebo takes them as given, so a value in
        the wrong unit (30 for 0.30 m) only shows as odometry that drifts and turns that
        overshoot; a robot whose collision wheel differs on purpose keeps its value."""
        m, d, p = engine.model, engine.data, self.params
        ids = [
            mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{self.ctx.model}/{j}")
            for j in (p.leftJoint, p.rightJoint)
        ]
        axle = d.xaxis[ids[0]]
        track = abs(float(np.dot(d.xanchor[ids[0]] - d.xanchor[ids[1]], axle)))
        if track > 1e-3 and abs(p.wheelSeparation - track) > GEOMETRY_TOLERANCE * track:
            _log.warning(
                "%s: wheelSeparation %g m, but the joints '%s' and '%s' are %.3f m apart along "
                "the axle: odometry and turns will be off (wheelSeparation is in metres)",
                self.where, p.wheelSeparation, p.leftJoint, p.rightJoint, track,
            )  # fmt: skip
        body = m.jnt_bodyid[ids[0]]
        radii = [
            float(m.geom_size[g, 0])
            for g in range(m.body_geomadr[body], m.body_geomadr[body] + m.body_geomnum[body])
            if m.geom_contype[g] or m.geom_conaffinity[g]
            if int(m.geom_type[g]) in ROUND_GEOMS
        ]
        if len(radii) == 1 and abs(p.wheelDiameter - 2 * radii[0]) > GEOMETRY_TOLERANCE * (
            2 * radii[0]
        ):
            _log.warning(
                "%s: wheelDiameter %g m, but the wheel of joint '%s' collides as a %.3f m "
                "diameter: speeds and odometry will be off (wheelDiameter is in metres)",
                self.where, p.wheelDiameter, p.leftJoint, 2 * radii[0],
            )  # fmt: skip


#: relative difference between a diff drive's wheelSeparation/wheelDiameter and the model's
#: own geometry above which it is warned about
GEOMETRY_TOLERANCE = 0.25
#: a wheel's collision geometry whose first size is its radius
ROUND_GEOMS = (int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_SPHERE))


def true_odometries(model, data, roots: np.ndarray) -> tuple[np.ndarray, ...]:
    """World poses and body-frame twists of the bodies ``roots`` ((B,) int64 body ids), as
    ``mj_objectVelocity(..., mjOBJ_XBODY, root, vel, flg_local=1)`` gives them one body at a
    time, bit for bit: the same operations in MuJoCo's order (``mju_transformSpatial``: the
    com-based velocity moved to the body's origin, then rotated into its frame), over the batch.

    Returns
    -------
    pos : (B, 3) m, world; quat : (B, 4) x, y, z, w, world;
    lin : (B, 3) m/s and ang : (B, 3) rad/s, in each body's frame.
    """
    out = _true_odometries(
        data.xpos, data.xquat, data.xmat, data.cvel, data.subtree_com, model.body_rootid, roots
    )
    return out[:, 0:3], out[:, 3:7], out[:, 7:10], out[:, 10:13]


@numba.njit(cache=True)
def _true_odometries(xpos, xquat, xmat, cvel, subtree_com, rootid, roots):
    """`true_odometries` as one (B, 13) array (pos, quat x y z w, lin, ang), compiled: drive
    odometry runs at 100 Hz per robot and the NumPy batch's two dozen small-array calls cost
    ~40 us each time."""
    n = roots.shape[0]
    out = np.empty((n, 13))
    for i in range(n):
        k = roots[i]
        c = rootid[k]
        w0, w1, w2 = cvel[k, 0], cvel[k, 1], cvel[k, 2]
        d0 = xpos[k, 0] - subtree_com[c, 0]
        d1 = xpos[k, 1] - subtree_com[c, 1]
        d2 = xpos[k, 2] - subtree_com[c, 2]
        # linear velocity at the body's origin: v - dif x w
        v0 = cvel[k, 3] - (d1 * w2 - d2 * w1)
        v1 = cvel[k, 4] - (d2 * w0 - d0 * w2)
        v2 = cvel[k, 5] - (d0 * w1 - d1 * w0)
        r = xmat[k]  # row-major body-to-world; R^T v in the body frame
        out[i, 0], out[i, 1], out[i, 2] = xpos[k, 0], xpos[k, 1], xpos[k, 2]
        out[i, 3], out[i, 4] = xquat[k, 1], xquat[k, 2]
        out[i, 5], out[i, 6] = xquat[k, 3], xquat[k, 0]
        out[i, 7] = r[0] * v0 + r[3] * v1 + r[6] * v2
        out[i, 8] = r[1] * v0 + r[4] * v1 + r[7] * v2
        out[i, 9] = r[2] * v0 + r[5] * v1 + r[8] * v2
        out[i, 10] = r[0] * w0 + r[3] * w1 + r[6] * w2
        out[i, 11] = r[1] * w0 + r[4] * w1 + r[7] * w2
        out[i, 12] = r[2] * w0 + r[5] * w1 + r[8] * w2
    return out


@dataclass(frozen=True)
class _NoParams:
    """The wheels' transforms have no parameters of their own: the drive's are used."""


class WheelTfPlugin(SensorPlugin):
    """A diff drive's ``publishWheelTF``: each wheel link's transform from its joint's parent
    link on ``/tf`` at the drive's ``updateRate``, as gazebo_ros_diff_drive broadcasts them
    (its transform is the wheel's pose relative to the model, which is the parent link's
    frame when the parent is the root; here it is the parent link's, as tf's tree needs)."""

    Params = _NoParams

    def __init__(self, drive: DiffDrivePlugin, rate: float) -> None:
        spec = replace(drive.spec, name=f"{drive.spec.name}/wheel_tf", params={})
        super().__init__(drive.ctx, spec)
        self.rate = rate
        self.joints = [drive.params.leftJoint, drive.params.rightJoint]
        joints = [drive.ctx.robot.joints[j] for j in self.joints]
        self.frames = [(drive.ctx.frame(j.parent), drive.ctx.frame(j.child)) for j in joints]

    @property
    def update_rate(self) -> float:
        return self.rate

    def bind(self, engine) -> None:
        m = engine.model
        ids = [engine.joint_id(self.ctx.model, j) for j in self.joints]
        self.qadr = [int(m.jnt_qposadr[j]) for j in ids]
        self.axes = [m.jnt_axis[j].copy() for j in ids]
        bodies = [int(m.jnt_bodyid[j]) for j in ids]
        self.origins = [(m.body_pos[b].copy(), m.body_quat[b].copy()) for b in bodies]

    def measure(self, engine, t: float) -> TransformsReading:
        # from the joint angle, not the bodies' world poses: those are the kinematics of the
        # step's start, one step behind the angle that the wheels' joint states report
        q = engine.data.qpos
        out = []
        for (pf, cf), adr, axis, (pos, origin) in zip(
            self.frames, self.qadr, self.axes, self.origins
        ):
            spin, quat = np.empty(4), np.empty(4)
            mujoco.mju_axisAngle2Quat(spin, axis, q[adr])
            mujoco.mju_mulQuat(quat, origin, spin)
            out.append((pf, cf, pos.copy(), quat[[1, 2, 3, 0]]))
        return TransformsReading(t, out, self.ctx.namespace)
