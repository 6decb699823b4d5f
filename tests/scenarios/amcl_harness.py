"""Test harness of the amcl scenarios: lizi in the Willow Garage map, driven around a loop.

The run is the lesson's setup without move_base: the ``Simulator`` on the Willow map
(``willow-full.yaml``, 0.1 m/px, walls extruded from the occupied cells), ``map_server``, the
``lizi`` robot in namespace ``/lizi1`` (skid steer, wheel-encoder odometry, p3d ground truth on
``base_pose_ground_truth``, the 270-degree laser on ``base_scan``), the lesson's
``static_transform_publisher`` for ``base_link -> laser_link`` (0, 0, 1) and ``amcl``. A
`RouteFollower` (pure pursuit on ground truth, publishing ``cmd_vel``) drives `ROUTE`; an
`AmclErrorLog` records ``amcl_pose`` and ground truth and pairs them by time.

Choices made here, and why:

- ``lizi`` with ``odometrySource encoder`` (opt-in; Gazebo's skid-steer plugin, and fleetsim's
  by default, report the true pose) rather than ``turtlebot3_burger``: its wheel-encoder
  odometry drifts (skid steer: when turning, it reports several times the true rotation), and a
  teleport does not show in it (the kidnapped-robot test); and its 30 m, 270-degree laser
  sees far down Willow's corridors; the burger reports its true pose as odometry
  (``odometrySource world``) and sees only 3.5 m.
- ``wall_height`` 2 m: lizi's laser sits 1.08 m above the floor, above the default 1 m walls.
- the laser at 10 Hz instead of 40 Hz: amcl updates only every 0.1 m / 0.1 rad here.
- spawned at z = 0.078 m (wheel radius): lizi's root link is at axle height.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fleetsim.description import load_robot
from fleetsim.localization.amcl.node import Amcl
from fleetsim.msgs import gazebo_msgs, geometry_msgs, nav_msgs, std_srvs
from fleetsim.nav.map_server import MapServer
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.node import Simulator
from fleetsim.tf import TransformBroadcaster, make_transform_stamped
from fleetsim.tf.static_transform_publisher import StaticTransformPublisher

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[2].parent / "shared"

WILLOW = Path(SHARED, "data/maps/willow-full.yaml")
LIZI_XACRO = (
    Path(__file__).resolve().parents[2] / "src/fleetsim/assets/robots/lizi/urdf/lizi.urdf.xacro"
)
ROBOT = "lizi1"
NS = "/lizi1"
SPAWN_Z = 0.078  # m, lizi's base_link (wheel axle) height: wheels just touch the floor

# The route, waypoints in the map frame (m): north up the corridor west of Willow's central block
# (x ~ 32 m), along the corridor north of it, back south (a U-turn at x = 35.8 m), east
# through the hall south of the block (y ~ 20 m) and north up the corridor east of it
# (x ~ 43.8 m). Every segment keeps >= 0.55 m from the occupied cells (checked by the tests);
# 62.7 m from the first waypoint to the last.
ROUTE = np.array(
    [
        [33.1, 18.4],
        [32.1, 23.9],
        [31.4, 37.5],
        [32.1, 38.1],
        [35.8, 38.5],
        [32.3, 38.0],
        [31.6, 36.5],
        [32.1, 23.9],
        [32.9, 20.2],
        [34.6, 20.0],
        [35.1, 20.0],
        [36.8, 19.8],
        [37.8, 19.1],
        [39.0, 19.1],
        [40.7, 20.1],
        [43.0, 20.4],
        [43.8, 21.7],
        [43.8, 26.8],
    ]
)


def wrapped(a: np.ndarray | float) -> np.ndarray | float:
    """Angles (rad) wrapped to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def yaw_of(q: Any) -> float:
    """Yaw (rad) of a geometry_msgs Quaternion."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def dense_route(waypoints: np.ndarray, step: float = 0.05) -> np.ndarray:
    """(K, 2) points every ``step`` m along the polyline ``waypoints`` (N, 2), m."""
    out = [waypoints[:1]]
    for a, b in itertools.pairwise(waypoints):
        n = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
        out.append(a + (b - a) * (np.arange(1, n + 1)[:, None] / n))
    return np.concatenate(out)


def route_length(waypoints: np.ndarray) -> float:
    """Length (m) of the polyline ``waypoints`` (N, 2)."""
    return float(np.sum(np.hypot(*np.diff(waypoints, axis=0).T)))


def start_pose(waypoints: np.ndarray = ROUTE) -> tuple[float, float, float]:
    """``(x, y, yaw)`` at the first waypoint, facing the second."""
    d = waypoints[1] - waypoints[0]
    return float(waypoints[0, 0]), float(waypoints[0, 1]), math.atan2(d[1], d[0])


def lizi_robot(scan_rate: float = 10.0):
    """The lizi model from its xacro, its laser at ``scan_rate`` Hz, wheel-encoder odometry."""
    robot = load_robot(LIZI_XACRO)
    for block in robot.gazebo:
        for plugin in block.plugins:
            if plugin.filename == "libgazebo_ros_skid_steer_drive.so":
                plugin.params["odometrySource"] = "encoder"
    for sensor in robot.sensors():
        if sensor.type == "ray":
            sensor.update_rate = scan_rate
    return robot


class RouteFollower(Node):
    """Pure pursuit along a polyline on ground truth; publishes ``cmd_vel`` at 20 Hz.

    Turns in place when the lookahead point is more than 0.7 rad off the heading; linear
    speed ramps at ``accel`` m/s^2. ``travelled`` is the ground-truth path length (m).
    """

    def __init__(self, rt, route: np.ndarray, speed: float = 0.5, lookahead: float = 0.8):
        super().__init__(rt, "route_follower", NS)
        self.points = dense_route(route)
        self.speed, self.lookahead, self.accel = speed, lookahead, 0.5
        self.index = 0
        self.v = 0.0
        self.pose: np.ndarray | None = None
        self.travelled = 0.0
        self.done = False
        self.cmd = self.create_publisher(geometry_msgs.Twist, "cmd_vel", queue_size=1)
        self.create_subscription(nav_msgs.Odometry, "base_pose_ground_truth", self.on_truth, 1)
        self.create_timer(0.05, self.on_timer)

    def on_truth(self, msg: nav_msgs.Odometry) -> None:
        p = msg.pose.pose
        pose = np.array([p.position.x, p.position.y, yaw_of(p.orientation)])
        if self.pose is not None:
            step = float(np.hypot(*(pose[:2] - self.pose[:2])))
            self.travelled += step if step < 0.5 else 0.0  # a teleport is not travel
        self.pose = pose

    def on_timer(self) -> None:
        if self.pose is None:
            return
        x, y, th = self.pose
        window = self.points[self.index : self.index + 60]
        gaps = np.hypot(window[:, 0] - x, window[:, 1] - y)
        if gaps.min() > 1.0:  # teleported: continue from the nearest route point
            self.index = int(np.argmin(np.hypot(*(self.points - (x, y)).T)))
            self.v = 0.0
        else:
            self.index += int(np.argmin(gaps))
        ahead = np.hypot(*(self.points[self.index :] - (x, y)).T)
        beyond = np.flatnonzero(ahead >= self.lookahead)
        if self.index >= len(self.points) - 1 or (len(beyond) == 0 and ahead[-1] < 0.1):
            self.done = True
            self.cmd.publish(geometry_msgs.Twist())
            return
        target = self.points[self.index + (beyond[0] if len(beyond) else len(ahead) - 1)]
        alpha = float(wrapped(math.atan2(target[1] - y, target[0] - x) - th))
        twist = geometry_msgs.Twist()
        if abs(alpha) > 0.7:
            self.v = max(0.0, self.v - self.accel * 0.05)
            twist.angular.z = math.copysign(1.5, alpha)
        else:
            self.v = min(self.speed, self.v + self.accel * 0.05)
            twist.angular.z = float(np.clip(2.0 * self.v * math.sin(alpha) / self.lookahead, -1, 1))
        twist.linear.x = self.v
        self.cmd.publish(twist)


class AmclErrorLog(Node):
    """Records ground truth and ``amcl_pose``; `errors` pairs them by time."""

    def __init__(self, rt, follower: RouteFollower):
        super().__init__(rt, "amcl_error_log", NS)
        self.follower = follower
        self.truth: list[tuple[float, float, float, float, float]] = []  # t, x, y, yaw, dist
        self.estimates: list[tuple[float, float, float, float]] = []  # t, x, y, yaw
        self.create_subscription(nav_msgs.Odometry, "base_pose_ground_truth", self.on_truth, 1)
        self.create_subscription(
            geometry_msgs.PoseWithCovarianceStamped, "amcl_pose", self.on_pose, 10
        )

    def on_truth(self, msg: nav_msgs.Odometry) -> None:
        p = msg.pose.pose
        t = msg.header.stamp.to_sec()
        self.truth.append(
            (t, p.position.x, p.position.y, yaw_of(p.orientation), self.follower.travelled)
        )

    def on_pose(self, msg: geometry_msgs.PoseWithCovarianceStamped) -> None:
        p = msg.pose.pose
        t = msg.header.stamp.to_sec()
        self.estimates.append((t, p.position.x, p.position.y, yaw_of(p.orientation)))

    def errors(self) -> dict[str, np.ndarray]:
        """Per ``amcl_pose``: ``t`` (s), ``dist`` travelled (m), ``pos`` (m) and ``yaw`` (rad)
        errors against the ground truth interpolated at the pose's stamp."""
        truth = np.array(self.truth)
        est = np.array(self.estimates).reshape(-1, 4)
        est = est[(est[:, 0] >= truth[0, 0]) & (est[:, 0] <= truth[-1, 0])]
        t = est[:, 0]
        tx = np.interp(t, truth[:, 0], truth[:, 1])
        ty = np.interp(t, truth[:, 0], truth[:, 2])
        tyaw = np.interp(t, truth[:, 0], np.unwrap(truth[:, 3]))
        return {
            "t": t,
            "dist": np.interp(t, truth[:, 0], truth[:, 4]),
            "pos": np.hypot(est[:, 1] - tx, est[:, 2] - ty),
            "yaw": np.abs(wrapped(est[:, 3] - tyaw)),
        }


