"""The wheel speed servos and encoder odometry of every wheeled drive (diff drive, skid steer)
in one compiled step each.

Each wheel has a velocity actuator (the proportional part, integrated implicitly by MuJoCo) whose
target is shifted by an integral term; the sum is clamped so that the torque stays within the
plugin's limit (anti-windup). Per plugin: command timeout, wheel speed ramp
(``wheelAcceleration``), differential-drive kinematics. While bound, the batch keeps the
commands, servo and odometry state of all drives in arrays (no per-step gathering) and writes it
back to the plugins before the world is rebuilt.
"""

from __future__ import annotations

import math

import numba
import numpy as np

INTEGRAL_TIME = 0.1  # s, integral time of the servo (holds speed against scrub and slopes)
# m/s: the most that full ground friction may change a drive wheel's surface speed in one physics
# step (sets the rotor armature, see ``rotor_armature``)
SLIP_RESOLUTION = 0.005


def rotor_armature(
    mass: float, radius: float, n_wheels: int, mu: float, gravity: float, timestep: float
) -> float:
    """Reflected rotor inertia of a drive wheel that lets the contact solver see a held wheel.

    Gazebo's wheel motor is a velocity constraint solved together with the contacts, so the
    ground cannot change a driven wheel's speed below the torque limit. The servo here is a
    force element that MuJoCo's constraint solver does not see: it treats the bare wheel
    inertia as free, finds that a small part of the friction cone stops the wheel's slip within
    one step, and spends the rest on the sideways direction. A skid-steer robot then scrubs
    sideways at full friction and barely turns (0.1 of the commanded rate instead of the
    Coulomb ``b^2 / (a^2 + b^2)``). A geared motor's rotor inertia, reflected to the wheel,
    is what holds a real wheel's speed over short times; this is the smallest such inertia
    with which full friction on the wheel (``mu * mass * gravity / n_wheels``) changes the
    wheel's surface speed by at most ``SLIP_RESOLUTION`` over one ``timestep``.

    Parameters
    ----------
    mass : whole robot mass, kg. radius : wheel radius, m. n_wheels : drive wheels sharing
    the load. mu : wheel friction coefficient. gravity : m/s^2. timestep : physics step, s.

    Returns
    -------
    float : armature of the wheel joint, kg m^2 (0 for a massless robot or no gravity).
    """
    load = mu * mass * abs(gravity) / max(n_wheels, 1)  # N, friction on one wheel
    return load * radius**2 * timestep / SLIP_RESOLUTION


