"""Tests for fleetsim.slam.node: slam_gmapping in a runtime, on the synthetic room.

A fake robot drives a loop with drifting odometry and exact 360-beam scans; the published map
is checked against the room's true occupancy, the map -> odom tf against the true pose.
"""

import logging

import numpy as np
import pytest
from slam_world import LASER, FakeRobot, exact_ranges, true_occupied

from fleetsim.errors import ServiceError
from fleetsim.launch.registry import resolve_node
from fleetsim.msgs import nav_msgs, sensor_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.map_io import load_map
from fleetsim.nav.map_server import MapSaver
from fleetsim.runtime import Node, Runtime
from fleetsim.slam import SlamGmapping
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster, make_transform_stamped

START = np.array([1.5, 1.5, 0.0])  # the route's first pose: the map frame's origin
FAST = {"xmin": -5.0, "ymin": -5.0, "xmax": 15.0, "ymax": 12.0, "particles": 15}


class Listener(Node):
    def __init__(self, rt, ns="/"):
        super().__init__(rt, "listener", ns)
        self.maps, self.meta, self.entropy = [], [], []
        self.create_subscription(nav_msgs.OccupancyGrid, "map", self.maps.append)
        self.create_subscription(nav_msgs.MapMetaData, "map_metadata", self.meta.append)
        self.create_subscription(std_msgs.Float64, "slam_gmapping/entropy", self.entropy.append)


def world(ns="/", prefix="", params=None, seed=0, **robot_kw):
    rt = Runtime(seed=seed)
    if prefix:
        rt.params.set(f"{ns}/tf_prefix", prefix)
    for key, value in {**FAST, **(params or {})}.items():
        rt.params.set(f"{ns.rstrip('/')}/slam_gmapping/{key}", value)
    robot = FakeRobot(rt, ns, seed=seed, **robot_kw)
    slam = SlamGmapping(rt, "slam_gmapping", ns)
    return rt, robot, slam, Listener(rt, ns)


def precision(grid: nav_msgs.OccupancyGrid, offset=START) -> float:
    """Share of occupied cells within 0.1 m of the room's true occupancy."""
    data = np.asarray(grid.data).reshape(grid.info.height, grid.info.width)
    iy, ix = np.nonzero(data == 100)
    res, o = grid.info.resolution, grid.info.origin.position
    x, y = o.x + (ix + 0.5) * res + offset[0], o.y + (iy + 0.5) * res + offset[1]
    near = np.zeros(len(x), dtype=bool)
    for dx in (-0.1, 0.0, 0.1):
        for dy in (-0.1, 0.0, 0.1):
            near |= true_occupied(x + dx, y + dy)
    return float(near.mean())


def test_registered_as_gmapping_slam_gmapping():
    assert resolve_node("gmapping", "slam_gmapping") is SlamGmapping


def test_maps_the_room_in_a_namespace_with_its_own_frames(caplog):
    with caplog.at_level(logging.WARNING):
        rt, robot, slam, out = world(
            "/lizi1", "lizi1", {"map_update_interval": 2.0, "linearUpdate": 0.5}
        )
        errors = []
        for _ in range(8):
            rt.run(duration=5.0)
            est = np.array(rt.tf_buffer.lookup_pose2d("lizi1/map", "lizi1/base_link", 0.0))
            errors.append(np.hypot(*(est[:2] + START[:2] - robot.true[:2])))
    assert (slam.map_frame, slam.odom_frame, slam.base_frame) == (
        "lizi1/map",
        "lizi1/odom",
        "lizi1/base_link",
    )
    assert max(errors) < 0.08, errors
    grid = out.maps[-1]
    assert grid.header.frame_id == "lizi1/map" and grid.info.resolution == pytest.approx(0.05)
    assert out.meta[-1].width == grid.info.width
    assert precision(grid) > 0.97
    data = np.asarray(grid.data)
    assert set(np.unique(data)) <= {-1, 0, 100} and (data == 0).sum() > 10_000
    assert out.entropy and out.entropy[-1].data > 0
    # map published every map_update_interval of scan time, not at every update
    assert 10 <= len(out.maps) <= 22 < slam.filter.updates
    assert "WARN" not in caplog.text
    # the tf thread: map -> odom every transform_publish_period, dated ahead by it
    info = rt.tf_buffer.frame_info("lizi1/odom")
    assert info.parent == "lizi1/map" and info.most_recent == pytest.approx(
        rt.now() + 0.05, abs=0.02
    )
    # dynamic_map answers the latest map
    resp = slam.runtime.graph.services["/lizi1/dynamic_map"].callback(nav_msgs.GetMap.Request())
    assert resp.map is slam.grid_msg


