"""Readings as ROS messages: the depth camera's point cloud."""

import math

import numpy as np

from fleetsim.nav.costmap.costmap_ros import points_from_cloud2
from fleetsim.sim import messages


def test_cloud_of_a_flat_wall_in_the_optical_frame():
    w, h, hfov = 8, 6, 1.2
    fx = (w / 2) / math.tan(hfov / 2)
    K = np.array([[fx, 0, (w + 1) / 2], [0, fx, (h + 1) / 2], [0, 0, 1.0]])
    depth = np.full((h, w), 2.0, np.float32)
    depth[0, 0] = np.nan  # outside the cutoffs
    rgb = np.zeros((h, w, 3), np.uint8)
    rgb[..., 0], rgb[..., 2] = 200, 7
    msg = messages.cloud_msg(1.5, "cam_optical", depth, rgb, K)
    assert (msg.height, msg.width, msg.point_step, msg.row_step) == (h, w, 32, 32 * w)
    assert [f.name for f in msg.fields] == ["x", "y", "z", "rgb"] and not msg.is_dense
    assert msg.header.frame_id == "cam_optical" and msg.header.stamp.to_sec() == 1.5
    pts = points_from_cloud2(msg)  # the costmap's reader drops the NaN point
    assert pts.shape == (h * w - 1, 3)
    np.testing.assert_allclose(pts[:, 2], 2.0)
    # the last column lies right of centre (x > 0), the bottom row below it (y > 0)
    grid = np.frombuffer(msg.data.tobytes(), np.float32).reshape(h, w, 8)
    u, v = w - 1, h - 1
    np.testing.assert_allclose(grid[v, u, :3], [(u - K[0, 2]) * 2 / fx, (v - K[1, 2]) * 2 / fx, 2])
    packed = grid[v, u, 4:5].view(np.uint32)[0]
    assert (packed >> 16, (packed >> 8) & 255, packed & 255) == (200, 0, 7)


def _reference_odometry(r):
    """The odometry message built field by field from keywords (the obvious construction)."""
    from fleetsim.msgs import builtin_interfaces, nav_msgs

    msg = nav_msgs.Odometry()
    msg.header.stamp = builtin_interfaces.Time.from_sec(max(0.0, r.stamp))
    msg.header.frame_id, msg.child_frame_id = r.frame_id, r.child_frame_id
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    p.x, p.y, p.z = (float(v) for v in r.position)
    o.x, o.y, o.z, o.w = (float(v) for v in r.orientation)
    tw = msg.twist.twist
    tw.linear.x, tw.linear.y, tw.linear.z = (float(v) for v in r.linear)
    tw.angular.x, tw.angular.y, tw.angular.z = (float(v) for v in r.angular)
    msg.pose.covariance[::7] = r.covariance
    msg.twist.covariance[::7] = r.covariance
    return msg


def _reading(t, cov=0.0):
    from fleetsim.sim.plugins.base import OdometryReading

    rng = np.random.default_rng(abs(int(t * 1000)))
    q = rng.normal(size=4)
    return OdometryReading(
        t, "odom", "r/odom", "r/base_link", rng.normal(size=3), q / np.linalg.norm(q),
        rng.normal(size=3), rng.normal(size=3), covariance=cov,
    )  # fmt: skip


def test_odometry_messages_equal_the_field_by_field_construction():
    from fleetsim.msgs import cdr

    for r in (_reading(0.0), _reading(1.234), _reading(1.234, 0.01), _reading(-0.5), _reading(7.0)):
        got, want = messages.odometry_msg(r), _reference_odometry(r)
        assert cdr.serialize(got) == cdr.serialize(want)
        assert type(got.pose.pose.position.x) is float
        assert got.pose.covariance.dtype == np.float64 and got.pose.covariance.shape == (36,)
        tf = messages.odometry_tf(r)
        assert (tf.header.frame_id, tf.child_frame_id) == ("r/odom", "r/base_link")
        assert tf.header.stamp == want.header.stamp
        pose = want.pose.pose
        tr, rot = tf.transform.translation, tf.transform.rotation
        assert (tr.x, tr.y, tr.z) == (pose.position.x, pose.position.y, pose.position.z)
        o = pose.orientation
        assert (rot.x, rot.y, rot.z, rot.w) == (o.x, o.y, o.z, o.w)


def test_messages_of_one_stamp_share_no_parts():
    """The stamp's parts are reused within an update, the objects never: a subscriber that
    changes its message changes no other."""
    r = _reading(2.5, 0.01)
    a, b, c = messages.odometry_msg(r), messages.odometry_msg(r), messages.odometry_tf(r)
    a.header.stamp.sec = 99
    a.pose.covariance[0] = 5.0
    assert b.header.stamp.sec == 2 and c.header.stamp.sec == 2
    assert b.pose.covariance[0] == 0.01 and a.twist.covariance[0] == 0.01
    assert a.header is not b.header and a.pose.pose is not b.pose.pose


def test_scan_message_equals_the_field_by_field_construction():
    from fleetsim.msgs import builtin_interfaces, cdr, sensor_msgs
    from fleetsim.sim.plugins.base import ScanReading

    ranges = np.linspace(0.2, 9.0, 360, dtype=np.float32)
    r = ScanReading(3.025, "scan", "r/laser", -1.5, 1.5, 0.01, 0.0, 0.025, 0.1, 30.0, ranges)
    want = sensor_msgs.LaserScan()
    want.header.stamp = builtin_interfaces.Time.from_sec(3.025)
    want.header.frame_id = "r/laser"
    want.angle_min, want.angle_max, want.angle_increment = -1.5, 1.5, 0.01
    want.time_increment, want.scan_time, want.range_min, want.range_max = 0.0, 0.025, 0.1, 30.0
    want.ranges = ranges
    got = messages.scan_msg(r)
    assert cdr.serialize(got) == cdr.serialize(want)
    assert got.ranges is ranges and got.intensities.dtype == np.float32
