"""A small world for navigation node tests: a room map and a kinematic robot node.

The room is 8 m x 6 m at 0.05 m/cell: outer walls, a wall at x = 4 m with a 1 m door
(y 2.5..3.5 m), and a closed 1 m box (x 6..7.4, y 0.4..1.8 m, walls 0.1 m) whose inside is free
but unreachable. The robot integrates ``cmd_vel`` as a unicycle at 50 Hz, publishes
``odom -> base_link`` (odom = its start pose), ``odom`` and ``base_pose_ground_truth``, a static
``base_link -> laser`` and a 10 Hz LaserScan ray-cast against a world grid (the map plus any
extra obstacles) with a simple NumPy marcher.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from fleetsim.msgs import geometry_msgs, nav_msgs, sensor_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.map_io import OccupancyMap
from fleetsim.runtime import Node
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster, make_transform_stamped

RES = 0.05
LASER = (0.1, 0.0, 0.2)  # laser in base_link, m


def fill(grid: np.ndarray, x0: float, y0: float, x1: float, y1: float, value: int = 100):
    """Set the cells whose centres lie in [x0, x1] x [y0, y1] (m) to ``value``."""
    c0, r0 = round(x0 / RES), round(y0 / RES)
    c1, r1 = round(x1 / RES), round(y1 / RES)
    grid[r0:r1, c0:c1] = value
    return grid


def room_grid() -> np.ndarray:
    g = np.zeros((120, 160), dtype=np.int8)
    g[:2, :] = g[-2:, :] = g[:, :2] = g[:, -2:] = 100
    fill(g, 3.95, 0.0, 4.05, 2.5)
    fill(g, 3.95, 3.5, 4.05, 6.0)
    fill(g, 6.0, 0.4, 7.4, 0.5)
    fill(g, 6.0, 1.7, 7.4, 1.8)
    fill(g, 6.0, 0.4, 6.1, 1.8)
    fill(g, 7.3, 0.4, 7.4, 1.8)
    return g


def room_map() -> OccupancyMap:
    return OccupancyMap(room_grid(), RES, (0.0, 0.0, 0.0))


def quaternion(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def ranges_from_grid(
    occupied: np.ndarray, pose: np.ndarray, angles: np.ndarray, range_max: float
) -> np.ndarray:
    """Distance to the first occupied cell along each beam (inf beyond range_max).

    occupied : (H, W) bool, origin (0, 0), RES m cells. pose : (3,) laser x, y, yaw in the
    grid frame. angles : (B,) beam angles in the laser frame. Returns (B,) float32 m.
    """
    r = np.arange(0.0, range_max, RES / 4.0)
    a = pose[2] + angles
    xs = pose[0] + np.cos(a)[:, None] * r[None, :]
    ys = pose[1] + np.sin(a)[:, None] * r[None, :]
    cx = np.floor(xs / RES).astype(np.int64)
    cy = np.floor(ys / RES).astype(np.int64)
    h, w = occupied.shape
    outside = (cx < 0) | (cy < 0) | (cx >= w) | (cy >= h)
    hit = outside | occupied[np.clip(cy, 0, h - 1), np.clip(cx, 0, w - 1)]
    first = np.argmax(hit, axis=1)
    out = np.where(hit.any(axis=1), r[first], np.inf)
    return out.astype(np.float32)


class KinematicRobot(Node):
    """A unicycle (holonomic if cmd_vel has y) driven by ``cmd_vel``, with tf, odom and a laser."""

    def __init__(self, rt, namespace="/lizi1", start=(1.0, 1.0, 0.0), world=None, beams=180):
        super().__init__(rt, "robot", namespace)
        self.pose = np.array(start, dtype=np.float64)  # ground truth in map
        self.start = self.pose.copy()
        self.cmd = np.zeros(3)
        self.commands: list[tuple[float, np.ndarray]] = []
        self.world = room_grid() if world is None else world
        self.beams = beams
        self.range_max = 4.0
        self.radius = 0.2
        self.min_clearance = math.inf
        self._refresh_distance()
        self.tf = TransformBroadcaster(self)
        StaticTransformBroadcaster(self).send_transform(
            make_transform_stamped(self.frame("base_link"), self.frame("laser"), 0.0, LASER)
        )
        self.odom_pub = self.create_publisher(nav_msgs.Odometry, "odom", 10)
        self.truth_pub = self.create_publisher(nav_msgs.Odometry, "base_pose_ground_truth", 10)
        self.scan_pub = self.create_publisher(sensor_msgs.LaserScan, "scan", 1)
        self.create_subscription(geometry_msgs.Twist, "cmd_vel", self.on_cmd, 1)
        self.create_timer(0.02, self.step, priority=-100)
        self.scan_timer = self.create_timer(0.1, self.scan, priority=-50)
        self.publish_state()

    def _refresh_distance(self) -> None:
        self.distance = ndimage.distance_transform_edt(self.world < 50) * RES

    def set_world(self, world: np.ndarray) -> None:
        self.world = world
        self._refresh_distance()

    def on_cmd(self, msg: geometry_msgs.Twist) -> None:
        self.cmd = np.array([msg.linear.x, msg.linear.y, msg.angular.z])
        self.commands.append((self.now(), self.cmd.copy()))

    def step(self) -> None:
        dt = 0.02
        vx, vy, w = self.cmd
        c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
        self.pose += dt * np.array([c * vx - s * vy, s * vx + c * vy, w])
        self.pose[2] = math.remainder(self.pose[2], 2 * math.pi)
        r, col = int(self.pose[1] / RES), int(self.pose[0] / RES)
        h, wd = self.distance.shape
        if 0 <= r < h and 0 <= col < wd:
            self.min_clearance = min(self.min_clearance, float(self.distance[r, col]))
        self.publish_state()

    def odom_pose(self) -> np.ndarray:
        """The pose in the odom frame (whose origin is the start pose)."""
        d = self.pose[:2] - self.start[:2]
        c, s = math.cos(-self.start[2]), math.sin(-self.start[2])
        return np.array([c * d[0] - s * d[1], s * d[0] + c * d[1], self.pose[2] - self.start[2]])

    def publish_state(self) -> None:
        t = self.now()
        stamp = Time.from_sec(t)
        o = self.odom_pose()
        self.tf.send_transform(
            make_transform_stamped(
                self.frame("odom"), self.frame("base_link"), t, (o[0], o[1], 0.0), quaternion(o[2])
            )
        )
        twist = geometry_msgs.TwistWithCovariance(
            twist=geometry_msgs.Twist(
                linear=geometry_msgs.Vector3(x=self.cmd[0], y=self.cmd[1]),
                angular=geometry_msgs.Vector3(z=self.cmd[2]),
            )
        )
        for pub, frame, p in (
            (self.odom_pub, self.frame("odom"), o),
            (self.truth_pub, "map", self.pose),
        ):
            q = quaternion(p[2])
            pose = geometry_msgs.Pose(
                position=geometry_msgs.Point(x=p[0], y=p[1]),
                orientation=geometry_msgs.Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]),
            )
            pub.publish(
                nav_msgs.Odometry(
                    header=std_msgs.Header(stamp=stamp, frame_id=frame),
                    child_frame_id=self.frame("base_link"),
                    pose=geometry_msgs.PoseWithCovariance(pose=pose),
                    twist=twist,
                )
            )

    def scan(self) -> None:
        c, s = math.cos(self.pose[2]), math.sin(self.pose[2])
        laser = np.array(
            [
                self.pose[0] + c * LASER[0] - s * LASER[1],
                self.pose[1] + s * LASER[0] + c * LASER[1],
                self.pose[2],
            ]
        )
        inc = 2 * math.pi / self.beams
        angles = -math.pi + inc * np.arange(self.beams)
        ranges = ranges_from_grid(self.world >= 50, laser, angles, self.range_max)
        self.scan_pub.publish(
            sensor_msgs.LaserScan(
                header=std_msgs.Header(stamp=self.now_msg(), frame_id=self.frame("laser")),
                angle_min=-math.pi,
                angle_max=math.pi - inc,
                angle_increment=inc,
                range_min=0.05,
                range_max=self.range_max,
                ranges=ranges,
            )
        )


class MapPublisher(Node):
    """Publishes the room map latched on /map (what map_server does)."""

    def __init__(self, rt, occupancy: OccupancyMap | None = None):
        from fleetsim.nav.map_server import grid_msg_from_map

        super().__init__(rt, "map_server")
        self.pub = self.create_publisher(nav_msgs.OccupancyGrid, "map", 1, latch=True)
        self.pub.publish(grid_msg_from_map(occupancy or room_map(), "map"))


COMMON = {  # costmap_common_params.yaml, pre-Hydro form
    "obstacle_range": 2.5,
    "raytrace_range": 3.0,
    "robot_radius": 0.2,
    "inflation_radius": 0.5,
    "cost_scaling_factor": 5.0,
    "observation_sources": "scan",
    "scan": {"data_type": "LaserScan", "topic": "scan", "marking": True, "clearing": True},
}
GLOBAL = {"global_frame": "/map", "robot_base_frame": "base_link", "update_frequency": 5.0,
          "publish_frequency": 1.0, "static_map": True}  # fmt: skip
LOCAL = {"global_frame": "odom", "robot_base_frame": "base_link", "update_frequency": 5.0,
         "publish_frequency": 2.0, "static_map": False, "rolling_window": True,
         "width": 3.0, "height": 3.0, "resolution": 0.05}  # fmt: skip
PLANNER = {"max_vel_x": 0.5, "min_vel_x": 0.1, "max_vel_theta": 1.0, "min_vel_theta": -1.0,
           "min_in_place_vel_theta": 0.4, "holonomic_robot": False, "xy_goal_tolerance": 0.15,
           "yaw_goal_tolerance": 0.2, "sim_time": 1.5, "vx_samples": 6, "vtheta_samples": 20,
           "meter_scoring": True, "pdist_scale": 0.6, "gdist_scale": 0.8,
           "occdist_scale": 0.01}  # fmt: skip


def move_base_params(local=None, glob=None, planner=None, **top):
    """move_base's private namespace as the lesson's launch file loads it."""
    return {
        "global_costmap": {**COMMON, **GLOBAL, **(glob or {})},
        "local_costmap": {**COMMON, **LOCAL, **(local or {})},
        "TrajectoryPlannerROS": {**PLANNER, **(planner or {})},
        **top,
    }


def goal_msg(x, y, yaw=0.0, frame="map"):
    from fleetsim.msgs import move_base_msgs
    from fleetsim.nav.move_base_support import pose_stamped

    return move_base_msgs.MoveBaseGoal(target_pose=pose_stamped(x, y, yaw, frame, Time()))


class Watcher(Node):
    """Records what move_base publishes."""

    def __init__(self, rt, ns="/lizi1"):
        from fleetsim.msgs import move_base_msgs

        super().__init__(rt, "watcher", ns)
        self.cmds, self.goals, self.plans, self.local, self.feedback = [], [], [], [], []
        sub = self.create_subscription
        sub(geometry_msgs.Twist, "cmd_vel", lambda m: self.cmds.append((self.now(), m)), 10)
        sub(geometry_msgs.PoseStamped, "move_base/current_goal", self.goals.append, 10)
        sub(nav_msgs.Path, "move_base/NavfnROS/plan", self.plans.append, 10)
        sub(nav_msgs.Path, "move_base/TrajectoryPlannerROS/local_plan", self.local.append, 10)
        sub(move_base_msgs.MoveBase.ActionFeedback, "move_base/feedback", self.feedback.append, 10)


def nav_world(params=None, start=(1.0, 1.0, 0.0), world=None, with_map=True):
    """A runtime with the room, a robot in /lizi1, fake_localization, move_base and a client."""
    from types import SimpleNamespace

    from fleetsim.msgs import move_base_msgs
    from fleetsim.nav.fake_localization import FakeLocalization
    from fleetsim.nav.move_base import MoveBase
    from fleetsim.runtime import Runtime

    rt = Runtime()
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    rt.params.update("/lizi1/move_base", params if params is not None else move_base_params())
    maps = MapPublisher(rt) if with_map else None
    bot = KinematicRobot(rt, start=start, world=world)
    FakeLocalization(rt, namespace="/lizi1")
    mb = MoveBase(rt, "move_base", "/lizi1", remaps={"map": "/map"})
    watcher = Watcher(rt)
    client = Node(rt, "client", "/lizi1").create_action_client(move_base_msgs.MoveBase, "move_base")
    return SimpleNamespace(rt=rt, bot=bot, mb=mb, watch=watcher, client=client, maps=maps)