def test_transform_publish_period_is_capped_at_the_simulator_rate(caplog):
    with caplog.at_level(logging.INFO):
        rt, robot, slam, out = world(params={"transform_publish_period": 0.0005})
    assert slam.tf_period == pytest.approx(0.01)  # no simulator node: its default period
    assert "faster than the simulator publishes" in caplog.text
    # with a simulator that publishes every 0.02 s: that period, and a slower one as it is
    from fleetsim.sim.node import Simulator

    for asked, expected in ((0.0005, 0.02), (0.05, 0.05)):
        rt = Runtime(seed=0)
        rt.params.set("/gazebo/update_period", 0.02)
        Simulator(rt, "gazebo")
        rt.params.set("/slam_gmapping/transform_publish_period", asked)
        assert SlamGmapping(rt, "slam_gmapping").tf_period == pytest.approx(expected)


def test_updates_gated_by_linear_angular_and_temporal_update():
    # the robot stands still: no update after the first unless temporalUpdate is set
    still = [[1.5, 1.5]]
    rt, _, slam, _ = world(route=still)
    rt.run(duration=5.0)
    assert slam.filter.updates == 1
    rt, _, slam, _ = world(params={"temporalUpdate": 1.0}, route=still)
    rt.run(duration=5.05)
    assert slam.filter.updates == 5  # t = 0, then every scan more than 1 s after the last
    rt, _, slam, _ = world(params={"temporalUpdate": -1.0}, route=still)  # ROS's "off"
    assert slam.params.temporalUpdate is None


def test_a_scan_whose_beam_count_changes_is_dropped_with_an_error(caplog):
    rt, robot, slam, _ = world("/r1", "r1")
    rt.run(duration=1.0)
    robot.beams = 180
    with caplog.at_level(logging.WARNING):
        rt.run(duration=2.0)
    assert "dropping scans on /r1/scan (frame 'r1/laser'): 180 beams" in caplog.text
    assert "first scan had 360" in caplog.text


def test_a_tilted_laser_is_refused_and_an_upside_down_one_mirrored(caplog):
    with caplog.at_level(logging.WARNING):
        rt, _, slam, _ = world(laser_rpy=(0.0, 0.4, 0.0))
        rt.run(duration=1.0)
    assert "the laser frame 'laser' of /scan is not level" in caplog.text
    assert slam.filter is None
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        rt, robot, slam, out = world(laser_rpy=(np.pi, 0.0, 0.0), params={"linearUpdate": 0.5})
        rt.run(duration=20.0)
    assert "laser frame 'laser' of /scan is mounted upside down" in caplog.text
    assert precision(out.maps[-1]) > 0.97  # the mirrored beams still make the right map


def test_missing_odometry_tf_is_reported_naming_the_frames(caplog):
    rt = Runtime(seed=0)
    robot = FakeRobot(rt)
    robot.tf.send_transform = lambda *a, **k: None  # the robot publishes no odometry
    SlamGmapping(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=2.0)
    assert "no odometry for the scans on /scan: cannot look up odom -> base_link" in caplog.text


def test_scans_wait_for_a_late_laser_transform_and_a_missing_one_is_reported(caplog):
    # a static laser transform sent after the first scans (a static_transform_publisher that
    # starts later): the scans wait for it, quietly, as gmapping's tf::MessageFilter does
    rt = Runtime(seed=0)
    FakeRobot(rt, laser_tf_at=0.3)
    slam = SlamGmapping(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=2.0)
    assert slam.filter is not None and slam.filter.updates >= 1
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    # one that never comes is reported after a second, naming the topic and both frames
    rt = Runtime(seed=0)
    FakeRobot(rt, laser_tf_at=None)
    slam = SlamGmapping(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=2.0)
    assert slam.filter is None
    assert "cannot place the laser of /scan: no transform from base_link to its frame 'laser'" in (
        caplog.text
    )


def test_dynamic_map_before_any_scan_is_a_clear_error():
    rt = Runtime(seed=0)
    SlamGmapping(rt)
    client = Node(rt, "client").create_client(nav_msgs.GetMap, "dynamic_map")
    with pytest.raises(ServiceError, match="no map yet"):
        client.call(nav_msgs.GetMap.Request())


