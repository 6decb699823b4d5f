"""Tests for fleetsim.localization.amcl.node: the amcl node in a runtime, on the synthetic world.

A fake robot node drives the synthetic route, publishing ``odom -> base_link`` on /tf, a static
``base_link -> laser`` and 360-beam scans at 10 Hz; a fake map server answers ``/static_map``.
"""

import logging

import numpy as np
import pytest
from amcl_world import ROUTE, drive, exact_ranges, world_map

from fleetsim.localization.amcl.node import Amcl
from fleetsim.msgs import geometry_msgs, nav_msgs, sensor_msgs, std_msgs, std_srvs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster, make_transform_stamped

LASER = np.array([0.2, 0.0, 0.0])  # laser in base_link


def grid_msg():
    g = world_map()
    data = np.where(g.occ_state == 1, 100, 0).astype(np.int8).ravel()
    info = nav_msgs.MapMetaData(resolution=g.resolution, width=g.width, height=g.height)
    return nav_msgs.OccupancyGrid(header=std_msgs.Header(frame_id="map"), info=info, data=data)


class FakeMapServer(Node):
    def __init__(self, rt):
        super().__init__(rt, "map_server")
        self.map = grid_msg()
        self.create_service(nav_msgs.GetMap, "static_map", self.on_get)

    def on_get(self, req):
        return nav_msgs.GetMap.Response(map=self.map)


class FakeRobot(Node):
    """Drives ``route``; true pose, drifting odometry, tf and scans at 10 Hz."""

    def __init__(self, rt, ns, route, seed=0, start_offset=(0.0, 0.0)):
        super().__init__(rt, "fake_robot", ns)
        self.rng = np.random.default_rng(seed)
        self.route = np.asarray(route) + np.asarray(start_offset)
        self.steps = drive(self.route, self.rng)
        self.true, self.odom = next(self.steps)
        self.offset = np.zeros(3)  # teleport offset (kidnapping)
        self.tf = TransformBroadcaster(self)
        StaticTransformBroadcaster(self).send_transform(
            make_transform_stamped(self.frame("base_link"), self.frame("laser"), 0.0, LASER)
        )
        self.scan_pub = self.create_publisher(sensor_msgs.LaserScan, "scan", queue_size=1)
        self.create_timer(0.1, self.tick, priority=-50)
        self.tick()

    def pose(self):
        return self.true + self.offset

    def tick(self):
        if self.now() > 0:
            self.true, self.odom = next(self.steps, (self.true, self.odom))
        t = self.now()
        q = (0.0, 0.0, np.sin(self.odom[2] / 2), np.cos(self.odom[2] / 2))
        self.tf.send_transform(
            make_transform_stamped(
                self.frame("odom"), self.frame("base_link"), t, (*self.odom[:2], 0.0), q
            )
        )
        p = self.pose()
        c, s = np.cos(p[2]), np.sin(p[2])
        sensor = p + np.array([c * LASER[0], s * LASER[0], 0.0])
        n = 360
        inc = 2 * np.pi / n
        ranges = exact_ranges(sensor, -np.pi + inc * np.arange(n), 10.0)
        ranges = ranges + 0.01 * self.rng.standard_normal(n)
        ranges[::37] = np.nan  # dropouts, as real lasers report them
        self.scan_pub.publish(
            sensor_msgs.LaserScan(
                header=std_msgs.Header(stamp=Time.from_sec(t), frame_id=self.frame("laser")),
                angle_min=-np.pi,
                angle_max=np.pi - inc,
                angle_increment=inc,
                range_min=0.05,
                range_max=10.0,
                ranges=ranges.astype(np.float32),
            )
        )


class Listener(Node):
    def __init__(self, rt, ns):
        super().__init__(rt, "listener", ns)
        self.poses, self.clouds = [], []
        self.create_subscription(
            geometry_msgs.PoseWithCovarianceStamped, "amcl_pose", self.poses.append
        )
        self.create_subscription(geometry_msgs.PoseArray, "particlecloud", self.clouds.append)


