"""fake_localization: map -> odom from ground truth, amcl_pose, particlecloud, offsets, frames."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.msgs import geometry_msgs, nav_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.fake_localization import FakeLocalization
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import TransformBroadcaster, make_transform_stamped
from fleetsim.tf.patience import GRACE


def quat(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def pose_msg(x, y, yaw, z=0.0):
    q = quat(yaw)
    return geometry_msgs.Pose(
        position=geometry_msgs.Point(x=x, y=y, z=z),
        orientation=geometry_msgs.Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]),
    )


class Sim(Node):
    """Publishes odom -> base_link on /tf and the ground truth, on demand."""

    def __init__(self, rt, ns="/lizi1"):
        super().__init__(rt, "sim", ns)
        self.tf = TransformBroadcaster(self)
        self.gt_pub = self.create_publisher(nav_msgs.Odometry, "base_pose_ground_truth")
        self.init_pub = self.create_publisher(
            geometry_msgs.PoseWithCovarianceStamped, "initialpose"
        )
        self.poses, self.clouds = [], []
        self.create_subscription(
            geometry_msgs.PoseWithCovarianceStamped, "amcl_pose", self.poses.append
        )
        self.create_subscription(geometry_msgs.PoseArray, "particlecloud", self.clouds.append)

    def odom(self, t, x, y, yaw, z=0.0):
        tr = make_transform_stamped(
            self.frame("odom"), self.frame("base_link"), t, (x, y, z), quat(yaw)
        )
        self.tf.send_transform(tr)

    def truth(self, t, x, y, yaw, z=0.0):
        self.gt_pub.publish(
            nav_msgs.Odometry(
                header=std_msgs.Header(stamp=Time.from_sec(t), frame_id="world"),
                pose=geometry_msgs.PoseWithCovariance(pose=pose_msg(x, y, yaw, z)),
            )
        )


def hold(rt, sim, t0, odom, truth, z=0.0, n=4, dt=0.05):
    """Publish the same odom and ground truth n times from t0 (so that the map -> odom edge,
    dated transform_tolerance ahead, covers the latest odom stamp)."""
    for k in range(n):
        sim.odom(t0 + k * dt, *odom, z=z)
        sim.truth(t0 + k * dt, *truth, z=z)
        rt.spin_once()


def world(params=None, prefix="lizi1"):
    rt = Runtime()
    if prefix:
        rt.params.set("/lizi1/tf_prefix", prefix)
    node = FakeLocalization(rt, "fake_localization", "/lizi1", params=params or {})
    return rt, node, Sim(rt)


def map_pose(rt, base="lizi1/base_link"):
    return np.array(rt.tf_buffer.lookup_pose2d("map", base, 0.0))


def test_map_to_odom_makes_the_base_land_on_the_ground_truth():
    rt, node, sim = world()
    assert (node.global_frame, node.odom_frame, node.base_frame) == (
        "map",
        "lizi1/odom",
        "lizi1/base_link",
    )
    hold(rt, sim, 1.0, (1.0, -0.5, 0.3), (20.0, 15.0, 1.2))
    np.testing.assert_allclose(map_pose(rt), [20.0, 15.0, 1.2], atol=1e-9)
    tf = rt.tf_buffer.lookup_transform("map", "lizi1/odom", 0.0)
    assert tf.header.stamp.to_sec() == pytest.approx(1.25)  # transform_tolerance ahead
    assert len(sim.poses) == 4 and len(sim.clouds) == 4
    p = sim.poses[0]
    assert p.header.frame_id == "map" and p.header.stamp.to_sec() == 1.0
    assert (p.pose.pose.position.x, p.pose.pose.position.y) == pytest.approx((20.0, 15.0))
    assert len(sim.clouds[0].poses) == 1
    assert sim.clouds[0].poses[0].position.x == pytest.approx(20.0)


def test_frames_already_spelled_with_the_prefix_are_not_prefixed_twice():
    rt, node, sim = world({"odom_frame_id": "lizi1/odom", "base_frame_id": "lizi1/base_link"})
    assert (node.odom_frame, node.base_frame) == ("lizi1/odom", "lizi1/base_link")
    rt2, node2, _ = world({"global_frame_id": "map"}, prefix="")
    assert node2.global_frame == "map" and node2.odom_frame == "odom"


def test_deltas_shift_the_published_pose():
    rt, node, sim = world({"delta_x": 2.0, "delta_y": -1.0, "delta_yaw": math.pi / 2})
    hold(rt, sim, 1.0, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    # offset (t=(-2, 1), R=-90 deg) applied as R p + t: (1, 0) -> (0, -1) -> (-2, 0)
    np.testing.assert_allclose(map_pose(rt), [-2.0, 0.0, -math.pi / 2], atol=1e-9)


def test_ground_truth_before_its_tf_waits_for_it():
    rt, node, sim = world()
    sim.truth(1.0, 5.0, 5.0, 0.0)
    rt.spin_once()
    assert sim.poses == []  # odom -> base at t=1 is not known yet
    sim.odom(1.0, 0.0, 0.0, 0.0)
    sim.odom(1.05, 0.5, 0.0, 0.0)
    sim.truth(1.05, 5.5, 5.0, 0.0)
    rt.spin_once()
    assert [p.header.stamp.to_sec() for p in sim.poses] == [1.0, 1.05]
    tf = rt.tf_buffer.lookup_transform("map", "lizi1/odom", 1.1)
    assert tf.transform.translation.x == pytest.approx(5.0)


def test_missing_odometry_is_waited_for_then_warned_about_once(caplog):
    rt, node, sim = world()
    sim.truth(0.0, 1.0, 1.0, 0.0)
    sim.truth(0.1, 1.0, 1.0, 0.0)
    rt.spin_once()
    assert "WARNING" not in caplog.text and len(node._pending) == 2
    rt.run(duration=GRACE)
    sim.truth(GRACE, 1.0, 1.0, 0.0)
    sim.truth(GRACE + 0.1, 1.0, 1.0, 0.0)
    rt.spin_once()
    assert caplog.text.count("waiting for tf lizi1/odom -> lizi1/base_link for 5.0 s") == 1
    assert len(node._pending) == 4


def test_ground_truth_is_published_at_publish_rate_and_its_tf_covers_the_present():
    rt, node, sim = world()
    for k in range(100):  # 1 s of 100 Hz odometry and ground truth, the robot driving in x
        sim.odom(1.0 + k * 0.01, k * 0.01, 0.0, 0.0)
        sim.truth(1.0 + k * 0.01, 10.0 + k * 0.01, 5.0, 0.0)
        rt.spin_once()
        if k >= 10:  # from transform_tolerance on (the first tf is dated 1.1 s, as in ROS),
            # any consumer's lookup at the newest odometry stamp finds map -> base
            got = rt.tf_buffer.lookup_pose2d("map", "lizi1/base_link", 1.0 + k * 0.01)
            assert got[0] == pytest.approx(10.0 + k * 0.01, abs=1e-9)
    stamps = [p.header.stamp.to_sec() for p in sim.poses]
    assert stamps == pytest.approx([1.0 + 0.05 * k for k in range(20)])


@pytest.mark.parametrize(("rate", "tolerance", "every"), [(0.0, 0.1, 1), (20.0, 0.04, 2)])
def test_publish_rate_zero_is_every_message_and_the_tolerance_caps_the_period(
    rate, tolerance, every
):
    rt, node, sim = world({"publish_rate": rate, "transform_tolerance": tolerance})
    for k in range(10):
        sim.odom(1.0 + k * 0.01, 0.0, 0.0, 0.0)
        sim.truth(1.0 + k * 0.01, 1.0, 1.0, 0.0)
        rt.spin_once()
    assert len(sim.poses) == 10 // every


def test_no_ground_truth_is_reported_with_what_provides_it(caplog):
    rt, node, sim = world()
    rt.run(duration=GRACE - 1.0)
    assert "WARNING" not in caplog.text
    rt.run(duration=2.0)
    assert (
        caplog.text.count("no ground truth on /lizi1/base_pose_ground_truth since the start") == 1
    )
    assert "libgazebo_ros_p3d.so" in caplog.text and "target_frame" not in caplog.text
    hold(rt, sim, rt.now(), (0.0, 0.0, 0.0), (1.0, 1.0, 0.0))
    rt.run(duration=GRACE + 1.0)  # it stopped again: said once more, with when it stopped
    assert caplog.text.count("no ground truth on /lizi1/base_pose_ground_truth since") == 2


def test_initialpose_moves_the_localized_pose():
    rt, node, sim = world()
    hold(rt, sim, 1.0, (0.0, 0.0, 0.0), (3.0, 4.0, 0.5))
    init = geometry_msgs.PoseWithCovarianceStamped(
        header=std_msgs.Header(frame_id="map"),
        pose=geometry_msgs.PoseWithCovariance(pose=pose_msg(10.0, -2.0, -1.0)),
    )
    sim.init_pub.publish(init)
    rt.spin_once()
    # the robot has not moved: it is now where we said
    hold(rt, sim, 2.0, (0.0, 0.0, 0.0), (3.0, 4.0, 0.5))
    np.testing.assert_allclose(map_pose(rt), [10.0, -2.0, -1.0], atol=1e-9)
    ahead = (3.0 + math.cos(0.5), 4.0 + math.sin(0.5), 0.5)  # 1 m straight ahead
    hold(rt, sim, 3.0, (0.0, 0.0, 0.0), ahead)
    np.testing.assert_allclose(
        map_pose(rt), [10.0 + math.cos(-1.0), -2.0 + math.sin(-1.0), -1.0], atol=1e-9
    )


def test_initialpose_in_another_frame_is_warned_about(caplog):
    rt, node, sim = world()
    sim.init_pub.publish(
        geometry_msgs.PoseWithCovarianceStamped(header=std_msgs.Header(frame_id="odom"))
    )
    rt.spin_once()
    assert "is different from the global frame map" in caplog.text
    assert "ignoring initialpose" in caplog.text  # no tf yet


@settings(max_examples=30, deadline=None)
@given(
    odom=st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(-3.1, 3.1)),
    truth=st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(-3.1, 3.1)),
    z=st.floats(0.0, 1.0),
)
def test_composition_property(odom, truth, z):
    rt, node, sim = world()
    hold(rt, sim, 1.0, odom, truth, z=z)
    got = map_pose(rt)
    assert got[:2] == pytest.approx(truth[:2], abs=1e-6)
    assert math.isclose(math.remainder(got[2] - truth[2], 2 * math.pi), 0.0, abs_tol=1e-9)
    t = rt.tf_buffer.lookup_transform("map", "lizi1/base_link", 0.0).transform.translation
    assert t.z == pytest.approx(z, abs=1e-9)
