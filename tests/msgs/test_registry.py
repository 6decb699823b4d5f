from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

from fleetsim.errors import MessageError
from fleetsim.msgs import (
    all_types,
    builtin_interfaces,
    geometry_msgs,
    get_type,
    message,
    msgs_equal,
    resolve_name,
    sensor_msgs,
    std_msgs,
    tf2_msgs,
    type_name,
)
from fleetsim.msgs.fields import Seq, float64, uint8


@pytest.mark.parametrize(
    ("name", "full"),
    [
        ("geometry_msgs/PoseStamped", "geometry_msgs/msg/PoseStamped"),
        ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/PoseStamped"),
        ("/geometry_msgs/Twist", "geometry_msgs/msg/Twist"),
        (" sensor_msgs/LaserScan ", "sensor_msgs/msg/LaserScan"),
        ("tf/tfMessage", "tf2_msgs/msg/TFMessage"),
        ("tf2_msgs/TFMessage", "tf2_msgs/msg/TFMessage"),
        ("time", "builtin_interfaces/msg/Time"),
        ("duration", "builtin_interfaces/msg/Duration"),
        ("std_msgs/Time", "builtin_interfaces/msg/Time"),
        ("std_msgs/Duration", "builtin_interfaces/msg/Duration"),
        ("Header", "std_msgs/msg/Header"),
        ("std_msgs/Header", "std_msgs/msg/Header"),
        ("nav_msgs/OccupancyGrid", "nav_msgs/msg/OccupancyGrid"),
        ("nav_msgs/GetMapResponse", "nav_msgs/srv/GetMap_Response"),
        ("nav_msgs/GetPlanRequest", "nav_msgs/srv/GetPlan_Request"),
        ("actionlib_msgs/GoalStatus", "actionlib_msgs/msg/GoalStatus"),
    ],
)
def test_ros1_and_ros2_names_resolve(name, full):
    assert resolve_name(name) == full
    assert type_name(get_type(name)) == full


def test_unknown_type_suggests_the_close_name():
    with pytest.raises(MessageError, match=r"'geometry_msgs/PoseStamped'\?"):
        get_type("geometry_msgs/PoseStampd")
    with pytest.raises(MessageError, match=r"'geometry_msgs/msg/PoseStamped'\?"):
        get_type("geometry_msgs/msg/PoseStampd")
    with pytest.raises(MessageError, match="unknown message type 'nonsense'"):
        get_type("nonsense")


def test_type_name_of_class_and_instance():
    assert type_name(geometry_msgs.Pose) == "geometry_msgs/msg/Pose"
    assert type_name(geometry_msgs.Pose()) == "geometry_msgs/msg/Pose"
    with pytest.raises(MessageError, match="not a fleetsim message"):
        type_name(3)


def test_every_class_has_its_name_and_slots():
    for name, cls in all_types().items():
        assert cls.__msgtype__ == name
        assert hasattr(cls, "__slots__")
        cls()  # every field has a default


def test_defaults():
    assert geometry_msgs.Quaternion().w == 1.0
    assert geometry_msgs.PoseWithCovariance().covariance.shape == (36,)
    assert geometry_msgs.PoseWithCovariance().covariance.dtype == np.float64
    scan = sensor_msgs.LaserScan()
    assert scan.ranges.dtype == np.float32 and scan.ranges.shape == (0,)
    assert sensor_msgs.CameraInfo().p.shape == (12,)
    assert tf2_msgs.TFMessage().transforms == []
    a, b = geometry_msgs.PoseStamped(), geometry_msgs.PoseStamped()
    assert a.header is not b.header  # nested defaults are not shared
    assert std_msgs.Header().stamp == builtin_interfaces.Time(0, 0)


def test_msgs_equal_compares_arrays_lists_and_nan():
    a = sensor_msgs.LaserScan(ranges=np.array([1.0, np.nan], np.float32))
    b = sensor_msgs.LaserScan(ranges=np.array([1.0, np.nan], np.float32))
    assert msgs_equal(a, b)
    b.ranges = np.array([1.0, 2.0], np.float32)
    assert not msgs_equal(a, b)
    assert not msgs_equal(geometry_msgs.Point(), geometry_msgs.Vector3())
    p = geometry_msgs.PoseArray(poses=[geometry_msgs.Pose()])
    assert not msgs_equal(p, geometry_msgs.PoseArray())
    assert msgs_equal(float("nan"), float("nan"))


def test_user_message_with_constants():
    @message("fleetsim_test/msg/Thing")
    class Thing:
        MODE_A: ClassVar[uint8] = 1
        values: Seq[float64]
        mode: uint8 = 1

    t = Thing()
    assert t.mode == Thing.MODE_A and t.values.dtype == np.float64
    assert Thing.__msgconsts__[0][0] == "MODE_A"
    assert get_type("fleetsim_test/Thing") is Thing


def test_bad_definitions_are_reported():
    with pytest.raises(MessageError, match="must be a ROS 2 full name"):
        message("geometry_msgs/Bad")
    with pytest.raises(MessageError, match=r"Bad2\)\.x: annotation .* is not a message field type"):

        @message("fleetsim_test/msg/Bad2")
        class Bad2:
            x: float

    @message("fleetsim_test/msg/Clash")
    class Clash:
        x: float64

    with pytest.raises(MessageError, match="already registered"):

        @message("fleetsim_test/msg/Clash")
        class Clash2:
            y: float64


def test_unknown_annotation_name_is_reported():
    with pytest.raises(MessageError, match=r"Bad3\)\: an annotation names an unknown type"):

        @message("fleetsim_test/msg/Bad3")
        class Bad3:
            x: NotAType  # noqa: F821
