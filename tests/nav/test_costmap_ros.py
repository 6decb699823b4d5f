"""Costmap2DROS: parameters under ~name, map and sensor topics, tf, update/publish, readiness."""

import math

import numpy as np
import pytest
from nav_world import GLOBAL, LOCAL, KinematicRobot, fill, room_grid, room_map

from fleetsim.msgs import geometry_msgs, nav_msgs, sensor_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.costmap import LETHAL_OBSTACLE, NO_INFORMATION
from fleetsim.nav.costmap.costmap_ros import Costmap2DROS, points_from_cloud2
from fleetsim.nav.errors import CostmapError
from fleetsim.nav.fake_localization import FakeLocalization
from fleetsim.nav.map_server import grid_msg_from_map
from fleetsim.runtime import Node, Runtime
from fleetsim.tf.patience import GRACE

COMMON = {  # a costmap_common_params.yaml in the lesson's style (pre-Hydro form)
    "obstacle_range": 2.5,
    "raytrace_range": 3.0,
    "robot_radius": 0.2,
    "inflation_radius": 0.4,
    "observation_sources": "scan",
    "scan": {"data_type": "LaserScan", "topic": "scan", "marking": True, "clearing": True},
}


class MapPub(Node):
    def __init__(self, rt, occupancy=None):
        super().__init__(rt, "map_server")
        self.pub = self.create_publisher(nav_msgs.OccupancyGrid, "map", 1, latch=True)
        self.pub.publish(grid_msg_from_map(occupancy or room_map(), "map"))


def host(rt, name, extra=None, remaps=None, ns="/lizi1"):
    base = GLOBAL if name == "global_costmap" else LOCAL
    rt.params.update(f"{ns}/move_base/{name}", {**COMMON, **base, **(extra or {})})
    node = Node(rt, "move_base", ns, remaps=remaps)
    return node, Costmap2DROS(node, name)


def world(name="global_costmap", extra=None, start=(1.0, 1.0, 0.0), remap=True, robot=True):
    rt = Runtime()
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    MapPub(rt)
    bot = KinematicRobot(rt, start=start) if robot else None
    FakeLocalization(rt, namespace="/lizi1")
    node, cm = host(rt, name, extra, {"map": "/map"} if remap else None)
    return rt, bot, node, cm


def test_global_costmap_reads_the_map_marks_walls_and_publishes():
    rt, bot, node, cm = world()
    assert (cm.global_frame, cm.robot_base_frame) == ("map", "lizi1/base_link")
    got = []
    Node(rt, "viewer").create_subscription(
        nav_msgs.OccupancyGrid, "/lizi1/move_base/global_costmap/costmap", got.append
    )
    foot = []
    Node(rt, "viewer2").create_subscription(
        geometry_msgs.PolygonStamped, "/lizi1/move_base/global_costmap/footprint", foot.append
    )
    rt.run(duration=1.05)
    assert cm.initialized and cm.is_current()
    m = cm.costmap
    assert (m.size_x, m.size_y, m.resolution) == (160, 120, 0.05)
    assert m.costs[0, 0] == LETHAL_OBSTACLE and m.costs[20, 80] == LETHAL_OBSTACLE  # wall x=4
    assert m.costs[60, 80] == 0  # the door
    assert 0 < m.costs[20, 74] < LETHAL_OBSTACLE  # inflated, 0.25 m from the wall
    assert m.costs[60, 40] == 0
    assert len(got) == 1 and got[0].header.frame_id == "map"
    assert got[0].data.reshape(120, 160)[0, 0] == 100
    assert foot and foot[-1].header.frame_id == "map"
    xs = [p.x for p in foot[-1].polygon.points]
    assert min(xs) == pytest.approx(1.0 - 0.21, abs=1e-3)  # radius 0.2 + padding 0.01


def test_map_topic_resolves_in_the_node_namespace_unless_remapped():
    rt, bot, node, cm = world(remap=False)
    assert [s.node for s in rt.graph.topics["/lizi1/map"].subscriptions] == [node]
    rt.run(duration=0.5)
    assert not cm.initialized  # nothing on /lizi1/map


