"""A small synthetic run for recording tests: robots publishing scans, odometry and tf."""

from __future__ import annotations

import numpy as np
import pytest

from fleetsim.msgs import geometry_msgs, nav_msgs, sensor_msgs, tf2_msgs
from fleetsim.runtime import Node, Runtime


class FakeRobot(Node):
    """Publishes a 10 Hz scan, 20 Hz odometry and tf, and (once) a latched map.

    ``fail_at``: raise from the scan timer at that sim time (an error in a node).
    """

    def __init__(self, rt, ns: str, fail_at: float | None = None, with_map: bool = False):
        super().__init__(rt, "fake", ns)
        self.prefix = ns.strip("/")
        self.fail_at = fail_at
        self.scan_pub = self.create_publisher(sensor_msgs.LaserScan, "scan")
        self.odom_pub = self.create_publisher(nav_msgs.Odometry, "odom")
        self.tf_pub = self.create_publisher(tf2_msgs.TFMessage, "/tf")
        self.scans: list = []
        if with_map:
            grid = nav_msgs.OccupancyGrid()
            grid.header.frame_id = "map"
            grid.info.resolution = 0.1
            grid.info.width, grid.info.height = 20, 10
            grid.data = np.zeros(200, np.int8)
            grid.data[:20] = 100
            self.map_pub = self.create_publisher(nav_msgs.OccupancyGrid, "/map", latch=True)
            self.map_pub.publish(grid)
        self.create_timer(0.1, self.on_scan)
        self.create_timer(0.05, self.on_odom)

    def on_scan(self):
        if self.fail_at is not None and self.now() >= self.fail_at:
            raise RuntimeError(f"node {self.full_name} failed at t={self.now():.2f}")
        scan = sensor_msgs.LaserScan()
        scan.header.stamp = self.now_msg()
        scan.header.frame_id = f"{self.prefix}/base_laser"
        scan.angle_min, scan.angle_max = -1.5, 1.5
        scan.angle_increment = float(np.float32(3.0 / 359))  # exact in float32
        scan.range_max = 10.0
        scan.ranges = self.rng.uniform(0.5, 5.0, 360).astype(np.float32)
        self.scans.append(scan)
        self.scan_pub.publish(scan)

    def on_odom(self):
        t = self.now()
        odom = nav_msgs.Odometry()
        odom.header.stamp = self.now_msg()
        odom.header.frame_id = f"{self.prefix}/odom"
        odom.child_frame_id = f"{self.prefix}/base_link"
        odom.pose.pose.position.x = 0.5 * t
        self.odom_pub.publish(odom)
        tr = geometry_msgs.TransformStamped()
        tr.header = odom.header
        tr.child_frame_id = odom.child_frame_id
        tr.transform.translation.x = 0.5 * t
        self.tf_pub.publish(tf2_msgs.TFMessage(transforms=[tr]))


@pytest.fixture
def fake_run():
    """``fake_run(n_robots, **kw)`` -> (runtime, [FakeRobot]); the first robot owns the map."""

    def make(n: int = 2, fail_at: float | None = None, seed: int = 0):
        rt = Runtime(seed=seed)
        robots = [
            FakeRobot(rt, f"/robot{i}", fail_at=fail_at if i == 0 else None, with_map=i == 0)
            for i in range(n)
        ]
        return rt, robots

    return make


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A finished 1 s recording of one robot with the map (51 messages)."""
    from fleetsim.record import Recorder

    rt = Runtime()
    FakeRobot(rt, "/robot0", with_map=True)
    path = tmp_path_factory.mktemp("rec") / "run.mcap"
    with Recorder(rt, path, chunk_size=1024):
        rt.run(1.0)
    return path
