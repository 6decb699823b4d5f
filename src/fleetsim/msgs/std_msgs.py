"""std_msgs: Header and the common one-field wrappers."""

from __future__ import annotations

from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.fields import (
    Seq,
    bool_,
    byte,
    char,
    float32,
    float64,
    int8,
    int16,
    int32,
    int64,
    string,
    uint8,
    uint16,
    uint32,
    uint64,
)
from fleetsim.msgs.registry import message


@message("std_msgs/msg/Header")
class Header:
    """Stamp and frame of a message (ROS 1's ``seq`` is gone in ROS 2)."""

    stamp: Time
    frame_id: string


@message("std_msgs/msg/Empty")
class Empty:
    pass


@message("std_msgs/msg/String")
class String:
    data: string


@message("std_msgs/msg/Bool")
class Bool:
    data: bool_


@message("std_msgs/msg/Byte")
class Byte:
    data: byte


@message("std_msgs/msg/Char")
class Char:
    data: char


@message("std_msgs/msg/Int8")
class Int8:
    data: int8


@message("std_msgs/msg/UInt8")
class UInt8:
    data: uint8


@message("std_msgs/msg/Int16")
class Int16:
    data: int16


@message("std_msgs/msg/UInt16")
class UInt16:
    data: uint16


@message("std_msgs/msg/Int32")
class Int32:
    data: int32


@message("std_msgs/msg/UInt32")
class UInt32:
    data: uint32


@message("std_msgs/msg/Int64")
class Int64:
    data: int64


@message("std_msgs/msg/UInt64")
class UInt64:
    data: uint64


@message("std_msgs/msg/Float32")
class Float32:
    data: float32


@message("std_msgs/msg/Float64")
class Float64:
    data: float64


@message("std_msgs/msg/ColorRGBA")
class ColorRGBA:
    """A colour, each channel in [0, 1]."""

    r: float32
    g: float32
    b: float32
    a: float32


@message("std_msgs/msg/MultiArrayDimension")
class MultiArrayDimension:
    label: string
    size: uint32
    stride: uint32


@message("std_msgs/msg/MultiArrayLayout")
class MultiArrayLayout:
    dim: Seq[MultiArrayDimension]
    data_offset: uint32


@message("std_msgs/msg/Float32MultiArray")
class Float32MultiArray:
    layout: MultiArrayLayout
    data: Seq[float32]


@message("std_msgs/msg/Float64MultiArray")
class Float64MultiArray:
    layout: MultiArrayLayout
    data: Seq[float64]


@message("std_msgs/msg/Int32MultiArray")
class Int32MultiArray:
    layout: MultiArrayLayout
    data: Seq[int32]


@message("std_msgs/msg/UInt8MultiArray")
class UInt8MultiArray:
    layout: MultiArrayLayout
    data: Seq[uint8]
