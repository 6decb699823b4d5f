from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rosbags.typesys import Stores, get_typestore

from fleetsim.errors import MessageError
from fleetsim.msgs import (
    all_types,
    deserialize,
    geometry_msgs,
    msgdef,
    msgs_equal,
    nav_msgs,
    sensor_msgs,
    serialize,
    std_msgs,
)

ROS2 = get_typestore(Stores.ROS2_HUMBLE)  # an untouched store: what ROS 2 tools decode with
NAMES = sorted(all_types())


@pytest.mark.parametrize("name", NAMES)
def test_round_trip_default_and_populated(name, populated):
    cls = all_types()[name]
    for msg in (cls(), populated(cls, seed=len(name))):
        data = serialize(msg)
        assert isinstance(data, bytes)
        back = deserialize(data, name)
        assert type(back) is cls
        assert msgs_equal(msg, back), name


@pytest.mark.parametrize("name", [n for n in NAMES if n in ROS2.fielddefs])
def test_standard_types_decode_with_rosbags(name, populated):
    msg = populated(all_types()[name], seed=1)
    theirs = ROS2.deserialize_cdr(serialize(msg), name)
    assert _same_values(msg, theirs), name
    assert msgdef(name) == ROS2.generate_msgdef(name, ros_version=2)[0]


def _same_values(ours, theirs) -> bool:
    if hasattr(ours, "__msgfields__"):
        return all(
            _same_values(getattr(ours, f), getattr(theirs, f)) for f, _ in ours.__msgfields__
        )
    if isinstance(ours, list):
        return len(ours) == len(theirs) and all(map(_same_values, ours, theirs))
    return msgs_equal(ours, theirs)


def test_bytes_are_ros2_cdr():
    data = serialize(std_msgs.Int32(data=7))
    assert data == b"\x00\x01\x00\x00\x07\x00\x00\x00"
    assert serialize(std_msgs.Empty()) == b"\x00\x01\x00\x00\x00"


def test_arrays_of_other_dtypes_are_converted_without_touching_the_message():
    ranges = np.arange(6, dtype=np.float64).reshape(2, 3)
    scan = sensor_msgs.LaserScan(ranges=ranges)
    back = deserialize(serialize(scan), "sensor_msgs/LaserScan")
    assert back.ranges.dtype == np.float32
    assert back.ranges.tolist() == [0, 1, 2, 3, 4, 5]
    assert scan.ranges is ranges
    grid = nav_msgs.OccupancyGrid(data=[0, 100, -1])
    assert deserialize(serialize(grid), "nav_msgs/OccupancyGrid").data.tolist() == [0, 100, -1]
    odom = nav_msgs.Odometry()
    odom.pose.covariance = list(range(36))
    assert deserialize(serialize(odom), "nav_msgs/Odometry").pose.covariance[35] == 35.0


def test_decoded_arrays_are_read_only():
    back = deserialize(
        serialize(sensor_msgs.LaserScan(ranges=np.ones(3, np.float32))), "sensor_msgs/msg/LaserScan"
    )
    assert not back.ranges.flags.writeable


def test_bad_values_name_the_field():
    with pytest.raises(MessageError, match=r"OccupancyGrid.data: values 0..200 do not fit int8"):
        serialize(nav_msgs.OccupancyGrid(data=[0, 200]))
    with pytest.raises(MessageError, match=r"covariance: expected 36 float64 values, got 3"):
        serialize(geometry_msgs.PoseWithCovariance(covariance=np.zeros(3)))
    with pytest.raises(MessageError, match=r"field 'pose.position.x' expected float64, got str"):
        serialize(
            geometry_msgs.PoseStamped(pose=geometry_msgs.Pose(position=geometry_msgs.Point(x="a")))
        )
    with pytest.raises(MessageError, match=r"field 'frame_id' expected string, got int"):
        serialize(std_msgs.Header(frame_id=3))
    with pytest.raises(MessageError, match=r"ranges: expected float32 values, got list of <U1"):
        serialize(sensor_msgs.LaserScan(ranges=["a"]))


def test_undecodable_bytes():
    with pytest.raises(MessageError, match=r"cannot decode 3 bytes as std_msgs/msg/Int32"):
        deserialize(b"\x00\x01\x00", "std_msgs/Int32")
    with pytest.raises(MessageError, match=r"cannot decode .* as sensor_msgs/msg/LaserScan"):
        deserialize(serialize(std_msgs.Int32(data=1)), "sensor_msgs/LaserScan")


def test_msgdef_format_for_mcap():
    text = msgdef("geometry_msgs/PoseStamped")
    assert text.startswith("std_msgs/Header header\ngeometry_msgs/Pose pose\n")
    assert "=" * 80 + "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n" in text
    status = msgdef("actionlib_msgs/msg/GoalStatus")
    assert "uint8 PENDING=0" in status and "uint8 LOST=9" in status


def test_user_types_and_redefinition():
    def define():
        from fleetsim.msgs import message
        from fleetsim.msgs.fields import Seq, float32, string

        @message("fleetsim_test/msg/Beacon")
        class Beacon:
            name: string
            signal: Seq[float32]

        return Beacon

    first = define()
    b = first(name="dock", signal=np.array([1.5], np.float32))
    assert type(deserialize(serialize(b), "fleetsim_test/Beacon")) is first
    second = define()  # e.g. a module reloaded: same name and fields
    back = deserialize(serialize(second(name="x")), "fleetsim_test/msg/Beacon")
    assert type(back) is second and back.name == "x"
    assert msgdef("fleetsim_test/Beacon") == "string name\nfloat32[] signal\n"


def test_wrong_nested_values_name_the_field():
    with pytest.raises(MessageError, match=r"field 'pose' expected a mapping .* got NoneType"):
        serialize(nav_msgs.Odometry(pose=None))
    with pytest.raises(
        MessageError,
        match=r"^cannot serialize std_msgs/msg/Header: field 'stamp' expected a mapping .* float",
    ):
        serialize(std_msgs.Header(stamp=1.5))
    with pytest.raises(MessageError, match=r"field 'poses\[0\]' expected a mapping .* got int"):
        serialize(geometry_msgs.PoseArray(poses=[3]))


@settings(max_examples=50, deadline=None)
@given(
    ranges=st.lists(st.floats(width=32, allow_nan=True), max_size=40),
    frame=st.text(max_size=12),
    sec=st.integers(-(2**31), 2**31 - 1),
)
def test_scan_round_trip_is_bit_exact(ranges, frame, sec):
    scan = sensor_msgs.LaserScan(ranges=np.array(ranges, np.float32))
    scan.header.frame_id = frame
    scan.header.stamp.sec = sec
    back = deserialize(serialize(scan), "sensor_msgs/LaserScan")
    assert back.ranges.tobytes() == scan.ranges.tobytes()
    assert back.header == scan.header