def robot_world(ns="/lizi1", prefix="lizi1", amcl_params=None, seed=0, route=ROUTE):
    rt = Runtime(seed=seed)
    rt.params.set(f"{ns}/tf_prefix", prefix)
    for key, value in (amcl_params or {}).items():
        rt.params.set(f"{ns}/amcl/{key}", value)  # as <param name="amcl/initial_pose_x">
    FakeMapServer(rt)
    robot = FakeRobot(rt, ns, route, seed=seed)
    amcl = Amcl(rt, "amcl", ns, remaps={"static_map": "/static_map"})
    return rt, robot, amcl, Listener(rt, ns)


def map_pose_of_base(rt, prefix):
    return np.array(rt.tf_buffer.lookup_pose2d("map", f"{prefix}/base_link", 0.0))


def test_tracks_under_a_namespace_and_publishes_tf_pose_and_cloud():
    rt, robot, amcl, out = robot_world(
        amcl_params={"initial_pose_x": 1.5, "initial_pose_y": 5.0, "laser_max_beams": 60}
    )
    assert (amcl.odom_frame, amcl.base_frame, amcl.global_frame) == (
        "lizi1/odom",
        "lizi1/base_link",
        "map",
    )
    errors = []
    for _ in range(30):
        rt.run(duration=2.0)
        est = map_pose_of_base(rt, "lizi1")  # through map -> lizi1/odom -> lizi1/base_link
        errors.append(np.hypot(*(est[:2] - robot.true[:2])))
    assert np.mean(errors) < 0.12 and max(errors) < 0.3
    last = out.poses[-1]
    assert last.header.frame_id == "map" and last.pose.covariance.shape == (36,)
    assert last.pose.covariance[0] > 0 and last.pose.covariance[35] > 0
    pos = last.pose.pose.position
    assert np.hypot(pos.x - robot.true[0], pos.y - robot.true[1]) < 0.3
    cloud = out.clouds[-1]
    assert cloud.header.frame_id == "map" and len(cloud.poses) == amcl.filter.particle_count
    # the map -> odom transform is dated transform_tolerance ahead of the scan
    info = rt.tf_buffer.frame_info("lizi1/odom")
    assert info.parent == "map" and info.most_recent == pytest.approx(rt.now() + 0.1, abs=0.11)
    # save_pose_rate stores the estimate for the next start
    assert abs(rt.params.get("/lizi1/amcl/initial_pose_x") - robot.true[0]) < 0.5


def test_particlecloud_is_built_only_for_a_reader_and_kept_for_a_late_one():
    rt = Runtime(seed=0)
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    rt.params.set("/lizi1/amcl/initial_pose_x", 1.5)
    rt.params.set("/lizi1/amcl/initial_pose_y", 5.0)
    FakeMapServer(rt)
    FakeRobot(rt, "/lizi1", ROUTE)
    amcl = Amcl(rt, "amcl", "/lizi1", remaps={"static_map": "/static_map"})
    rt.run(duration=4.0)
    assert amcl.cloud_pub._last is None  # nobody subscribed: no PoseArray was built
    particles = amcl.filter.particles.copy()  # as of the last update, which published
    late = Listener(rt, "/lizi1")  # subscribes to the latched particlecloud now
    rt.run(duration=0.01)
    assert len(late.clouds) == 1
    got = np.array([[p.position.x, p.position.y] for p in late.clouds[0].poses])
    np.testing.assert_allclose(got, particles[:, :2])
    yaw = [2 * np.arctan2(p.orientation.z, p.orientation.w) for p in late.clouds[0].poses]
    np.testing.assert_allclose(np.cos(yaw), np.cos(particles[:, 2]), atol=1e-9)