def test_scan_marks_an_unmapped_obstacle_in_the_odom_frame_and_clears_it():
    extra = room_grid()
    fill(extra, 2.0, 0.8, 2.2, 1.2)  # a 0.2 m box 1 m ahead of the robot, not on the map
    rt, bot, node, cm = world("local_costmap", start=(1.0, 1.0, math.pi / 2))
    bot.set_world(extra)
    rt.run(duration=1.0)
    # odom is the start pose (yaw 90 deg): map (2.0..2.2, 0.8..1.2) is odom x -0.2..0.2, y -1..-1.2
    m = cm.costmap
    cell = m.world_to_map(0.0, -1.02)
    assert m.costs[cell[1], cell[0]] == LETHAL_OBSTACLE
    assert m.origin_x == pytest.approx(-1.5, abs=0.05) and m.size_x == 60
    bot.set_world(room_grid())  # the box is taken away
    rt.run(duration=1.0)
    assert m.costs[cell[1], cell[0]] < LETHAL_OBSTACLE


def test_pose_waits_for_tf_and_warns_when_it_stays_missing(caplog):
    rt, bot, node, cm = world(robot=False)
    rt.run(duration=GRACE - 0.5)
    assert cm.robot_pose() is None and not cm.initialized
    assert "WARNING" not in caplog.text  # waited for, as costmap_2d waits at start-up
    rt.run(duration=1.0)
    assert "cannot get the robot pose for 5." in caplog.text
    KinematicRobot(rt)  # tf arrives late: the costmap starts on its own
    rt.run(duration=0.5)
    assert cm.initialized


def test_transforms_late_by_less_than_the_grace_period_are_not_reported(caplog):
    rt, bot, node, cm = world(robot=False)
    rt.run(duration=1.0)  # no tf at all for 1 s: readings and poses wait quietly
    KinematicRobot(rt)
    rt.run(duration=1.0)
    assert cm.initialized
    assert "WARNING" not in caplog.text


def test_stale_tf_is_a_transform_timeout(caplog):
    rt, bot, node, cm = world(extra={"transform_tolerance": 0.3})
    rt.run(duration=0.5)
    assert cm.robot_pose() is not None
    bot.destroy()  # tf stops
    rt.run(duration=1.0)
    assert cm.robot_pose() is None
    assert "transform timeout" in caplog.text


def test_bare_global_frame_gets_the_prefix_and_a_hint(caplog):
    rt, bot, node, cm = world(extra={"global_frame": "map"})
    assert cm.global_frame == "lizi1/map"
    rt.run(duration=GRACE + 0.5)
    assert not cm.initialized
    assert "write '/map' for the shared frame" in caplog.text


def test_point_cloud_source_and_cloud_parsing():
    pts = np.array([[1.0, 2.0, 0.5], [np.nan, 0.0, 0.0], [-3.0, 0.25, 1.0]], dtype=np.float32)
    fields = [sensor_msgs.PointField(name=k, offset=4 * i, datatype=7, count=1)
              for i, k in enumerate("xyz")]  # fmt: skip
    cloud = sensor_msgs.PointCloud2(
        header=std_msgs.Header(frame_id="lizi1/laser", stamp=Time.from_sec(0.5)),
        height=1, width=3, fields=fields, point_step=12, row_step=36,
        data=np.frombuffer(pts.tobytes(), dtype=np.uint8),
    )  # fmt: skip
    got = points_from_cloud2(cloud)
    np.testing.assert_allclose(got, pts[[0, 2]].astype(np.float64))
    bad = sensor_msgs.PointCloud2(fields=fields[:2])
    with pytest.raises(CostmapError, match=r"no field\(s\) z"):
        points_from_cloud2(bad)
    extra = {"observation_sources": "cloud",
             "cloud": {"data_type": "PointCloud2", "topic": "points", "marking": True}}  # fmt: skip
    rt, bot, node, cm = world(extra=extra)
    pub = Node(rt, "camera", "/lizi1").create_publisher(sensor_msgs.PointCloud2, "points")
    rt.run(duration=0.5)
    pub.publish(cloud)  # laser at map (1.1, 1.0, 0.2): point (1, 2) lands at (2.1, 3.0)
    rt.run(duration=0.25)
    c = cm.costmap.world_to_map(2.1, 3.0)
    assert cm.costmap.costs[c[1], c[0]] == LETHAL_OBSTACLE