class DriveBatch:
    """Servo, command and encoder-odometry state of every wheeled drive, as arrays.

    While bound, the arrays are the state (a drive's ``command`` writes its row); ``sync_back``
    stores it in the plugins before the world is rebuilt and ``reload`` takes it back (after
    ``bind`` or a reset).
    """

    def __init__(self) -> None:
        self.drives: list = []

    def bind(self, drives: list, engine) -> None:
        """Gather the drives' wheels (after every compile, once the drives are bound)."""
        for d in self.drives:
            d.batch = None
        self.drives = drives
        if not drives:
            return
        for i, d in enumerate(drives):
            d.batch, d.slot = self, i
        wheels = [
            (a, v, i, 0 if k < d.nl else 1, d.radius, d.torque / d.kv)
            for i, d in enumerate(drives)
            for k, (a, v) in enumerate(d.wheels)
        ]
        cols = list(zip(*wheels))
        self.acts = np.array(cols[0], np.int64)
        self.dofs = np.array(cols[1], np.int64)
        self.owner = np.array(cols[2], np.int64)
        self.side = np.array(cols[3], np.int64)
        self.radius = np.array(cols[4])
        self.limit = np.array(cols[5])
        self.half_sep = np.array([d.sep / 2 for d in drives])
        self.accel = np.array([d.accel for d in drives])
        self.timeout = np.array([d.params.commandTimeout for d in drives])
        # encoder odometry: qpos addresses of each drive's wheels (left ones first)
        self.wheel_q = np.array([q for d in drives for q in d.q_left + d.q_right], np.int64)
        self.wheel_start = np.cumsum([0] + [len(d.wheels) for d in drives]).astype(np.int64)
        self.n_left = np.array([d.nl for d in drives], np.int64)
        self.wheel_radius = np.array([d.radius for d in drives])
        self.sep = np.array([d.sep for d in drives])
        self.dt = float(engine.model.opt.timestep)
        self.qpos, self.qvel, self.ctrl = engine.data.qpos, engine.data.qvel, engine.data.ctrl
        self.reload()

    def reload(self) -> None:
        """Take the servo, command and odometry state from the plugins (after bind or a reset)."""
        if not self.drives:
            return
        ds = self.drives
        n = len(ds)
        self.cmd = np.array([d.cmd for d in ds], float).reshape(n, 2)
        self.last = np.array([d.last_cmd_t for d in ds], float)
        self.speed = np.array([d.speed for d in ds], float).reshape(n, 2)
        self.integral = np.concatenate([np.asarray(d.integral, float) for d in ds])
        self.pose = np.array([d.pose for d in ds], float).reshape(n, 3)
        self.twist = np.array([d.twist for d in ds], float).reshape(n, 2)
        self.has_prev = np.array([d.prev_angles is not None for d in ds])
        self.prev = np.array([d.prev_angles or (0.0, 0.0) for d in ds], float).reshape(n, 2)
        self.prev_t = np.array([d.prev_t if d.prev_t is not None else 0.0 for d in ds], float)

    def sync_back(self) -> None:
        """Store the servo, command and odometry state in the plugins (before a recompile)."""
        k = 0
        for i, d in enumerate(self.drives):
            n = len(d.wheels)
            d.cmd = (float(self.cmd[i, 0]), float(self.cmd[i, 1]))
            d.last_cmd_t = float(self.last[i])
            d.speed = (float(self.speed[i, 0]), float(self.speed[i, 1]))
            d.integral = self.integral[k : k + n].tolist()
            d.pose = tuple(float(v) for v in self.pose[i])
            d.twist = (float(self.twist[i, 0]), float(self.twist[i, 1]))
            if self.has_prev[i]:
                d.prev_angles = (float(self.prev[i, 0]), float(self.prev[i, 1]))
                d.prev_t = float(self.prev_t[i])
            else:
                d.prev_angles = d.prev_t = None
            k += n

    def set_command(self, slot: int, vx: float, wz: float, t: float) -> None:
        self.cmd[slot, 0] = vx
        self.cmd[slot, 1] = wz
        self.last[slot] = t

    def control(self, engine, t: float) -> None:
        """Set every drive wheel's actuator target for the next physics step."""
        if not self.drives:
            return
        servo_targets(
            self.cmd,
            self.last,
            t,
            self.timeout,
            self.half_sep,
            self.accel,
            self.dt,
            self.speed,
            self.owner,
            self.side,
            self.radius,
            self.limit,
            self.integral,
            self.qvel,
            self.ctrl,
            self.acts,
            self.dofs,
        )

    def encoder_odometry(self, slots: np.ndarray, t: float) -> np.ndarray:
        """Advance the encoder odometry of the drives in ``slots`` to time ``t``.

        Returns
        -------
        (K, 13) float64 rows: position (3,) m, quaternion x, y, z, w (4,), linear (3,) m/s and
        angular (3,) rad/s velocity, in the odometry frame / base frame as ``OdometryReading``.
        """
        out = np.empty((len(slots), 13))
        odometry_from_encoders(
            self.qpos,
            self.wheel_q,
            self.wheel_start,
            self.n_left,
            self.wheel_radius,
            self.sep,
            slots,
            t,
            self.pose,
            self.twist,
            self.prev,
            self.has_prev,
            self.prev_t,
            out,
        )
        return out


