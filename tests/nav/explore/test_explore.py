"""Tests for fleetsim.nav.explore.explore: explore_lite over move_base and slam_gmapping."""

import logging
import math
from pathlib import Path

import numpy as np
import pytest

from fleetsim.cli.launch import resolve_launch_file
from fleetsim.launch.registry import resolve_node
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import geometry_msgs, move_base_msgs, nav_msgs, std_msgs, visualization_msgs
from fleetsim.nav.explore import Explore, frontiers_from_grid
from fleetsim.nav.map_io import load_map
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, make_transform_stamped


def test_registered_as_explore_lite_explore():
    assert resolve_node("explore_lite", "explore") is Explore


class FakeWorld(Node):
    """A costmap with one frontier and a robot at (0.35, 1.05); no move_base."""

    def __init__(self, rt, data):
        super().__init__(rt, "fake_world")
        pub = self.create_publisher(nav_msgs.OccupancyGrid, "costmap", 1, latch=True)
        info = nav_msgs.MapMetaData(resolution=0.1, width=data.shape[1], height=data.shape[0])
        pub.publish(
            nav_msgs.OccupancyGrid(
                header=std_msgs.Header(frame_id="map"), info=info, data=data.ravel()
            )
        )
        StaticTransformBroadcaster(self).send_transform(
            make_transform_stamped("map", "base_link", 0.0, (0.35, 1.05, 0.0))
        )


def test_without_move_base_it_waits_and_a_closed_map_stops_it(caplog):
    data = np.full((20, 30), -1, dtype=np.int8)
    data[:, :10] = 0
    rt = Runtime(seed=0)
    rt.params.set("/explore/visualize", True)
    FakeWorld(rt, data)
    markers = []
    rt.graph.subscribe("/explore/frontiers", visualization_msgs.MarkerArray, markers.append)
    ex = Explore(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=2.5)
    assert "waiting for move_base at /move_base" in caplog.text
    assert ex.goals_sent == 0 and not ex.finished and len(ex.frontiers) == 1
    assert markers and len(markers[-1].markers) == 2  # DELETEALL + one frontier
    # everything known: no frontier left, exploration stops
    ex.grid.data = np.zeros(600, dtype=np.int8)
    rt.run(duration=1.0)
    assert ex.finished and ex.succeeded


def test_a_costmap_without_unknown_space_is_said_and_not_explored(caplog):
    """A costmap not tracking unknown space (track_unknown_space false) has no frontier: it
    is named and exploration fails, rather than stopping at once as if all were explored."""
    rt = Runtime(seed=0)
    FakeWorld(rt, np.zeros((20, 30), dtype=np.int8))
    ex = Explore(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=2.5)
    assert ex.finished and not ex.succeeded and ex.goals_sent == 0
    assert "the costmap on /costmap has no unknown cell" in caplog.text
    assert "track_unknown_space: true" in caplog.text


def test_a_costmap_topic_nobody_publishes_is_named(caplog):
    rt = Runtime(seed=0)
    rt.params.set("/explore/costmap_topic", "costmap_typo")
    FakeWorld(rt, np.full((20, 30), -1, dtype=np.int8))
    Explore(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=9.0)
        assert "no costmap" not in caplog.text
        rt.run(duration=2.0)
    assert "no costmap on /costmap_typo in 10 s (no publisher; OccupancyGrid is published on " in (
        caplog.text
    )
    assert "/costmap" in caplog.text


@pytest.mark.scenario
def test_slam_explore_drives_the_hunter_to_frontiers_of_its_own_map(caplog, tmp_path):
    out = tmp_path / "office_slam"
    plan = load_plan(resolve_launch_file("slam_explore"), {"map_out": str(out)})
    with caplog.at_level(logging.WARNING), LaunchSession(plan, seed=1) as s:
        ex = s.nodes["/explore"]
        path = []
        for _ in range(25):
            s.runtime.run(duration=1.0)
            path.append(s.monitor.sim.engine.model_pose("robocluedo_robot")[0][:2])
        slam = s.nodes["/slam_gmapping"].grid_msg
        assert not out.with_suffix(".yaml").exists()  # written when the run ends
        assert not s.monitor.all_goals_done()  # exploring: the explorer is not done
    assert ex.goals_sent >= 2 and ex.frontiers and not ex.finished
    saved = load_map(out.with_suffix(".yaml"))
    assert saved.data.shape == (slam.info.height, slam.info.width)
    # it drove (with explore_lite's potential_scale 3 it first clears the frontiers round its
    # start, turning between them, rather than heading down the corridor)
    assert np.hypot(*np.diff(path, axis=0).T).sum() > 5.0
    known = np.count_nonzero(np.asarray(slam.data) >= 0) * slam.info.resolution**2
    assert known > 60.0  # m^2 mapped
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    assert not Path("MUJOCO_LOG.TXT").exists()


@pytest.mark.scenario
def test_slam_explore_two_hunters_explore_through_the_merged_map(caplog, tmp_path):
    out = tmp_path / "merged"
    plan = load_plan(resolve_launch_file("slam_explore"), {"robots": "2", "map_out": str(out)})
    with caplog.at_level(logging.WARNING), LaunchSession(plan, seed=1) as s:
        s.runtime.run(duration=20.0)
        explorers = [s.nodes[f"/hunter{i}/explore"] for i in (1, 2)]
        merged = s.nodes["/map_merge"].merged
        own = [s.nodes[f"/hunter{i}/slam_gmapping"].grid_msg for i in (1, 2)]
        costmap = s.nodes["/hunter2/move_base"].global_costmap
        engine = s.monitor.sim.engine
        starts = [engine.model_pose(f"hunter{i}")[0] for i in (1, 2)]  # where they are now
        driven = [r.path_length for r in sorted(s.monitor.results(), key=lambda r: r.namespace)]
    # each maps on its own, in its own frame ...
    assert [g.header.frame_id for g in own] == ["hunter1/map", "hunter2/map"]
    # ... the merged map (frame map) holds both, and each explorer works on it
    assert merged is not None and merged.header.frame_id == "map"
    data = np.asarray(merged.data).reshape(merged.info.height, merged.info.width)
    o, res = merged.info.origin.position, merged.info.resolution
    for x, y, _ in starts:  # the space round both robots is mapped (their lasers look ahead)
        i, j = int((y - o.y) / res), int((x - o.x) / res)
        assert np.count_nonzero(data[i - 20 : i + 20, j - 20 : j + 20] == 0) > 400
    known = [np.count_nonzero(np.asarray(g.data) >= 0) for g in own]
    assert np.count_nonzero(data >= 0) > max(known) + 0.5 * min(known)  # both contribute
    assert costmap.global_frame == "map"
    for ex in explorers:
        assert ex.goals_sent >= 1 and ex.grid.header.frame_id == "map"
    # both drove (an explorer may bring its robot back near its start: path length, not the
    # distance from the start), and each stays on its side, west and east of the corridor
    assert all(d > 1.5 for d in driven), driven
    assert starts[0][0] < starts[1][0]
    saved = load_map(out.with_suffix(".yaml"))  # the merged map is the one saved
    assert saved.data.shape == data.shape
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    assert not Path("MUJOCO_LOG.TXT").exists()


@pytest.mark.scenario
def test_slam_explore_with_a_lizi_maps_in_its_own_frame(caplog, tmp_path):
    # robot:=lizi alone: in namespace lizi1, its gmapping on base_scan (a 270-degree laser 1 m
    # up, published by a static transform that may come after the first scan), its global
    # costmap in lizi1/map (the lizi's file names the shared /map of its amcl scenarios)
    out = tmp_path / "lizi_slam"
    plan = load_plan(resolve_launch_file("slam_explore"), {"robot": "lizi", "map_out": str(out)})
    with caplog.at_level(logging.WARNING), LaunchSession(plan, seed=1) as s:
        s.runtime.run(duration=20.0)
        ex = s.nodes["/lizi1/explore"]
        slam = s.nodes["/lizi1/slam_gmapping"]
        grid = slam.grid_msg
        costmap = s.nodes["/lizi1/move_base"].global_costmap
        pos = s.monitor.sim.engine.model_pose("lizi1")[0]
        est = s.runtime.tf_buffer.lookup_pose2d("lizi1/map", "lizi1/base_link", 0.0)
    assert grid.header.frame_id == "lizi1/map" and costmap.global_frame == "lizi1/map"
    assert slam.filter.updates > 5 and ex.goals_sent >= 2 and not ex.finished
    assert math.hypot(pos[0] - 4.0, pos[1] - 10.0) > 3.0  # it drove off
    # the map frame starts on the odometry's, i.e. the world's: the estimate is the true pose
    assert math.hypot(est[0] - pos[0], est[1] - pos[1]) < 0.15
    known = np.count_nonzero(np.asarray(grid.data) >= 0) * grid.info.resolution**2
    assert known > 100.0  # m^2 mapped
    saved = load_map(out.with_suffix(".yaml"))  # map_saver reads lizi1/map
    assert saved.data.shape == (grid.info.height, grid.info.width)
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    assert not Path("MUJOCO_LOG.TXT").exists()


class GoalSink(Node):
    """A move_base that accepts every goal and never finishes one."""

    def __init__(self, rt):
        super().__init__(rt, "move_base")
        self.goals = []
        self.server = self.create_action_server(
            move_base_msgs.MoveBase, "move_base", goal_callback=self.on_goal
        )

    def on_goal(self):
        p = self.server.accept_new_goal().target_pose.pose.position
        self.goals.append((round(p.x, 2), round(p.y, 2)))