def test_old_point_cloud_type_is_refused():
    rt = Runtime()
    extra = {"observation_sources": "c", "c": {"data_type": "PointCloud", "topic": "c"}}
    with pytest.raises(CostmapError, match=r"lizi1/move_base/global_costmap/obstacle_layer/c: "
                       r"data_type PointCloud"):  # fmt: skip
        host(rt, "global_costmap", extra)


def test_expected_update_rate_makes_a_silent_sensor_stale(caplog):
    extra = {"scan": {**COMMON["scan"], "expected_update_rate": 0.3}}
    rt, bot, node, cm = world(extra=extra)
    rt.run(duration=0.6)
    assert cm.is_current()
    bot.scan_timer.cancel()
    rt.run(duration=0.6)
    assert not cm.is_current()
    assert "'scan' (/lizi1/scan) has not been updated" in caplog.text


def test_reset_stop_start_and_full_update_after_a_direct_clear():
    extra = room_grid()
    fill(extra, 2.0, 0.8, 2.2, 1.2)
    rt, bot, node, cm = world()
    bot.set_world(extra)
    rt.run(duration=0.6)
    c = cm.costmap.world_to_map(2.05, 1.0)
    assert cm.costmap.costs[c[1], c[0]] == LETHAL_OBSTACLE
    layer = cm.layered.layer("obstacle_layer")
    layer.grid.costs[:] = NO_INFORMATION  # what a clearing recovery does to the layer
    cm.mark_full_update()
    bot.scan_timer.cancel()  # no new readings
    layer.buffers["scan"].observations = []
    cm.update()
    assert cm.costmap.costs[c[1], c[0]] == 0
    cm.stop()
    assert not cm.is_current() and not cm.update()
    cm.start()
    assert cm.update() and cm.is_current()
    cm.reset_layers()
    assert cm.update() and cm.costmap.costs[0, 0] == LETHAL_OBSTACLE


def count_readings(layer):
    """Wrap the layer's add_observation to count the readings read into it."""
    calls = []
    add = layer.add_observation
    layer.add_observation = lambda *a, **k: (calls.append(a[-1]), add(*a, **k))
    return calls


@pytest.mark.parametrize("persistence", [0.0, 1.0])
def test_readings_are_read_at_the_update_unless_they_persist(persistence):
    extra = room_grid()
    fill(extra, 2.0, 0.8, 2.2, 1.2)  # a box 1 m ahead, not on the map
    scan = {**COMMON["scan"], "observation_persistence": persistence}
    rt, bot, node, cm = world(extra={"scan": scan, "update_frequency": 2.0})
    bot.set_world(extra)
    calls = count_readings(cm.layered.layer("obstacle_layer"))
    rt.run(duration=2.0)  # 20 scans at 10 Hz, 4 updates at 2 Hz
    if persistence:  # every reading within the window counts: each is read as it comes
        # (the first, at 0.1 s, before fake_localization's first map -> odom, is dropped)
        assert calls == pytest.approx([0.1 * k for k in range(2, 21)])
    else:  # only the newest counts: one read per update, the newest
        assert len(calls) == 4
        assert calls[-1] == pytest.approx(rt.now())  # the scan of the same instant, first
    box = cm.costmap.world_to_map(2.01, 1.0)  # the face the laser sees
    assert cm.costmap.costs[box[1], box[0]] == LETHAL_OBSTACLE
    assert cm.is_current()


def _window_over_map(odom_in_map: str) -> Costmap2DROS:
    """A 3 m local costmap in lizi1/odom whose only layer is the map's (`room_map`), after a
    second; odom is at ``odom_in_map`` ("x y z yaw pitch roll") in the map, the robot at
    odom's origin."""
    from fleetsim.tf.static_transform_publisher import StaticTransformPublisher

    rt = Runtime()
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    MapPub(rt)
    KinematicRobot(rt, start=(3.0, 1.0, 0.0))
    StaticTransformPublisher(rt, args=f"{odom_in_map} map lizi1/odom 100")
    extra = {
        "plugins": [{"name": "static_layer", "type": "costmap_2d::StaticLayer"}],
        "static_layer": {"map_topic": "/map"},
    }
    _, cm = host(rt, "local_costmap", extra)
    rt.run(duration=1.05)
    return cm


