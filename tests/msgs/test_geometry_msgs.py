from __future__ import annotations

import numpy as np

from fleetsim.msgs import geometry_msgs


def test_identity_and_covariances():
    assert geometry_msgs.Transform().rotation.w == 1.0
    assert geometry_msgs.Pose().orientation == geometry_msgs.Quaternion(0.0, 0.0, 0.0, 1.0)
    cov = geometry_msgs.TwistWithCovariance().covariance
    assert cov.dtype == np.float64 and cov.shape == (36,) and not cov.any()


def test_positional_construction_follows_ros_field_order():
    t = geometry_msgs.TransformStamped(child_frame_id="lizi1/base_link")
    assert t.header.frame_id == "" and t.child_frame_id == "lizi1/base_link"
    assert geometry_msgs.Point(1, 2, 3).z == 3
    assert geometry_msgs.Polygon([geometry_msgs.Point32(1, 2, 0)]).points[0].y == 2
