"""Goal and initial-pose messages, status names, action names."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fleetsim.errors import ActionError, InvalidName
from fleetsim.transport.goal import (
    INITIALPOSE_COVARIANCE_YAW,
    action_name,
    initial_pose,
    pose_stamped,
    status_name,
    yaw_of,
)


@given(st.floats(-math.pi + 1e-6, math.pi - 1e-6))
def test_yaw_round_trip(yaw):
    q = pose_stamped(0.0, 0.0, yaw, "map", 0.0).pose.orientation
    assert yaw_of(q) == pytest.approx(yaw, abs=1e-9)
    assert q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w == pytest.approx(1.0)


def test_pose_stamped_fields():
    p = pose_stamped(22, 17, 0.0, "map", 3.25)
    assert (p.header.frame_id, p.header.stamp.to_sec()) == ("map", 3.25)
    assert (p.pose.position.x, p.pose.position.y, p.pose.orientation.w) == (22.0, 17.0, 1.0)
    with pytest.raises(ActionError, match="goal yaw must be a finite number, got nan"):
        pose_stamped(0, 0, math.nan, "map", 0.0)


def test_initial_pose_covariance_is_rviz_default():
    m = initial_pose(1, 2, 0.3, "map", 0.0)
    cov = m.pose.covariance
    assert cov[0] == cov[7] == 0.25 and cov[35] == INITIALPOSE_COVARIANCE_YAW
    assert pytest.approx((math.pi / 12) ** 2) == INITIALPOSE_COVARIANCE_YAW
    assert sum(1 for c in cov if c) == 3


def test_status_and_action_names():
    assert status_name(3) == "SUCCEEDED" and status_name(4) == "ABORTED"
    assert status_name(99) == "99"
    assert action_name("lizi1") == action_name("/lizi1/") == "/lizi1/move_base"
    assert action_name("/") == "/move_base"
    with pytest.raises(InvalidName):
        action_name("1bad")