def test_initialpose_topic_and_services():
    rt, robot, amcl, out = robot_world(amcl_params={"initial_pose_x": 8.0, "initial_pose_y": 2.0})
    helper = Node(rt, "helper")
    pub = helper.create_publisher(geometry_msgs.PoseWithCovarianceStamped, "/lizi1/initialpose")
    rt.run(duration=0.5)
    assert np.hypot(*(amcl.filter.estimate.pose[:2] - [8.0, 2.0])) < 0.5  # params, not truth
    msg = geometry_msgs.PoseWithCovarianceStamped(header=std_msgs.Header(frame_id="map"))
    msg.pose.pose.position.x, msg.pose.pose.position.y = robot.true[:2]
    yaw = robot.true[2]
    msg.pose.pose.orientation = geometry_msgs.Quaternion(z=np.sin(yaw / 2), w=np.cos(yaw / 2))
    cov = np.zeros(36)
    cov[0] = cov[7] = 0.04
    cov[35] = 0.02
    msg.pose.covariance = cov
    pub.publish(msg)
    rt.run(duration=6.0)
    assert np.hypot(*(map_pose_of_base(rt, "lizi1")[:2] - robot.true[:2])) < 0.2
    # a no-motion update runs the sensor model on the next scan without motion
    helper.create_client(std_srvs.Empty, "/lizi1/request_nomotion_update").call()
    assert amcl.filter.force_update
    rt.run(duration=0.15)
    assert not amcl.filter.force_update
    # global localization spreads particles over the free space
    helper.create_client(std_srvs.Empty, "/lizi1/global_localization").call()
    assert amcl.filter.particle_count == amcl.params.max_particles and not amcl.filter.converged
    # set_map: a new map and a pose in one call
    req = nav_msgs.SetMap.Request(map=grid_msg(), initial_pose=msg)
    resp = helper.create_client(nav_msgs.SetMap, "/lizi1/set_map").call(req)
    assert resp.success
    mean = amcl.filter.particles[:, :2].mean(axis=0)
    assert np.hypot(mean[0] - msg.pose.pose.position.x, mean[1] - msg.pose.pose.position.y) < 0.05


def test_bad_input_is_logged_not_raised(caplog):
    rt = Runtime()
    rt.params.set("/amcl/initial_pose_x", 50.0)  # off the 16 m x 10 m map
    helper = Node(rt, "helper")
    robot = FakeRobot(rt, "/", ROUTE)
    with caplog.at_level(logging.WARNING):
        amcl = Amcl(rt, "amcl")  # no map server yet
        rt.run(duration=0.5)
        assert "no service" not in caplog.text  # map_server may start a moment later
        rt.run(duration=0.7)
        assert "waiting for the map: no service /static_map; start map_server" in caplog.text
        assert "received a scan but no map yet" in caplog.text
        FakeMapServer(rt)
        rt.run(duration=1.5)
    assert amcl.map_received
    assert "initial pose (50.000, 0.000) is outside the map" in caplog.text
    assert amcl.filter.particle_count == amcl.params.max_particles  # fell back to global
    pub = helper.create_publisher(geometry_msgs.PoseWithCovarianceStamped, "/initialpose")
    wrong = geometry_msgs.PoseWithCovarianceStamped(header=std_msgs.Header(frame_id="odom"))
    pub.publish(wrong)
    far = geometry_msgs.PoseWithCovarianceStamped(header=std_msgs.Header(frame_id="map"))
    far.pose.pose.position.x = -40.0
    pub.publish(far)
    bad_map = grid_msg()
    bad_map.info.width = 3
    with caplog.at_level(logging.WARNING):
        rt.run(duration=0.3)
        resp = helper.create_client(nav_msgs.SetMap, "/set_map").call(
            nav_msgs.SetMap.Request(map=bad_map)
        )
    assert not resp.success
    assert "ignoring initial pose in frame 'odom'" in caplog.text
    assert "ignoring initial pose: amcl: initial pose (-40.000" in caplog.text
    assert "ignoring map" in caplog.text and "data has" in caplog.text
    assert robot.true is not None


def test_three_robots_with_per_robot_initial_poses():
    rt = Runtime(seed=3)
    FakeMapServer(rt)
    robots, amcls = [], []
    for k, start in enumerate((0, 2, 4), start=1):  # route waypoints the robots start at
        ns = f"/lizi{k}"
        x, y = ROUTE[start]
        rt.params.set(f"{ns}/tf_prefix", f"lizi{k}")
        rt.params.set(f"{ns}/amcl/initial_pose_x", float(x))
        rt.params.set(f"{ns}/amcl/initial_pose_y", float(y))
        dx, dy = ROUTE[start + 1] - ROUTE[start]
        rt.params.set(f"{ns}/amcl/initial_pose_a", float(np.arctan2(dy, dx)))
        route = np.roll(ROUTE[:-1], -start, axis=0)
        robots.append(FakeRobot(rt, ns, route, seed=k))
        amcls.append(Amcl(rt, "amcl", ns, remaps={"static_map": "/static_map"}))
    rt.run(duration=20.0)
    for k, robot in enumerate(robots, start=1):
        est = map_pose_of_base(rt, f"lizi{k}")
        assert np.hypot(*(est[:2] - robot.true[:2])) < 0.25


