"""A synthetic world for the SLAM tests: axis-aligned boxes, their true occupancy, exact scans,
and a fake robot node publishing drifting odometry tf and 360-beam scans at 10 Hz (another
robot in its view: a disc, ``peer_disc``)."""

from __future__ import annotations

import numpy as np

from fleetsim.msgs import sensor_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.runtime import Node
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster, make_transform_stamped

# (xmin, ymin, xmax, ymax), m: outer walls of a 12 x 8 m room, then asymmetric obstacles
BOXES = np.array(
    [
        [0.0, 0.0, 12.0, 0.2],
        [0.0, 7.8, 12.0, 8.0],
        [0.0, 0.0, 0.2, 8.0],
        [11.8, 0.0, 12.0, 8.0],
        [4.0, 0.2, 4.2, 3.0],
        [8.0, 5.0, 8.2, 7.8],
        [9.0, 1.5, 10.5, 2.5],
        [2.0, 5.5, 3.0, 6.0],
    ]
)
LASER = np.array([0.15, 0.0, 0.0])  # laser in base_link


def true_occupied(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Whether points (m) lie inside a box."""
    occ = np.zeros(np.broadcast(x, y).shape, dtype=bool)
    for x0, y0, x1, y1 in BOXES:
        occ |= (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
    return occ


def exact_ranges(pose, angles, max_range):
    """(B,) exact ranges from sensor pose ``(x, y, yaw)``; inf beyond ``max_range``."""
    a = pose[2] + np.asarray(angles, dtype=float)
    dx, dy = np.cos(a), np.sin(a)
    best = np.full(len(a), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for x0, y0, x1, y1 in BOXES:
            tx1, tx2 = (x0 - pose[0]) / dx, (x1 - pose[0]) / dx
            ty1, ty2 = (y0 - pose[1]) / dy, (y1 - pose[1]) / dy
            tmin = np.maximum(np.minimum(tx1, tx2), np.minimum(ty1, ty2))
            tmax = np.minimum(np.maximum(tx1, tx2), np.maximum(ty1, ty2))
            hit = (tmax >= tmin) & (tmax > 0) & ~np.isnan(tmin)
            t = np.where(tmin > 0, tmin, 0.0)
            best = np.where(hit & (t < best), t, best)
    return np.where(best <= max_range, best, np.inf)


def disc_ranges(pose, angles, centre, radius):
    """(B,) ranges from sensor pose ``(x, y, yaw)`` to a disc (another robot); inf if missed."""
    a = pose[2] + np.asarray(angles, dtype=float)
    dx, dy = np.cos(a), np.sin(a)
    ox, oy = pose[0] - centre[0], pose[1] - centre[1]
    b = ox * dx + oy * dy
    disc = b * b - (ox * ox + oy * oy - radius * radius)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc >= 0) & (t > 0), t, np.inf)


# a loop through free space, about 30 m
ROUTE = np.array([[1.5, 1.5], [3.0, 1.5], [3.0, 4.0], [7.0, 4.0], [7.0, 1.2], [11.0, 1.2],
                  [11.0, 4.0], [7.0, 4.0], [7.0, 6.8], [4.0, 6.8], [1.0, 4.0]])  # fmt: skip


def drive(waypoints, rng, speed=0.5, turn=1.0, dt=0.1, odom_noise=0.02, odom_bias=0.02):
    """Yield ``(true_pose, odom_pose)`` each ``dt`` along ``waypoints`` (turn, then drive).

    Odometry integrates the body-frame steps scaled by ``1 + bias + noise`` and with a yaw
    bias, so it drifts like wheel odometry; it starts at the origin of the odom frame.
    """
    true = np.array([*waypoints[0], 0.0])
    odom = np.zeros(3)
    yield true.copy(), odom.copy()
    for target in waypoints[1:]:
        while True:
            d = target - true[:2]
            dist = float(np.hypot(*d))
            if dist < 1e-6:
                break
            err = (np.arctan2(d[1], d[0]) - true[2] + np.pi) % (2 * np.pi) - np.pi
            if abs(err) > 1e-3:
                step = np.array([0.0, 0.0, np.clip(err, -turn * dt, turn * dt)])
            else:
                step = np.array([min(speed * dt, dist), 0.0, 0.0])
            c, s = np.cos(true[2]), np.sin(true[2])
            true = true + np.array([c * step[0], s * step[0], step[2]])
            k = 1.0 + odom_bias + odom_noise * rng.standard_normal()
            ostep = np.array([step[0] * k, 0.0, step[2] * k + 0.01 * step[0]])
            c, s = np.cos(odom[2]), np.sin(odom[2])
            odom = odom + np.array([c * ostep[0], s * ostep[0], ostep[2]])
            yield true.copy(), odom.copy()


class FakeRobot(Node):
    """Drives ``route``; odometry tf, a static laser tf and scans at 10 Hz."""

    def __init__(
        self, rt, ns="/", route=ROUTE, seed=0, beams=360, laser_rpy=(0.0, 0.0, 0.0),
        laser_tf_at=0.0,
    ):  # fmt: skip
        """``laser_tf_at``: sim time (s) the static laser transform is sent at (None: never)."""
        super().__init__(rt, "fake_robot", ns)
        self.rng = np.random.default_rng(seed)
        self.steps = drive(np.asarray(route, float), self.rng)
        self.true, self.odom = next(self.steps)
        self.beams = beams
        self.trajectory = []  # (time, true pose)
        self.tf = TransformBroadcaster(self)
        r, p, y = laser_rpy
        q = _quat(r, p, y)
        laser_tf = make_transform_stamped(
            self.frame("base_link"), self.frame("laser"), 0.0, LASER, q
        )
        if laser_tf_at == 0.0:
            StaticTransformBroadcaster(self).send_transform(laser_tf)
        elif laser_tf_at is not None:
            static = StaticTransformBroadcaster(self)

            def send_laser_tf():
                if self.now() >= laser_tf_at and not self._laser_sent:
                    static.send_transform(laser_tf)
                    self._laser_sent = True

            self._laser_sent = False
            self.create_timer(0.05, send_laser_tf)
        self.flip = r != 0.0
        self.peer_disc: tuple[float, float, float] | None = None  # (x, y, radius) in view, m
        self.scan_pub = self.create_publisher(sensor_msgs.LaserScan, "scan", queue_size=1)
        self.create_timer(0.1, self.tick, priority=-50)
        self.tick()

    def tick(self):
        if self.now() > 0:
            self.true, self.odom = next(self.steps, (self.true, self.odom))
        t = self.now()
        self.trajectory.append((t, self.true.copy()))
        q = (0.0, 0.0, np.sin(self.odom[2] / 2), np.cos(self.odom[2] / 2))
        self.tf.send_transform(
            make_transform_stamped(
                self.frame("odom"), self.frame("base_link"), t, (*self.odom[:2], 0.0), q
            )
        )
        c, s = np.cos(self.true[2]), np.sin(self.true[2])
        sensor = self.true + np.array([c * LASER[0], s * LASER[0], 0.0])
        n = self.beams
        inc = 2 * np.pi / n
        angles = -np.pi + inc * np.arange(n)
        ranges = exact_ranges(sensor, -angles if self.flip else angles, 12.0)
        if self.peer_disc is not None:
            x, y, radius = self.peer_disc
            disc = disc_ranges(sensor, -angles if self.flip else angles, (x, y), radius)
            ranges = np.minimum(ranges, disc)
        ranges = ranges + 0.01 * self.rng.standard_normal(n)
        self.scan_pub.publish(
            sensor_msgs.LaserScan(
                header=std_msgs.Header(stamp=Time.from_sec(t), frame_id=self.frame("laser")),
                angle_min=-np.pi,
                angle_max=np.pi - inc,
                angle_increment=inc,
                range_min=0.05,
                range_max=12.0,
                ranges=ranges.astype(np.float32),
            )
        )


def _quat(r, p, y):
    cr, sr = np.cos(r / 2), np.sin(r / 2)
    cp, sp = np.cos(p / 2), np.sin(p / 2)
    cy, sy = np.cos(y / 2), np.sin(y / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )
