"""/position_share: me_publisher's messages, the neighbour table (radius, staleness) and the
rejection of NaN poses and empty footprints with one warning naming the robot."""

import logging
import math
import re

import numpy as np
import pytest

from fleetsim.msgs import collvoid_msgs, geometry_msgs, nav_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.multirobot.me_publisher import MePublisher
from fleetsim.nav.multirobot.position_share import NeighbourTable, PositionShare
from fleetsim.nav.multirobot.uncertainty import uncertainty_radius
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, make_transform_stamped

SQUARE = [[-0.2, -0.2], [-0.2, 0.2], [0.2, 0.2], [0.2, -0.2]]


def shared(rid, x, y, t, vx=0.0, footprint=SQUARE, radius=0.3):
    msg = collvoid_msgs.PoseTwistWithCovariance(robot_id=rid, radius=radius)
    msg.header.stamp = Time.from_sec(t)
    msg.pose.pose.position = geometry_msgs.Point(x=x, y=y)
    msg.holonomic_velocity.x = vx
    msg.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in footprint]
    return msg


def test_table_keeps_robots_within_radius_nearest_first():
    table = NeighbourTable()
    for rid, x in (("a", 3.0), ("b", 1.0), ("c", 10.0), ("me", 0.0)):
        assert table.update(shared(rid, x, 0.0, 5.0)) is None
    near = table.near(5.0, (0.0, 0.0), radius=4.0, max_n=10, exclude="me")
    assert near.ids == ["b", "a"]
    assert near.positions.tolist() == [[1.0, 0.0], [3.0, 0.0]]
    assert table.near(5.0, (0.0, 0.0), 4.0, max_n=1, exclude="me").ids == ["b"]


def test_table_drops_robots_silent_for_two_seconds():
    table = NeighbourTable()
    table.update(shared("old", 1.0, 0.0, 1.0))
    table.update(shared("new", 2.0, 0.0, 2.5))
    assert [r.robot_id for r in table.fresh(3.0)] == ["new", "old"]
    assert [r.robot_id for r in table.fresh(3.1)] == ["new"]
    assert "old" not in table.robots and table.get("new", 4.6) is None


@pytest.mark.parametrize(
    "msg, words",
    [
        (shared("r1", math.nan, 0.0, 1.0), "robot 'r1' shared a non-finite pose"),
        (shared("r2", 0.0, 0.0, 1.0, vx=math.inf), "robot 'r2' shared a non-finite"),
        (shared("r3", 0.0, 0.0, 1.0, footprint=[]), "robot 'r3' shared an empty"),
        (shared("r4", 0.0, 0.0, 1.0, footprint=[[0, 0], [1, 1]]), "'r4'.*2 points"),
        (shared("", 0.0, 0.0, 1.0), "without robot_id"),
    ],
)
def test_bad_messages_are_rejected_with_the_reason(msg, words):
    table = NeighbourTable()
    problem = table.update(msg)
    assert problem is not None
    assert len(table.robots) == 0
    assert re.search(words, problem)


