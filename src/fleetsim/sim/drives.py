"""The wheel speed servos of every wheeled drive (diff drive, skid steer) in one NumPy step.

Each wheel has a velocity actuator (the proportional part, integrated implicitly by MuJoCo) whose
target is shifted by an integral term; the sum is clamped so that the torque stays within the
plugin's limit (anti-windup). Per plugin: command timeout, wheel speed ramp
(``wheelAcceleration``), differential-drive kinematics. The plugins keep their commands; the
batch keeps the servo state while bound and writes it back before the world is rebuilt.
"""

from __future__ import annotations

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
    def __init__(self) -> None:
        self.drives: list = []

    def bind(self, drives: list) -> None:
        """Gather the drives' wheels (after every compile, once the drives are bound)."""
        self.drives = drives
        if not drives:
            return
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
        self.reload()

    def reload(self) -> None:
        """Take the servo state from the plugins (after bind or a reset)."""
        if self.drives:
            self.speed = np.array([d.speed for d in self.drives], float).reshape(-1, 2)
            self.integral = np.concatenate([np.asarray(d.integral, float) for d in self.drives])

    def sync_back(self) -> None:
        """Store the servo state in the plugins (before the world is recompiled)."""
        k = 0
        for i, d in enumerate(self.drives):
            n = len(d.wheels)
            d.speed = (float(self.speed[i, 0]), float(self.speed[i, 1]))
            d.integral = self.integral[k : k + n].tolist()
            k += n

    def control(self, engine, t: float) -> None:
        """Set every drive wheel's actuator target for the next physics step."""
        if not self.drives:
            return
        n = len(self.drives)
        cmd = np.array([d.cmd for d in self.drives], float).reshape(n, 2)
        last = np.fromiter((d.last_cmd_t for d in self.drives), float, n)
        servo_targets(
            cmd,
            last,
            t,
            self.timeout,
            self.half_sep,
            self.accel,
            engine.model.opt.timestep,
            self.speed,
            self.owner,
            self.side,
            self.radius,
            self.limit,
            self.integral,
            engine.data.qvel,
            engine.data.ctrl,
            self.acts,
            self.dofs,
        )


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
