"""A synthetic run for viz tests: a walled map, two robots driving straight, with scans, tf,
plans, particle clouds and goals, recorded to MCAP."""

from __future__ import annotations

import numpy as np
import pytest

from fleetsim.msgs import geometry_msgs, nav_msgs, sensor_msgs, tf2_msgs
from fleetsim.record import Recorder
from fleetsim.runtime import Node, Runtime

MAP_W, MAP_H, RES = 200, 160, 0.05  # a 10 m x 8 m room, origin (0, 0)
STARTS = {"robot0": (2.0, 2.0), "robot1": (2.0, 6.0)}
SPEED = 0.5  # m/s along +x


def _tf(parent, child, x, y, yaw=0.0, stamp=None):
    t = geometry_msgs.TransformStamped()
    t.header.frame_id = parent
    t.child_frame_id = child
    if stamp is not None:
        t.header.stamp = stamp
    t.transform.translation.x, t.transform.translation.y = x, y
    t.transform.rotation.z, t.transform.rotation.w = np.sin(yaw / 2), np.cos(yaw / 2)
    return t


def room_map() -> nav_msgs.OccupancyGrid:
    grid = np.zeros((MAP_H, MAP_W), np.int8)
    grid[:3, :] = grid[-3:, :] = grid[:, :3] = grid[:, -3:] = 100
    grid[60:100, 150:160] = -1  # an unknown patch
    m = nav_msgs.OccupancyGrid()
    m.header.frame_id = "map"
    m.info.resolution = RES
    m.info.width, m.info.height = MAP_W, MAP_H
    m.data = grid.ravel()
    return m


class Driver(Node):
    """Drives along +x; publishes tf, a scan seeing the walls, a plan, particles, a goal."""

    def __init__(self, rt, robot: str):
        super().__init__(rt, "driver", f"/{robot}")
        self.robot = robot
        self.x0, self.y0 = STARTS[robot]
        self.tf_pub = self.create_publisher(tf2_msgs.TFMessage, "/tf")
        self.scan_pub = self.create_publisher(sensor_msgs.LaserScan, "scan")
        self.plan_pub = self.create_publisher(nav_msgs.Path, "move_base/NavfnROS/plan")
        self.cloud_pub = self.create_publisher(geometry_msgs.PoseArray, "particlecloud")
        self.goal_pub = self.create_publisher(geometry_msgs.PoseStamped, "move_base_simple/goal")
        static = self.create_publisher(tf2_msgs.TFMessage, "/tf_static", latch=True)
        static.publish(
            tf2_msgs.TFMessage(
                transforms=[
                    _tf("map", f"{robot}/odom", self.x0, self.y0),
                    _tf(f"{robot}/base_link", f"{robot}/base_laser", 0.1, 0.0),
                ]
            )
        )
        rt.call_later(0.5, self.send_goal)
        self.create_timer(0.05, self.on_tf)
        self.create_timer(0.1, self.on_scan)
        self.create_timer(0.5, self.on_plan)

    def send_goal(self):
        goal = geometry_msgs.PoseStamped()
        goal.header.frame_id = "map"
        goal.pose.position.x, goal.pose.position.y = 8.0, self.y0
        self.goal_pub.publish(goal)

    def pose(self):
        return self.x0 + SPEED * self.now(), self.y0

    def on_tf(self):
        t = _tf(f"{self.robot}/odom", f"{self.robot}/base_link", SPEED * self.now(), 0.0,
                stamp=self.now_msg())  # fmt: skip
        self.tf_pub.publish(tf2_msgs.TFMessage(transforms=[t]))

    def on_scan(self):
        x, y = self.pose()
        lx = x + 0.1
        a = np.linspace(-np.pi / 2, np.pi / 2, 181)
        # distance to the walls of the room (inner faces at 0.15 m and 9.85 / 7.85 m)
        with np.errstate(divide="ignore"):
            tx = np.where(np.cos(a) > 0, (9.85 - lx) / np.cos(a), np.inf)
            ty = np.where(np.sin(a) > 0, (7.85 - y) / np.sin(a),
                          np.where(np.sin(a) < 0, (0.15 - y) / np.sin(a), np.inf))  # fmt: skip
        s = sensor_msgs.LaserScan()
        s.header.stamp = self.now_msg()
        s.header.frame_id = f"{self.robot}/base_laser"
        s.angle_min, s.angle_max = float(a[0]), float(a[-1])
        s.angle_increment = float(np.float32(a[1] - a[0]))
        s.range_max = 30.0
        s.ranges = np.minimum(tx, ty).astype(np.float32)
        self.scan_pub.publish(s)

    def on_plan(self):
        x, y = self.pose()
        path = nav_msgs.Path()
        path.header.frame_id = "map"
        for px in np.linspace(x, 8.0, 10):
            p = geometry_msgs.PoseStamped()
            p.pose.position.x, p.pose.position.y = float(px), y
            path.poses.append(p)
        self.plan_pub.publish(path)
        cloud = geometry_msgs.PoseArray()
        cloud.header.frame_id = "map"
        for dx, dy in self.rng.normal(0.0, 0.2, (30, 2)):
            p = geometry_msgs.Pose()
            p.position.x, p.position.y = x + dx, y + dy
            cloud.poses.append(p)
        self.cloud_pub.publish(cloud)


@pytest.fixture(scope="session")
def room_recording(tmp_path_factory):
    """(path, duration): two robots recorded for 4 s; robot0 declares a 0.6 x 0.4 m footprint."""
    rt = Runtime(seed=1)
    rt.params.set(
        "/robot0/move_base/local_costmap/footprint",
        [[0.3, 0.2], [0.3, -0.2], [-0.3, -0.2], [-0.3, 0.2]],
    )
    mp = rt.graph.advertise("/map", nav_msgs.OccupancyGrid, latch=True)
    mp.publish(room_map())
    for robot in STARTS:
        Driver(rt, robot)
    path = tmp_path_factory.mktemp("viz") / "room.mcap"
    with Recorder(rt, path):
        rt.run(4.0)
    return path, 4.0


@pytest.fixture
def room_runtime():
    """A runtime with the latched room map and robot0 driving (not recorded)."""
    rt = Runtime(seed=3)
    rt.graph.advertise("/map", nav_msgs.OccupancyGrid, latch=True).publish(room_map())
    Driver(rt, "robot0")
    yield rt
    rt.shutdown()