class NoisyOdometryTf(Node):
    """Re-broadcasts ``odom -> base_link`` from ``odom`` with extra, drifting noise.

    Each odometry increment (body frame) gets its translation scaled by ``1 + trans_noise * n``
    and ``rot_noise * |step| * n`` added to its rotation (``n`` standard normal, drawn per
    message), plus a constant heading drift ``yaw_bias`` rad per metre: the errors of a worn
    or badly calibrated base. Use with the drive plugin's ``broadcastTF`` off.
    """

    def __init__(self, rt, trans_noise: float, rot_noise: float, yaw_bias: float):
        super().__init__(rt, "noisy_odometry_tf", NS)
        self.noise = (trans_noise, rot_noise, yaw_bias)
        self.last: np.ndarray | None = None
        self.pose = np.zeros(3)
        self.tf = TransformBroadcaster(self)
        self.create_subscription(nav_msgs.Odometry, "odom", self.on_odom, 10)

    def on_odom(self, msg: nav_msgs.Odometry) -> None:
        p = msg.pose.pose
        now = np.array([p.position.x, p.position.y, yaw_of(p.orientation)])
        if self.last is not None:
            c, s = math.cos(self.last[2]), math.sin(self.last[2])
            dx, dy = now[0] - self.last[0], now[1] - self.last[1]
            fwd, side = c * dx + s * dy, -s * dx + c * dy
            dth = float(wrapped(now[2] - self.last[2]))
            tn, rn, bias = self.noise
            n = self.rng.standard_normal(2)
            scale = 1.0 + tn * n[0]
            fwd, side = fwd * scale, side * scale
            dth += rn * abs(dth) * n[1] + bias * math.hypot(fwd, side)
            c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
            self.pose += (c * fwd - s * side, s * fwd + c * side, dth)
        self.last = now
        yaw = float(self.pose[2])
        self.tf.send_transform(
            make_transform_stamped(
                msg.header.frame_id,
                msg.child_frame_id,
                msg.header.stamp.to_sec(),
                (float(self.pose[0]), float(self.pose[1]), 0.0),
                (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)),
            )
        )