@numba.njit(cache=True)
def odometry_from_encoders(
    qpos,
    wheel_q,
    wheel_start,
    n_left,
    radius,
    sep,
    slots,
    t,
    pose,
    twist,
    prev,
    has_prev,
    prev_t,
    out,
):
    """Integrate wheel-angle increments into odometry (the gazebo_ros wheel odometry).

    Parameters
    ----------
    qpos : MuJoCo joint positions. wheel_q : (W,) qpos address of every wheel, drive by drive,
    left wheels first; wheel_start : (P + 1,) each drive's first wheel; n_left : (P,) left wheels.
    radius, sep : (P,) wheel radius and separation, m. slots : (K,) drives to advance.
    t : sim time, s. pose : (P, 3) x, y (m), yaw (rad) in the odom frame; twist : (P, 2) m/s,
    rad/s; prev : (P, 2) last mean wheel angles (rad), valid where ``has_prev`` (P,); prev_t :
    (P,) time of those angles, s (all updated in place). out : (K, 13) readings, see
    ``DriveBatch.encoder_odometry``.

    A drive's first reading only stores the angles (zero pose and twist), as the plugin does.
    """
    for k in range(slots.shape[0]):
        i = slots[k]
        a, nl, b = wheel_start[i], n_left[i], wheel_start[i + 1]
        left = 0.0
        for j in range(a, a + nl):
            left += qpos[wheel_q[j]]
        left /= nl
        right = 0.0
        for j in range(a + nl, b):
            right += qpos[wheel_q[j]]
        right /= b - a - nl
        if has_prev[i]:
            dl = (left - prev[i, 0]) * radius[i]
            dr = (right - prev[i, 1]) * radius[i]
            ds = (dl + dr) / 2
            dth = (dr - dl) / sep[i]
            mid = pose[i, 2] + dth / 2
            pose[i, 0] = pose[i, 0] + ds * math.cos(mid)
            pose[i, 1] = pose[i, 1] + ds * math.sin(mid)
            pose[i, 2] = pose[i, 2] + dth
            dt = t - prev_t[i]
            if dt > 0:
                twist[i, 0] = ds / dt
                twist[i, 1] = dth / dt
        has_prev[i] = True
        prev[i, 0] = left
        prev[i, 1] = right
        prev_t[i] = t
        yaw = pose[i, 2]
        out[k, 0] = pose[i, 0]
        out[k, 1] = pose[i, 1]
        out[k, 2] = 0.0
        out[k, 3] = 0.0
        out[k, 4] = 0.0
        out[k, 5] = math.sin(yaw / 2)
        out[k, 6] = math.cos(yaw / 2)
        out[k, 7] = twist[i, 0]
        out[k, 8] = 0.0
        out[k, 9] = 0.0
        out[k, 10] = 0.0
        out[k, 11] = 0.0
        out[k, 12] = twist[i, 1]


@numba.njit(cache=True)
def servo_targets(
    cmd,
    last,
    t,
    timeout,
    half_sep,
    accel,
    dt,
    speed,
    owner,
    side,
    radius,
    limit,
    integral,
    qvel,
    ctrl,
    acts,
    dofs,
):
    """Wheel actuator targets of all drives (updates ``speed``, ``integral``, ``ctrl``).

    Parameters
    ----------
    cmd : (P, 2) commanded linear (m/s) and angular (rad/s) speed per drive.
    last : (P,) sim time of each drive's last command, s; ``timeout`` (P,) s (0: none).
    half_sep : (P,) half wheel separation, m; accel : (P,) wheel ramp, m/s^2 (0: none).
    speed : (P, 2) wheel surface speed targets (left, right), m/s, ramp state.
    owner, side : (W,) drive index and side (0 left, 1 right) of each wheel.
    radius, limit : (W,) wheel radius (m) and the speed error at the torque limit (rad/s).
    integral : (W,) integral state of the servo, rad/s.
    qvel, ctrl : the MuJoCo data arrays; acts, dofs : (W,) actuator and dof of each wheel.
    """
    for i in range(cmd.shape[0]):
        vx = cmd[i, 0]
        wz = cmd[i, 1]
        if timeout[i] > 0 and t - last[i] > timeout[i]:
            vx = 0.0
            wz = 0.0
        for k in range(2):
            target = vx - wz * half_sep[i] if k == 0 else vx + wz * half_sep[i]
            if accel[i] > 0:
                dv = accel[i] * dt
                target = speed[i, k] + min(max(target - speed[i, k], -dv), dv)
            speed[i, k] = target
    gain = dt / INTEGRAL_TIME
    for j in range(acts.shape[0]):
        w = qvel[dofs[j]]
        err = speed[owner[j], side[j]] / radius[j] - w
        lim = limit[j]
        integral[j] = min(max(integral[j] + err * gain, -lim - err), lim - err)
        ctrl[acts[j]] = w + min(max(err + integral[j], -lim), lim)
