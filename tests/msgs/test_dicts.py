from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from fleetsim.errors import MessageError
from fleetsim.msgs import (
    all_types,
    from_dict,
    geometry_msgs,
    msgs_equal,
    nav_msgs,
    sensor_msgs,
    std_msgs,
    to_dict,
)
from fleetsim.msgs.dicts import find_invalid_field


def test_rostopic_pub_style_yaml():
    data = yaml.safe_load("{header: {frame_id: map}, pose: {position: {x: 22}}}")
    msg = from_dict("geometry_msgs/PoseStamped", data)
    assert msg.header.frame_id == "map"
    assert msg.pose.position.x == 22.0 and isinstance(msg.pose.position.x, float)
    assert msg.pose.orientation.w == 1.0


@pytest.mark.parametrize("name", sorted(all_types()))
def test_to_dict_from_dict_round_trip(name, populated):
    msg = populated(all_types()[name], seed=3)
    back = from_dict(name, yaml.safe_load(yaml.safe_dump(to_dict(msg))))
    assert msgs_equal(msg, back)


def test_ros1_field_names():
    msg = from_dict(
        "std_msgs/Header", {"seq": 4, "stamp": {"secs": 3, "nsecs": 5}, "frame_id": "odom"}
    )
    assert msg == std_msgs.Header(stamp=msg.stamp.from_nsec(3_000_000_005), frame_id="odom")
    info = from_dict("sensor_msgs/CameraInfo", {"K": [1, 0, 2, 0, 1, 3, 0, 0, 1]})
    assert info.k.tolist() == [1, 0, 2, 0, 1, 3, 0, 0, 1]


def test_conveniences():
    assert from_dict("std_msgs/String", "hello").data == "hello"
    assert from_dict("std_msgs/Empty", None) == std_msgs.Empty()
    marker = from_dict("visualization_msgs/Marker", {"lifetime": 0.5})
    assert marker.lifetime.nanosec == 500_000_000
    scan = from_dict("sensor_msgs/LaserScan", {"ranges": [1, ".inf", 2.5], "range_max": "inf"})
    assert scan.ranges.dtype == np.float32 and math.isinf(scan.ranges[1])
    assert math.isinf(scan.range_max)
    p = geometry_msgs.Point(x=1.0)
    assert from_dict("geometry_msgs/Pose", {"position": p}).position is p


@pytest.mark.parametrize(
    ("typename", "data", "match"),
    [
        (
            "geometry_msgs/PoseStamped",
            {"pose": {"positon": {"x": 1}}},
            r"unknown field 'pose\.positon' in geometry_msgs/msg/Pose "
            r"\(did you mean 'position'\?\)",
        ),
        (
            "geometry_msgs/PoseStamped",
            {"pose": {"position": {"x": "far"}}},
            r"field 'pose\.position\.x' expected float64, got str 'far'",
        ),
        ("std_msgs/Bool", {"data": 1}, r"field 'data' expected bool, got int 1"),
        ("std_msgs/Int32", {"data": 1.5}, r"field 'data' expected int32, got float"),
        ("std_msgs/Float64", {"data": True}, r"field 'data' expected float64, got bool"),
        ("std_msgs/UInt8", {"data": 256}, r"value 256 is out of range for uint8 \(0\.\.255\)"),
        ("geometry_msgs/Pose", {"position": [1, 2]}, r"field 'position' expected a mapping"),
        (
            "geometry_msgs/PoseArray",
            {"poses": [{}, {"position": {"q": 1}}]},
            r"unknown field 'poses\[1\]\.position\.q'",
        ),
        (
            "geometry_msgs/PoseWithCovariance",
            {"covariance": [0, 1]},
            r"field 'covariance': expected 36 float64 values, got 2",
        ),
        ("nav_msgs/OccupancyGrid", {"data": "abc"}, r"field 'data' expected int8\[\]"),
        ("nav_msgs/OccupancyGrid", {"data": [1.5]}, r"expected int8 values, got list"),
        ("sensor_msgs/JointState", {"name": "j1"}, r"field 'name' expected string\[\]"),
        ("sensor_msgs/JointState", {"name": [3]}, r"field 'name\[0\]' expected string"),
    ],
)
def test_errors_name_the_field(typename, data, match):
    with pytest.raises(MessageError, match=match):
        from_dict(typename, data)


def test_where_prefixes_errors():
    with pytest.raises(MessageError, match=r"^robots\.yaml line 3: unknown field 'xx'"):
        from_dict("geometry_msgs/Point", {"xx": 1}, where="robots.yaml line 3")
    with pytest.raises(MessageError, match="unknown message type"):
        from_dict("geometry_msgs/Pointy", {})
    with pytest.raises(MessageError, match="not a message type name or class"):
        from_dict(3, {})


def test_to_dict_is_plain():
    d = to_dict(nav_msgs.OccupancyGrid(data=np.array([0, -1], np.int8)))
    assert d["data"] == [0, -1] and type(d["data"][0]) is int
    assert d["info"]["origin"]["orientation"] == {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
    yaml.safe_dump(d)  # plain types only


def test_find_invalid_field():
    assert find_invalid_field(sensor_msgs.LaserScan()) is None
    bad = sensor_msgs.LaserScan(header=std_msgs.Header(frame_id=None))
    assert "field 'header.frame_id' expected string, got NoneType" in find_invalid_field(bad)