@dataclass
class WillowAmclRun:
    """One assembled run; call ``rt.run(...)`` or `drive`."""

    rt: Runtime
    sim: Simulator
    amcl: Amcl
    follower: RouteFollower
    log: AmclErrorLog
    probe: Node
    extra: list = field(default_factory=list)

    def drive(self, max_sim_time: float, until=None) -> None:
        """Run until the route is done (or ``until()``), at most ``max_sim_time`` s of sim time."""
        end = self.rt.now() + max_sim_time

        def stop() -> bool:
            return self.follower.done or self.rt.now() >= end or (until is not None and until())

        self.rt.run(until=stop)

    def teleport(self, x: float, y: float, yaw: float) -> bool:
        """Move the robot with ``/gazebo/set_model_state`` (kidnapping); True on success."""
        client = self.probe.create_client(gazebo_msgs.SetModelState, "/gazebo/set_model_state")
        req = gazebo_msgs.SetModelState.Request()
        s = req.model_state
        s.model_name = ROBOT
        s.reference_frame = "world"
        s.pose.position.x, s.pose.position.y, s.pose.position.z = x, y, SPAWN_Z
        s.pose.orientation.z, s.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        ok = client.call(req).success
        self.follower.pose = None  # the next ground-truth message re-anchors the follower
        return ok

    def global_localization(self) -> None:
        client = self.probe.create_client(std_srvs.Empty, f"{NS}/global_localization")
        client.call(std_srvs.Empty.Request())

    def estimate(self) -> np.ndarray:
        """The filter's current ``(x, y, yaw)`` estimate."""
        return np.asarray(self.amcl.filter.estimate.pose, dtype=float)

    def truth(self) -> np.ndarray:
        """The robot's true ``(x, y, yaw)`` from the simulator."""
        pos, q = self.sim.engine.model_pose(ROBOT)
        w, qx, qy, qz = q
        return np.array(
            [pos[0], pos[1], math.atan2(2 * (w * qz + qx * qy), 1 - 2 * (qy**2 + qz**2))]
        )