def test_map_saver_saves_the_slam_map(tmp_path):
    rt, robot, slam, out = world(params={"map_update_interval": 1.0, "linearUpdate": 0.5})
    rt.run(duration=20.0)
    saver = MapSaver(rt, args=["-f", str(tmp_path / "room")])
    rt.run(duration=0.1)
    assert saver.saved is not None
    saved = load_map(tmp_path / "room.yaml")
    grid = slam.grid_msg
    assert saved.data.shape == (grid.info.height, grid.info.width)
    assert saved.origin[:2] == pytest.approx(
        (grid.info.origin.position.x, grid.info.origin.position.y)
    )
    # occupied / free / unknown come back as they were published
    expected = np.asarray(grid.data).reshape(saved.data.shape)
    assert np.array_equal(saved.data == 100, expected == 100)
    assert np.array_equal(saved.data == -1, expected == -1)


def test_frame_parameters_are_strings_next_to_the_str_noise_parameter():
    rt = Runtime(seed=0)
    for key, value in {"base_frame": "base_footprint", "str": 0.3, "temporalUpdate": 3}.items():
        rt.params.set(f"/slam_gmapping/{key}", value)
    slam = SlamGmapping(rt)
    assert slam.base_frame == "base_footprint" and slam.params.str == 0.3
    assert slam.params.temporalUpdate == 3.0


def test_a_waiting_scan_is_retried_on_its_own_robots_odometry_only():
    # lizi1's scan waits for its odometry at its stamp; lizi2's transforms (10 Hz) do not wake
    # it, as amcl's scans wait on their own robot's edges; its own odometry does
    class CountingSlam(SlamGmapping):
        tries = 0

        def _process(self, scan):
            self.tries += 1
            return super()._process(scan)

    rt = Runtime(seed=0)
    for ns in ("lizi1", "lizi2"):
        rt.params.set(f"/{ns}/tf_prefix", ns)
    for key, value in FAST.items():
        rt.params.set(f"/lizi1/slam_gmapping/{key}", value)
    FakeRobot(rt, "/lizi2")
    slam = CountingSlam(rt, "slam_gmapping", "/lizi1")
    me = Node(rt, "driver", "/lizi1")
    odom = TransformBroadcaster(me)
    StaticTransformBroadcaster(me).send_transform(
        make_transform_stamped("lizi1/base_link", "lizi1/laser", 0.0, LASER, (0, 0, 0, 1))
    )

    def send_odom(t):
        odom.send_transform(
            make_transform_stamped("lizi1/odom", "lizi1/base_link", t, START, (0, 0, 0, 1))
        )

    send_odom(0.0)
    rt.run(duration=1.0)
    angles = -np.pi + 2 * np.pi / 360 * np.arange(360)
    ranges = exact_ranges(START + LASER, angles, 12.0).astype(np.float32)
    me.create_publisher(sensor_msgs.LaserScan, "scan", 1).publish(
        sensor_msgs.LaserScan(
            header=std_msgs.Header(stamp=Time.from_sec(1.0), frame_id="lizi1/laser"),
            angle_min=-np.pi, angle_max=np.pi - 2 * np.pi / 360,
            angle_increment=2 * np.pi / 360, range_min=0.05, range_max=12.0, ranges=ranges,
        )
    )  # fmt: skip
    rt.run(duration=1.0)  # lizi2's odometry only
    assert slam.tries == 1 and slam.filter is None
    send_odom(1.0)
    rt.run(duration=0.05)
    assert slam.tries == 2 and slam.filter is not None and slam.filter.updates == 1


def test_no_scan_for_10_s_is_said_naming_where_scans_are(caplog):
    """gmapping reading 'scan' while the laser publishes on 'base_scan' (the lizi): said after
    10 s, with the topic that has scans, instead of no map and no word."""
    rt = Runtime(seed=0)
    laser = Node(rt, "laser", "/lizi1").create_publisher(sensor_msgs.LaserScan, "base_scan", 1)
    assert laser.topic.name == "/lizi1/base_scan"
    SlamGmapping(rt, "slam_gmapping", "/lizi1")
    with caplog.at_level(logging.WARNING):
        rt.run(duration=9.5)
        assert "no scan" not in caplog.text
        rt.run(duration=1.0)
    assert (
        "no scan received on /lizi1/scan in 10 s (no publisher; LaserScan is published on "
        "/lizi1/base_scan): no map until one comes (remap 'scan' to the laser's topic)"
    ) in caplog.text
