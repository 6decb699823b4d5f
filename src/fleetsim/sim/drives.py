"""The wheel speed servos of every wheeled drive (diff drive, skid steer) in one NumPy step.

Each wheel has a velocity actuator (the proportional part, integrated implicitly by MuJoCo) whose
target is shifted by an integral term; the sum is clamped so that the torque stays within the
plugin's limit (anti-windup). Per plugin: command timeout, wheel speed ramp
(``wheelAcceleration``), differential-drive kinematics. The plugins keep their commands; the
batch keeps the servo state while bound and writes it back before the world is rebuilt.
"""

from __future__ import annotations

import numpy as np

INTEGRAL_TIME = 0.1  # s, integral time of the servo (holds speed against scrub and slopes)


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
        cmd[(self.timeout > 0) & (t - last > self.timeout)] = 0.0
        target = np.empty((n, 2))
        target[:, 0] = cmd[:, 0] - cmd[:, 1] * self.half_sep
        target[:, 1] = cmd[:, 0] + cmd[:, 1] * self.half_sep
        dt = engine.model.opt.timestep
        ramp = self.accel > 0
        if ramp.any():
            dv = (self.accel * dt)[:, None]
            ramped = self.speed + np.clip(target - self.speed, -dv, dv)
            target = np.where(ramp[:, None], ramped, target)
        self.speed = target
        qvel, ctrl = engine.data.qvel, engine.data.ctrl
        w = qvel[self.dofs]
        err = target[self.owner, self.side] / self.radius - w
        lim = self.limit
        self.integral = np.clip(self.integral + err * (dt / INTEGRAL_TIME), -lim - err, lim - err)
        ctrl[self.acts] = w + np.clip(err + self.integral, -lim, lim)