def willow_amcl_run(
    seed: int,
    amcl_params: dict[str, Any],
    initial_guess: tuple[float, float, float] | None = None,
    route: np.ndarray = ROUTE,
    speed: float = 0.5,
    odom_noise: tuple[float, float, float] | None = None,
    scan_rate: float = 10.0,
) -> WillowAmclRun:
    """Assemble the scenario: simulator, map_server, lizi, laser tf, amcl, follower, log.

    ``initial_guess`` (default: the true start pose) becomes amcl's ``initial_pose_*``;
    ``odom_noise`` = ``(trans_noise, rot_noise, yaw_bias)`` replaces the simulator's odometry tf
    by a `NoisyOdometryTf` one.
    """
    rt = Runtime(seed=seed)
    rt.params.set(f"{NS}/tf_prefix", ROBOT)  # as the lesson's launch file sets it
    sim = Simulator(rt, args=[str(WILLOW)], params={"wall_height": 2.0})
    MapServer(rt, map_file=WILLOW)
    robot = lizi_robot(scan_rate)
    extra: list = []
    if odom_noise is not None:
        for plugin in robot.plugins():
            if plugin.filename == "libgazebo_ros_skid_steer_drive.so":
                plugin.params["broadcastTF"] = "0"
    x, y, yaw = start_pose(route)
    sim.spawn_robot(ROBOT, robot, (x, y, SPAWN_Z, 0.0, 0.0, yaw), NS)
    if odom_noise is not None:
        extra.append(NoisyOdometryTf(rt, *odom_noise))
    StaticTransformPublisher(rt, "laser_tf", NS, args="0 0 1 0 0 0 base_link laser_link")
    gx, gy, gyaw = initial_guess if initial_guess is not None else (x, y, yaw)
    params = {"initial_pose_x": gx, "initial_pose_y": gy, "initial_pose_a": gyaw}
    params.update(amcl_params)
    amcl = Amcl(
        rt, "amcl", NS, params=params, remaps={"scan": "base_scan", "static_map": "/static_map"}
    )
    follower = RouteFollower(rt, route, speed=speed)
    log = AmclErrorLog(rt, follower)
    probe = Node(rt, "scenario_probe")
    return WillowAmclRun(rt, sim, amcl, follower, log, probe, extra)
