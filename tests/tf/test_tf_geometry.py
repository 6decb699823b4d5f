"""do_transform_* on geometry messages, against the NumPy transform math."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from tf_strategies import tf_settings, translations, unit_quaternions

from fleetsim.errors import TransformError
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.geometry_msgs import (
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
    Twist,
    Vector3Stamped,
)
from fleetsim.tf import Buffer, make_transform_stamped
from fleetsim.tf import transforms as tm
from fleetsim.tf.geometry import (
    do_transform_point,
    do_transform_pose_stamped,
    do_transform_pose_with_covariance_stamped,
    do_transform_vector3,
)


@tf_settings
@given(translations, unit_quaternions(), translations, unit_quaternions())
def test_point_vector_pose_match_numpy(t, q, p, o):
    tf = make_transform_stamped("map", "base", Time(3, 0), t, q)
    pt = PointStamped()
    pt.header.frame_id = "base"
    pt.point.x, pt.point.y, pt.point.z = p
    out = do_transform_point(pt, tf)
    assert out.header.frame_id == "map" and out.header.stamp == Time(3, 0)
    assert np.allclose([out.point.x, out.point.y, out.point.z], tm.transform_points(t, q, [p])[0])
    v = Vector3Stamped()
    v.vector.x, v.vector.y, v.vector.z = p
    vo = do_transform_vector3(v, tf)
    assert np.allclose([vo.vector.x, vo.vector.y, vo.vector.z], tm.rotate_vector(q, p))
    ps = PoseStamped()
    ps.pose.position.x, ps.pose.position.y, ps.pose.position.z = p
    ps.pose.orientation.x, ps.pose.orientation.y, ps.pose.orientation.z, ps.pose.orientation.w = o
    po = do_transform_pose_stamped(ps, tf)
    want_t, want_q = tm.compose_transforms(t, q, p, o)
    pos, ori = po.pose.position, po.pose.orientation
    assert np.allclose([pos.x, pos.y, pos.z], want_t)
    assert np.allclose([ori.x, ori.y, ori.z, ori.w], want_q)
    assert ps.header.frame_id == "" and ps.pose.position.x == p[0]  # input untouched


def test_covariance_is_rotated_with_the_pose():
    tf = make_transform_stamped("map", "odom", 1.0, (1, 0, 0), tm.quaternion_from_yaw(np.pi / 2))
    msg = PoseWithCovarianceStamped()
    msg.pose.covariance[:] = np.diag([1.0, 4.0, 0.0, 0.0, 0.0, 0.5]).reshape(36)
    out = do_transform_pose_with_covariance_stamped(msg, tf)
    cov = np.asarray(out.pose.covariance).reshape(6, 6)
    assert np.allclose(np.diag(cov), [4.0, 1.0, 0.0, 0.0, 0.0, 0.5])
    assert out.pose.pose.position.x == pytest.approx(1.0)


def test_buffer_transform_uses_the_message_stamp_and_frame():
    buf = Buffer()
    buf.set_transform(make_transform_stamped("map", "odom", 1.0, (0, 0, 0)))
    buf.set_transform(make_transform_stamped("map", "odom", 2.0, (2, 0, 0)))
    pt = PointStamped()
    pt.header.frame_id = "odom"
    pt.header.stamp = Time.from_sec(1.5)
    assert buf.transform(pt, "map").point.x == pytest.approx(1.0)
    pt.header.stamp = Time(0, 0)  # zero stamp: latest
    assert buf.transform(pt, "map").point.x == pytest.approx(2.0)
    assert buf.transform(pt, "map", time=1.0).point.x == pytest.approx(0.0)
    with pytest.raises(TransformError, match=r"cannot transform a geometry_msgs/msg/Twist; "):
        buf.transform(Twist(), "map")