def test_a_frontier_a_peer_explorer_heads_for_is_left_to_it():
    data = np.full((20, 30), -1, dtype=np.int8)
    data[:, :10] = 0  # known room x < 1 m: its east edge (20 cells) is the big frontier
    data[:4, :6] = -1  # ... and a small one round an unknown corner at its south-west
    big, small = frontiers_from_grid(data, 0.1, (0.0, 0.0), (0.35, 1.05))
    big_goal, small_goal = (tuple(round(v, 2) for v in f.centroid) for f in (big, small))
    rt = Runtime(seed=0)
    rt.params.set("/explore/peer_goals", ["/peer/goal"])
    rt.params.set("/explore/peer_radius", 0.5)
    FakeWorld(rt, data)
    sink = GoalSink(rt)
    peer = Node(rt, "peer").create_publisher(
        geometry_msgs.PointStamped, "/peer/goal", 1, latch=True
    )
    announced = []
    rt.graph.subscribe("/explore/goal", geometry_msgs.PointStamped, announced.append)
    peer.publish(geometry_msgs.PointStamped(point=geometry_msgs.Point(x=1.2, y=1.0)))
    Explore(rt)
    rt.run(duration=1.5)
    assert sink.goals == [small_goal]  # the big frontier is the peer's
    assert (announced[-1].point.x, announced[-1].point.y) == pytest.approx(small.centroid)
    # the peer is done: the big frontier is free again
    peer.publish(geometry_msgs.PointStamped(point=geometry_msgs.Point(x=math.nan, y=math.nan)))
    rt.run(duration=1.0)
    assert sink.goals[-1] == big_goal


def test_a_frontier_nearer_to_a_peer_robot_is_left_to_it():
    data = np.full((20, 30), -1, dtype=np.int8)
    data[:, :10] = 0  # the big frontier along x = 1 m, nearer to the peer at x = 1.5 m
    data[:4, :6] = -1  # the small one at the south-west, nearer to this robot
    big, small = frontiers_from_grid(data, 0.1, (0.0, 0.0), (0.35, 1.05))
    big_goal, small_goal = (tuple(round(v, 2) for v in f.centroid) for f in (big, small))
    rt = Runtime(seed=0)
    rt.params.set("/explore/peer_frames", ["peer/base_link"])
    FakeWorld(rt, data)
    sink = GoalSink(rt)
    peer_tf = StaticTransformBroadcaster(Node(rt, "peer"))
    peer_tf.send_transform(make_transform_stamped("map", "peer/base_link", 0.0, (1.5, 1.0, 0.0)))
    Explore(rt)
    rt.run(duration=1.5)
    assert sink.goals == [small_goal]
    # the peer drives far off: this robot is the nearer one to both, the big one is best
    peer_tf.send_transform(make_transform_stamped("map", "peer/base_link", 0.0, (9.0, 9.0, 0.0)))
    rt.run(duration=1.0)
    assert sink.goals[-1] == big_goal


def test_a_peer_frame_tf_does_not_know_is_warned_about_and_ignored(caplog):
    data = np.full((20, 30), -1, dtype=np.int8)
    data[:, :10] = 0
    rt = Runtime(seed=0)
    rt.params.set("/explore/peer_frames", ["nobody/base_link"])
    FakeWorld(rt, data)
    sink = GoalSink(rt)
    Explore(rt)
    with caplog.at_level(logging.WARNING):
        rt.run(duration=1.5)
    assert "cannot find the peer nobody/base_link in map" in caplog.text
    assert len(sink.goals) == 1


class AbortingMoveBase(GoalSink):
    """A move_base that aborts every goal at once."""

    def on_goal(self):
        super().on_goal()
        self.server.set_aborted(text="no path")


def test_a_frontier_a_peer_blacklisted_is_skipped_and_its_own_blacklist_is_published():
    data = np.full((20, 30), -1, dtype=np.int8)
    data[:, :10] = 0
    data[:4, :6] = -1
    big, small = frontiers_from_grid(data, 0.1, (0.0, 0.0), (0.35, 1.05))
    big_goal, small_goal = (tuple(round(v, 2) for v in f.centroid) for f in (big, small))
    rt = Runtime(seed=0)
    rt.params.set("/explore/peer_blacklists", ["/peer/explore/blacklist"])
    FakeWorld(rt, data)
    sink = GoalSink(rt)
    peer = Node(rt, "peer").create_publisher(
        geometry_msgs.PoseArray, "/peer/explore/blacklist", 1, latch=True
    )
    # the peer gave up on the big frontier: this explorer does not drive there
    peer.publish(
        geometry_msgs.PoseArray(
            poses=[geometry_msgs.Pose(position=geometry_msgs.Point(x=big_goal[0], y=big_goal[1]))]
        )
    )
    Explore(rt)
    rt.run(duration=1.5)
    assert sink.goals == [small_goal]


def test_an_explorer_publishes_what_it_blacklists_for_its_peers():
    data = np.full((20, 30), -1, dtype=np.int8)
    data[:, :10] = 0
    rt = Runtime(seed=0)
    FakeWorld(rt, data)
    mb = AbortingMoveBase(rt)
    published = []
    rt.graph.subscribe("/explore/blacklist", geometry_msgs.PoseArray, published.append)
    ex = Explore(rt)
    rt.run(duration=1.5)
    assert mb.goals and ex.blacklist
    assert published[-1].header.frame_id == "map"
    got = [(q.position.x, q.position.y) for q in published[-1].poses]
    assert np.allclose(got, ex.blacklist) and len(got) == len(ex.blacklist)