def test_a_bad_robot_is_warned_about_once_and_the_others_kept(caplog):
    rt = Runtime()
    node = Node(rt, "listener", "/lizi1")
    share = PositionShare(node)
    pub = Node(rt, "talker", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    with caplog.at_level(logging.WARNING):
        for k in range(5):
            pub.publish(shared("lizi2", math.nan, 0.0, 0.1 * k))
            pub.publish(shared("lizi3", 1.0, 0.0, 0.1 * k))
            rt.run(duration=0.1)
    warnings = [r.getMessage() for r in caplog.records if "lizi2" in r.getMessage()]
    assert len(warnings) == 1 and "non-finite pose" in warnings[0]
    assert list(share.table.robots) == ["lizi3"]
    assert share.rejected == 5


def test_uncertainty_radius_holds_one_minus_eps_of_the_particles():
    rng = np.random.default_rng(3)
    pts = rng.normal(0.0, 0.1, size=(5000, 2))
    r = uncertainty_radius(pts, np.zeros(2), eps=0.1, cap=10.0)
    # 2-D normal: P(|x| <= r) = 1 - exp(-r^2 / 2 s^2) = 0.9 -> r = s sqrt(2 ln 10)
    assert r == pytest.approx(0.1 * math.sqrt(2 * math.log(10)), rel=0.05)
    assert uncertainty_radius(pts, np.zeros(2), 0.1, cap=0.05) == 0.05
    assert uncertainty_radius(np.zeros((0, 2)), np.zeros(2), 0.1, 1.0) == 0.0
    w = np.r_[np.ones(9), 1000.0]  # the heavy far particle decides
    far = np.r_[np.zeros((9, 2)), [[3.0, 4.0]]].reshape(-1, 2)
    assert uncertainty_radius(far, np.zeros(2), 0.1, 10.0, weights=w) == 5.0


class Robot(Node):
    """map -> lizi1/base_link as a static transform, odom and a particle cloud on demand."""

    def __init__(self, rt, x, y, yaw):
        super().__init__(rt, "robot", "/lizi1")
        rt.params.set("/lizi1/tf_prefix", "lizi1")
        q = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
        self.static = StaticTransformBroadcaster(self)
        self.static.send_transform(
            make_transform_stamped("map", "lizi1/base_link", 0.0, (x, y, 0), q)
        )
        self.odom = self.create_publisher(nav_msgs.Odometry, "odom")
        self.cloud = self.create_publisher(geometry_msgs.PoseArray, "particlecloud", latch=True)
        self.got = []
        self.create_subscription(
            collvoid_msgs.PoseTwistWithCovariance, "/position_share", self.got.append
        )


def test_me_publisher_shares_pose_velocity_and_footprint_at_10_hz():
    rt = Runtime()
    robot = Robot(rt, 2.0, 3.0, math.pi / 2)
    me = MePublisher(rt, "me_publisher", "/lizi1", params={"footprint": SQUARE})
    odom = nav_msgs.Odometry()
    odom.twist.twist.linear.x = 0.4
    robot.odom.publish(odom)
    rt.run(duration=1.0)
    assert 9 <= len(robot.got) <= 11
    m = robot.got[-1]
    assert m.robot_id == "lizi1" and m.header.frame_id == "map"
    assert (m.pose.pose.position.x, m.pose.pose.position.y) == pytest.approx((2.0, 3.0))
    # 0.4 m/s forward while facing +y is +y in the map
    assert (m.holonomic_velocity.x, m.holonomic_velocity.y) == pytest.approx((0.0, 0.4), abs=1e-9)
    assert m.radius == pytest.approx(math.hypot(0.2, 0.2))  # fake localization: no inflation
    assert len(m.footprint.polygon.points) == 4
    assert me.uncertainty() == 0.0
    assert not any(m.pose.covariance)


def test_me_publisher_inflates_the_footprint_by_amcl_spread():
    rt = Runtime()
    robot = Robot(rt, 0.0, 0.0, 0.0)
    MePublisher(rt, "me_publisher", "/lizi1", params={"footprint": SQUARE, "eps": 0.1})
    angles = np.linspace(0, 2 * math.pi, 50, endpoint=False)
    at = geometry_msgs.Point
    ring = [geometry_msgs.Pose(position=at(x=0.1 * math.cos(a), y=0.1 * math.sin(a)))
            for a in angles]  # fmt: skip
    robot.cloud.publish(geometry_msgs.PoseArray(poses=ring))
    rt.run(duration=0.5)
    m = robot.got[-1]
    # a ring of 0.1 m: variance 0.005 m^2 (sample: x 50/49) per axis, shared in pose.covariance;
    # the footprint is padded by its widest 90 % spread, sqrt(-2 ln 0.1) standard deviations
    var = 0.005 * 50 / 49
    assert [m.pose.covariance[i] for i in (0, 1, 6, 7)] == pytest.approx([var, 0, 0, var], abs=1e-9)
    pad = math.sqrt(-2 * math.log(0.1)) * math.sqrt(var)
    assert m.radius == pytest.approx(math.hypot(0.2 + pad, 0.2 + pad), abs=1e-6)
    xs = sorted({round(p.x, 6) for p in m.footprint.polygon.points})
    assert xs == pytest.approx([-0.2 - pad, 0.2 + pad], abs=1e-6)


def test_me_publisher_rejects_a_bad_footprint_parameter():
    rt = Runtime()
    with pytest.raises(Exception, match="me_publisher/footprint"):
        MePublisher(rt, "me_publisher", "/lizi1", params={"footprint": [[0, 0]]})


def test_me_publisher_takes_the_named_costmaps_footprint():
    rt = Runtime()
    cm = "/lizi1/move_base_node/local_costmap"
    rt.params.set(f"{cm}/footprint", [[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
    rt.params.set(f"{cm}/footprint_padding", 0.01)
    me = MePublisher(
        rt, "me_publisher", "/lizi1", params={"costmap": "move_base_node/local_costmap"}
    )
    assert me.footprint.max(axis=0) == pytest.approx((0.2, 0.17))
    rt.params.set("/lizi2/move_base_node/local_costmap/robot_radius", 0.15)
    me2 = MePublisher(
        rt, "me_publisher", "/lizi2", params={"costmap": "move_base_node/local_costmap"}
    )
    assert me2.robot_radius == pytest.approx(0.15, abs=0.01)
    with pytest.raises(Exception, match="lizi3/move_base_node/local_costmap has neither"):
        MePublisher(
            rt, "me_publisher", "/lizi3", params={"costmap": "move_base_node/local_costmap"}
        )


def test_me_publisher_is_controlled_only_while_move_base_has_a_goal():
    from fleetsim.msgs import actionlib_msgs

    rt = Runtime()
    robot = Robot(rt, 0.0, 0.0, 0.0)
    MePublisher(rt, "me_publisher", "/lizi1", params={"footprint": SQUARE})
    status = robot.create_publisher(actionlib_msgs.GoalStatusArray, "move_base/status")
    rt.run(duration=0.3)
    assert robot.got[-1].controlled  # no move_base heard: the parameter (true)

    def say(code):
        status.publish(
            actionlib_msgs.GoalStatusArray(status_list=[actionlib_msgs.GoalStatus(status=code)])
        )
        rt.run(duration=0.3)
        return robot.got[-1].controlled

    assert say(actionlib_msgs.GoalStatus.ACTIVE)
    assert not say(actionlib_msgs.GoalStatus.SUCCEEDED)  # parked at its goal


def test_me_publisher_takes_a_cloud_of_one_pose_as_no_uncertainty():
    """fake_localization's cloud is one pose, the true one a moment before the tf the estimate
    comes from: a moving robot is not padded by the distance it drove in between (issue 18:
    zero for fake_localization, as the planner's own_radius takes it)."""
    rt = Runtime()
    robot = Robot(rt, 0.0, 0.0, 0.0)
    me = MePublisher(rt, "me_publisher", "/lizi1", params={"footprint": SQUARE})
    one = geometry_msgs.Pose(position=geometry_msgs.Point(x=0.03, y=0.0))
    robot.cloud.publish(geometry_msgs.PoseArray(poses=[one]))
    rt.run(duration=0.3)
    assert me.uncertainty() == 0.0
    assert not any(robot.got[-1].pose.covariance)
    assert robot.got[-1].radius == pytest.approx(math.hypot(0.2, 0.2))


def in_frame(msg, frame):
    msg.header.frame_id = frame
    return msg


@pytest.mark.parametrize(
    "msg, words",
    [
        (in_frame(shared("r5", 1.0, 0.0, 1.0), "r_odom/odom"), "'r5'.*frame 'r_odom/odom'.*'map'"),
        (in_frame(shared("r6", 1.0, 0.0, 1.0), "lizi6/base_link"), "frame 'lizi6/base_link'"),
        (shared("r7", 1.0, 0.0, 1.0, radius=-0.3), "'r7' shared radius -0.3 m"),
        (shared("r8", 1.0, 0.0, 1.0, radius=0.0), "'r8' shared radius 0.0 m"),
    ],
)
def test_a_pose_in_another_frame_or_a_radius_not_above_zero_is_rejected(msg, words):
    table = NeighbourTable()
    problem = table.update(msg)
    assert problem is not None and re.search(words, problem), problem
    assert table.robots == {}


@pytest.mark.parametrize("frame", ["map", "/map", ""])
def test_the_shared_frame_is_accepted_with_or_without_slash_or_unset(frame):
    table = NeighbourTable()
    assert table.update(in_frame(shared("r1", 1.0, 0.0, 1.0), frame)) is None


def test_a_message_stamped_far_in_the_future_is_not_fresh():
    """t = 1000 s heard at 900 s would stay fresh for 102 s; more than 2 s ahead of the
    listener's clock, its sender's clock is another one: dropped, reported naming the robot."""
    bad = []
    table = NeighbourTable(on_bad=bad.append)
    table.update(shared("ahead", 1.0, 0.0, 1000.0))
    table.update(shared("near", 2.0, 0.0, 901.5))  # 1.5 s ahead: clocks a little apart
    assert table.get("ahead", 900.0) is None
    assert [r.robot_id for r in table.fresh(900.0)] == ["near"]
    assert "ahead" not in table.robots and table.get("near", 900.0) is not None
    assert bad and all(b.robot_id == "ahead" and "'ahead'" in b for b in bad)
    assert "100.000 s ahead" in bad[0]


def test_one_warning_per_bad_robot_however_many_nodes_listen(caplog):
    """Every robot's move_base listens to /position_share; a broken robot is warned about once
    in the process (the issue: "ignored with one warning naming it"), per kind of fault."""
    rt = Runtime()
    shares = [PositionShare(Node(rt, "move_base", f"/lizi{k}")) for k in range(1, 5)]
    pub = Node(rt, "talker", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    with caplog.at_level(logging.WARNING):
        for k in range(5):
            pub.publish(shared("ghost", math.nan, 0.0, 0.1 * k))
            pub.publish(shared("late", 1.0, 0.0, 100.0))
            pub.publish(shared("ok", 1.0, 0.0, 0.1 * k))
            rt.run(duration=0.1)
            for s in shares:
                s.table.near(rt.now(), (0.0, 0.0), 5.0, 10)
    said = [r.getMessage() for r in caplog.records]
    assert len([m for m in said if "'ghost'" in m]) == 1
    assert len([m for m in said if "'late'" in m and "ahead of this clock" in m]) == 1
    assert all(list(s.table.robots) == ["ok"] for s in shares)
    assert all(s.rejected == 5 for s in shares)
    # another process (runtime) warns for itself
    rt2 = Runtime()
    PositionShare(Node(rt2, "move_base", "/lizi1"))
    Node(rt2, "talker", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    ).publish(shared("ghost", math.nan, 0.0, 0.0))
    with caplog.at_level(logging.WARNING):
        rt2.run(duration=0.1)
    assert len([r for r in caplog.records if "'ghost'" in r.getMessage()]) == 2