@pytest.mark.parametrize("shift", [(0.0, 0.0), (0.3, 0.0), (-0.2, 0.25)])
def test_a_rolling_window_places_the_map_by_tf(shift, caplog):
    """A local costmap in odom with a static layer, the map in `map`: odom starts at the robot's
    start (3, 1), and map -> odom is off by ``shift`` (amcl's correction). The map's wall at
    x = 4 lies at 1 - shift[0] in odom, as costmap_2d's StaticLayer transforms each cell of a
    rolling window by tf. fleetsim used the map as if it were in odom (the wall then fell at
    x = 4, outside the 3 m window) and warned so at start."""
    sx, sy = shift
    cm = _window_over_map(f"{3.0 + sx} {1.0 + sy} 0 0 0 0")
    assert cm.initialized
    m = cm.costmap
    col = int((1.0 - sx - m.origin_x) / m.resolution)  # the wall's cell in odom
    row = int((-sy - m.origin_y) / m.resolution)  # map y = 1.0
    assert m.costs[row, col] == LETHAL_OBSTACLE
    assert m.costs[row, col - 3] != LETHAL_OBSTACLE  # 0.15 m before it: free
    assert m.costs[row, col + 3] != LETHAL_OBSTACLE  # and after it
    assert not [r for r in caplog.records if "as if it were in the global frame" in r.message]


@pytest.mark.parametrize("yaw", [math.pi / 2, -math.pi / 2])
def test_a_rolling_window_turned_from_the_map_places_it_by_tf(yaw):
    """odom turned a quarter from the map at (3, 1): the map's wall at x = 4 runs across the
    window at odom y = -1 (yaw +90 degrees) or +1 (-90), and not on the other side."""
    cm = _window_over_map(f"3.0 1.0 0 {yaw} 0 0")
    m = cm.costmap
    side = -1.0 if yaw > 0 else 1.0
    col = int((0.0 - m.origin_x) / m.resolution)
    wall = int((side - m.origin_y) / m.resolution)
    mirror = int((-side - m.origin_y) / m.resolution)
    assert LETHAL_OBSTACLE in m.costs[wall - 1 : wall + 2, col]
    assert LETHAL_OBSTACLE not in m.costs[mirror - 2 : mirror + 3, col]


def test_a_source_that_never_gets_a_reading_is_warned_about_naming_what_is_published(caplog):
    """A source reading a topic nobody publishes (the laser is on ``scan``, the source on
    ``base_scan``) marks nothing: after SILENT_AFTER s a warning names the topic and where its
    type is published; a source that gets readings is not warned about."""
    from fleetsim.nav.costmap.sources import SILENT_AFTER

    extra = {"scan": {**COMMON["scan"], "topic": "base_scan"}}
    rt, bot, node, cm = world("local_costmap", extra=extra)
    rt.run(duration=SILENT_AFTER - 1.0)
    assert "no reading" not in caplog.text  # not before its time
    rt.run(duration=2.0)
    assert (
        "obstacle_layer/scan: no reading on /lizi1/base_scan in 1" in caplog.text
        and "(no publisher; LaserScan is published on /lizi1/scan)" in caplog.text
    ), caplog.text
    caplog.clear()
    rt2, *_ = world("local_costmap")  # the source on the laser's topic
    rt2.run(duration=SILENT_AFTER + 2.0)
    assert "no reading" not in caplog.text, caplog.text


def test_a_sensor_frame_tf_never_has_is_warned_about(caplog):
    """A ``sensor_frame`` typo: every reading is dropped (no origin to clear from), and the
    warning names the sensor frame, though the message's own frame is found each time."""
    extra = {"scan": {**COMMON["scan"], "sensor_frame": "laser_link"}}
    rt, bot, node, cm = world("local_costmap", extra=extra)
    rt.run(duration=GRACE + 2.0)
    assert "(sensor_frame) in frame 'lizi1/laser_link'" in caplog.text, caplog.text


def test_a_costmap_shut_down_until_a_goal_does_not_call_its_laser_silent(caplog):
    """shutdown_costmaps: the costmaps stop at start-up and start with the first goal, 15 s
    later; the laser was heard meanwhile, so the first updates warn of no silent source."""
    rt, bot, node, cm = world("local_costmap")
    cm.stop()  # before any reading
    rt.run(duration=15.0)
    cm.start()
    cm.update()  # the first update after the start, before the laser's next reading
    rt.run(duration=1.0)
    assert "no reading" not in caplog.text, caplog.text
