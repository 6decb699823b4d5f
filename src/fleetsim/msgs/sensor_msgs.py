"""sensor_msgs: laser scans, images, camera info, joint states, IMU, point clouds."""

from __future__ import annotations

from typing import ClassVar

from fleetsim.msgs.fields import Arr, Seq, bool_, float32, float64, string, uint8, uint32
from fleetsim.msgs.geometry_msgs import Quaternion, Vector3
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("sensor_msgs/msg/LaserScan")
class LaserScan:
    """A planar scan: angles in rad (counter-clockwise, 0 = x of ``header.frame_id``), ranges in m.

    ``ranges`` and ``intensities`` are float32 arrays of shape (B,); out-of-range beams are
    ``inf`` (beyond ``range_max``) or ``nan``, per REP 117.
    """

    header: Header
    angle_min: float32
    angle_max: float32
    angle_increment: float32
    time_increment: float32
    scan_time: float32
    range_min: float32
    range_max: float32
    ranges: Seq[float32]
    intensities: Seq[float32]


@message("sensor_msgs/msg/Image")
class Image:
    """A raw image: ``data`` is uint8 of shape (height * step,), rows ``step`` bytes apart."""

    header: Header
    height: uint32
    width: uint32
    encoding: string
    is_bigendian: uint8
    step: uint32
    data: Seq[uint8]


@message("sensor_msgs/msg/CompressedImage")
class CompressedImage:
    header: Header
    format: string
    data: Seq[uint8]


@message("sensor_msgs/msg/RegionOfInterest")
class RegionOfInterest:
    x_offset: uint32
    y_offset: uint32
    height: uint32
    width: uint32
    do_rectify: bool_


@message("sensor_msgs/msg/CameraInfo")
class CameraInfo:
    """Pinhole calibration: ``k`` (3x3), ``r`` (3x3), ``p`` (3x4), row-major; ``d`` distortion."""

    header: Header
    height: uint32
    width: uint32
    distortion_model: string
    d: Seq[float64]
    k: Arr[float64, 9]
    r: Arr[float64, 9]
    p: Arr[float64, 12]
    binning_x: uint32
    binning_y: uint32
    roi: RegionOfInterest


@message("sensor_msgs/msg/JointState")
class JointState:
    """Joint positions (rad or m), velocities and efforts, by joint ``name``."""

    header: Header
    name: Seq[string]
    position: Seq[float64]
    velocity: Seq[float64]
    effort: Seq[float64]


@message("sensor_msgs/msg/Imu")
class Imu:
    """Orientation, angular velocity (rad/s), linear acceleration (m/s^2), 3x3 covariances."""

    header: Header
    orientation: Quaternion
    orientation_covariance: Arr[float64, 9]
    angular_velocity: Vector3
    angular_velocity_covariance: Arr[float64, 9]
    linear_acceleration: Vector3
    linear_acceleration_covariance: Arr[float64, 9]


@message("sensor_msgs/msg/PointField")
class PointField:
    """One field of a PointCloud2 point: byte ``offset``, ``datatype`` constant, ``count``."""

    INT8: ClassVar[uint8] = 1
    UINT8: ClassVar[uint8] = 2
    INT16: ClassVar[uint8] = 3
    UINT16: ClassVar[uint8] = 4
    INT32: ClassVar[uint8] = 5
    UINT32: ClassVar[uint8] = 6
    FLOAT32: ClassVar[uint8] = 7
    FLOAT64: ClassVar[uint8] = 8

    name: string
    offset: uint32
    datatype: uint8
    count: uint32


@message("sensor_msgs/msg/PointCloud2")
class PointCloud2:
    """An N-D point cloud: ``data`` is uint8 of shape (row_step * height,)."""

    header: Header
    height: uint32
    width: uint32
    fields: Seq[PointField]
    is_bigendian: bool_
    point_step: uint32
    row_step: uint32
    data: Seq[uint8]
    is_dense: bool_