def test_map_topic_first_map_only_throttle_and_no_tf():
    rt = Runtime()
    rt.params.set(
        "/amcl",
        {
            "use_map_topic": True,
            "first_map_only": True,
            "gui_publish_rate": 1.0,
            "tf_broadcast": False,
            "initial_pose_x": 1.5,
            "initial_pose_y": 5.0,
            "update_min_d": 0.05,
        },
    )
    helper = Node(rt, "helper")
    map_pub = helper.create_publisher(nav_msgs.OccupancyGrid, "/map", latch=True)
    map_pub.publish(grid_msg())  # latched: delivered when amcl subscribes
    FakeRobot(rt, "/", ROUTE)
    amcl = Amcl(rt, "amcl")
    out = Listener(rt, "/")
    rt.run(duration=5.0)
    assert amcl.map_received and "/static_map" not in rt.graph.services
    first = amcl.filter.grid
    other = grid_msg()
    other.data = np.zeros_like(other.data)
    map_pub.publish(other)
    rt.run(duration=0.2)
    assert amcl.filter.grid is first  # first_map_only
    assert 4 <= len(out.clouds) <= 6  # about 1 Hz over 5 s although the filter updated more
    assert len(out.poses) > 8
    assert not rt.tf_buffer.can_transform("map", "odom")  # tf_broadcast false


def test_a_scan_ahead_of_its_odometry_waits_for_tf_without_amcl_reading_all_of_tf():
    rt, robot, amcl, out = robot_world(
        amcl_params={"initial_pose_x": 1.5, "initial_pose_y": 5.0, "laser_max_beams": 60}
    )
    rt.run(duration=0.55)
    # amcl is told by the tf buffer when tf changes; it does not get every /tf message itself
    assert all(sub.node is not amcl for sub in rt.graph.topics["/tf"].subscriptions)
    scan = sensor_msgs.LaserScan(
        header=std_msgs.Header(stamp=Time.from_sec(0.58), frame_id="lizi1/laser"),
        angle_min=-np.pi, angle_max=np.pi, angle_increment=2 * np.pi / 360,
        range_min=0.05, range_max=10.0, ranges=np.full(360, 5.0, np.float32),
    )  # fmt: skip
    amcl.on_scan(scan)  # odometry is known up to 0.5 s: the scan waits
    assert len(amcl._pending_scans) == 1
    rt.run(duration=0.1)  # the robot's tf at 0.6 s lets it through, before the robot's own scan
    assert len(amcl._pending_scans) == 0


def test_an_amcl_in_a_namespace_is_told_to_remap_static_map(caplog):
    # the lesson's amcl_node.xml in <group ns="lizi1"> asks for /lizi1/static_map
    rt = Runtime()
    FakeMapServer(rt)
    with caplog.at_level(logging.WARNING):
        amcl = Amcl(rt, "amcl", "/lizi1")
        rt.run(duration=1.5)
    assert not amcl.map_received
    assert (
        "no service /lizi1/static_map, but /static_map is there; add "
        '<remap from="static_map" to="/static_map"/>' in caplog.text
    )


def test_an_amcl_reading_a_topic_nobody_publishes_says_so(caplog):
    """amcl on ``scan`` while the laser publishes ``base_scan``: after SILENT_AFTER s without a
    scan it warns, naming where scans are published; an amcl that gets scans does not."""
    from fleetsim.runtime.node import SILENT_AFTER

    rt = Runtime(seed=0)
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    FakeMapServer(rt)
    FakeRobot(rt, "/lizi1", ROUTE, seed=0)
    Amcl(rt, "amcl", "/lizi1", remaps={"static_map": "/static_map", "scan": "base_scan"})
    with caplog.at_level(logging.WARNING):
        rt.run(duration=SILENT_AFTER + 0.5)
    assert (
        "no scan received on /lizi1/base_scan in 10 s (no publisher; LaserScan is published on "
        "/lizi1/scan)" in caplog.text
    ), caplog.text
    caplog.clear()
    rt2, *_ = robot_world()
    with caplog.at_level(logging.WARNING):
        rt2.run(duration=SILENT_AFTER + 0.5)
    assert "no scan received" not in caplog.text
