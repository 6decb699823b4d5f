"""Planar laser (``libgazebo_ros_laser.so``, ``libgazebo_ros_gpu_laser.so``) in a ray sensor.

Beam geometry comes from the enclosing ``<sensor type="ray">``: ``scan/horizontal`` samples,
min_angle, max_angle; ``range`` min, max; ``noise`` gaussian mean, stddev; ``update_rate``.
Rays are cast in the horizontal plane at the sensor's height, along its heading; the casting (and
the noise) is batched over all lasers by ``fleetsim.sim.lasers.LaserBatch``. No hit within
range: ``inf``. Under the simulator node a laser casts only while its topic has a subscriber,
as gazebo_ros_laser activates its sensor on the first connection.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.runtime.params import param
from fleetsim.sim.build import quat_from_rpy
from fleetsim.sim.plugins.base import ScanReading, SensorPlugin, register, require_link


@dataclass(frozen=True)
class LaserParams:
    topicName: str = param("/world", help="scan topic (relative to the robot namespace)")
    frameName: str = param("/world", help="frame_id of the scans (tf_prefix applied)")
    gaussianNoise: float = param(0.0, unit="m", range=(0.0, None), help="unused (sensor noise)")
    updateRate: float = param(
        0.0, unit="Hz", range=(0.0, None), help="unused: the sensor's <update_rate> sets the rate"
    )
    hokuyoMinIntensity: float = param(101.0, help="unused")


def _num(d: dict, path: str, default: float, where: str) -> float:
    cur = d
    for k in path.split("/"):
        if not isinstance(cur, dict) or k not in cur:
            return default
        cur = cur[k]
    try:
        return float(cur)
    except (TypeError, ValueError):
        raise SimulationError(
            f"{where}: sensor field '{path}' must be a number, got '{cur}'"
        ) from None


@register("libgazebo_ros_laser.so", "libgazebo_ros_gpu_laser.so", "libgazebo_ros_ray_sensor.so")
class LaserPlugin(SensorPlugin):
    Params = LaserParams
    is_laser = True
    #: set by the simulator node: True while the scan topic has a subscriber (None: always
    #: cast). As gazebo_ros_laser ("sensor generation off by default", on while connected),
    #: a laser nobody listens to casts no rays and draws no noise.
    wanted = None

    def __init__(self, ctx, spec, sensor=None) -> None:
        super().__init__(ctx, spec, sensor)
        if sensor is None:
            raise SimulationError(f"{self.where}: a laser plugin must sit inside a <sensor>")
        w = f"{self.where} sensor '{sensor.name}'"
        ray = sensor.ray or {}
        self.samples = int(_num(ray, "scan/horizontal/samples", 640, w))
        self.angle_min = _num(ray, "scan/horizontal/min_angle", 0.0, w)
        self.angle_max = _num(ray, "scan/horizontal/max_angle", 0.0, w)
        self.range_min = _num(ray, "range/min", 0.0, w)
        self.range_max = _num(ray, "range/max", 0.0, w)
        self.noise_mean = _num(ray, "noise/mean", 0.0, w)
        self.noise_std = _num(ray, "noise/stddev", 0.0, w)
        if self.samples < 1 or self.range_max <= self.range_min:
            raise SimulationError(
                f"{w}: needs samples >= 1 and range max > min; got samples {self.samples}, "
                f"range [{self.range_min}, {self.range_max}]"
            )
        self.link = require_link(ctx, sensor.reference, "the sensor reference", spec.name)
        self.rate = float(sensor.update_rate)
        self.pos = np.array(sensor.pose.xyz, float)
        self.quat = quat_from_rpy(*sensor.pose.rpy)
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, self.quat)
        self.xaxis = rot.reshape(3, 3)[:, 0].copy()  # the sensor's x axis in its link frame
        self.zaxis = rot.reshape(3, 3)[:, 2].copy()  # and its z axis (down: mounted upside down)
        self.frame_id = ctx.frame(self.params.frameName)

    @property
    def update_rate(self) -> float:
        return self.rate

    def bind(self, engine) -> None:
        self.body = engine.link_id(self.ctx.model, self.link)
        self.owner = engine._model_names.index(self.ctx.model)

    @property
    def increment(self) -> float:
        return (self.angle_max - self.angle_min) / max(self.samples - 1, 1)

    def pose(self, engine) -> tuple[np.ndarray, float, float, int]:
        """World origin (3,) m, world yaw of the first beam (rad), world angle between beams
        (rad; negative for a laser mounted upside down, whose beams sweep clockwise seen from
        above), owner model index."""
        d = engine.data
        R = d.xmat[self.body].reshape(3, 3)
        origin = d.xpos[self.body] + R @ self.pos
        x, z = R @ self.xaxis, R @ self.zaxis
        sign = -1.0 if z[2] < 0 else 1.0
        yaw = float(np.arctan2(x[1], x[0]))
        return origin, yaw + sign * self.angle_min, sign * self.increment, self.owner

    def rays(self, engine):
        """World ray origins (S, 3), world yaws (S,) and the owner model index."""
        origin, a0, inc, owner = self.pose(engine)
        return np.tile(origin, (self.samples, 1)), a0 + inc * np.arange(self.samples), owner

    scans_taken = 0  # readings taken so far: each one's noise has its own stream

    def reading(self, ranges: np.ndarray | Callable[[], np.ndarray], t: float) -> ScanReading:
        """A scan of ``ranges`` ((samples,) float32 m, noise already applied by the batch), or
        of the function that casts them when they are first read."""
        return ScanReading(
            t,
            self.params.topicName,
            self.frame_id,
            self.angle_min,
            self.angle_max,
            self.increment,
            0.0,
            1.0 / self.rate if self.rate > 0 else 0.0,
            self.range_min,
            self.range_max,
            ranges,
            _NO_INTENSITIES,
        )


_NO_INTENSITIES = np.zeros(0, np.float32)  # shared by every scan: empty, nothing to change
