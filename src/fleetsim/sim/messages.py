"""Plugin readings as ROS messages (pure conversions, used by the ``Simulator`` node)."""

from __future__ import annotations

import numpy as np

from fleetsim.msgs import (
    builtin_interfaces,
    gazebo_msgs,
    geometry_msgs,
    nav_msgs,
    sensor_msgs,
    std_msgs,
)
from fleetsim.sim.plugins.base import (
    ImageReading,
    JointStateReading,
    OdometryReading,
    ScanReading,
    TransformsReading,
)
from fleetsim.sim.queries import Contact


def stamp(t: float) -> builtin_interfaces.Time:
    """``t`` seconds (negative clamped to 0) as a Time; the parts of the last ``t`` are kept,
    since every reading of one simulator update shares its stamp (a new Time each call: a
    subscriber may change its copy)."""
    global _last_stamp
    last = _last_stamp
    if last[0] != t:
        s = builtin_interfaces.Time.from_sec(max(0.0, t))
        last = _last_stamp = (t, s.sec, s.nanosec)
    return _Time(last[1], last[2])


# The odometry conversions run for every robot at the odometry and ground-truth rates (100 Hz
# each), so they build each message once from its parts, positionally (the fields' order is the
# message definition's; keywords cost ~3x as much in a dataclass ``__init__``) and with the
# covariance arrays given (a default one comes from a factory): 5.6 -> ~2 us a message.
_Time, _Header = builtin_interfaces.Time, std_msgs.Header
_Point, _Quaternion, _Vector3 = geometry_msgs.Point, geometry_msgs.Quaternion, geometry_msgs.Vector3
_Pose, _Twist, _Transform = geometry_msgs.Pose, geometry_msgs.Twist, geometry_msgs.Transform
_PoseCov, _TwistCov = geometry_msgs.PoseWithCovariance, geometry_msgs.TwistWithCovariance
_Odometry, _TransformStamped = nav_msgs.Odometry, geometry_msgs.TransformStamped
_LaserScan = sensor_msgs.LaserScan
_last_stamp: tuple[float, int, int] = (float("nan"), 0, 0)
_zeros = np.zeros


def odometry_msg(r: OdometryReading) -> nav_msgs.Odometry:
    x, y, z = r.position.tolist()
    qx, qy, qz, qw = r.orientation.tolist()
    vx, vy, vz = r.linear.tolist()
    wx, wy, wz = r.angular.tolist()
    pose_cov, twist_cov = _zeros(36), _zeros(36)
    if r.covariance:
        pose_cov[::7] = r.covariance
        twist_cov[::7] = r.covariance
    return _Odometry(
        _Header(stamp(r.stamp), r.frame_id),
        r.child_frame_id,
        _PoseCov(_Pose(_Point(x, y, z), _Quaternion(qx, qy, qz, qw)), pose_cov),
        _TwistCov(_Twist(_Vector3(vx, vy, vz), _Vector3(wx, wy, wz)), twist_cov),
    )


def odometry_tf(r: OdometryReading) -> geometry_msgs.TransformStamped:
    x, y, z = r.position.tolist()
    qx, qy, qz, qw = r.orientation.tolist()
    return _TransformStamped(
        _Header(stamp(r.stamp), r.frame_id),
        r.child_frame_id,
        _Transform(_Vector3(x, y, z), _Quaternion(qx, qy, qz, qw)),
    )


def reading_tfs(r: TransformsReading) -> list[geometry_msgs.TransformStamped]:
    out = []
    for parent, child, pos, quat in r.transforms:
        x, y, z = pos.tolist()
        qx, qy, qz, qw = quat.tolist()
        out.append(
            _TransformStamped(
                _Header(stamp(r.stamp), parent),
                child,
                _Transform(_Vector3(x, y, z), _Quaternion(qx, qy, qz, qw)),
            )
        )
    return out


_RANGES = sensor_msgs.LaserScan.__dict__["ranges"]  # the slot the dataclass keeps them in
_NOT_CAST = np.zeros(0, np.float32)


class LazyLaserScan(sensor_msgs.LaserScan):
    """A ``sensor_msgs/msg/LaserScan`` whose ranges are cast when first read.

    A laser publishes at its rate whoever reads, but most readers take one scan in several (a
    costmap updating at 5 Hz keeps the newest of a 40 Hz laser's scans): the beams of the
    others need not be cast at all. To a reader this is the LaserScan it stands for: topics
    take it for one (``__lazy_of__``), it serializes as one and compares equal to one with the
    same fields; reading ``ranges`` casts them once (see ``fleetsim.sim.lasers.Sweep``)."""

    __slots__ = ("_reading",)
    __lazy_of__ = sensor_msgs.LaserScan

    @property
    def ranges(self) -> np.ndarray:
        reading = getattr(self, "_reading", None)
        if reading is not None:
            self._reading = None
            _RANGES.__set__(self, reading.ranges)
        return _RANGES.__get__(self)

    @ranges.setter
    def ranges(self, value: np.ndarray) -> None:
        self._reading = None
        _RANGES.__set__(self, value)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, sensor_msgs.LaserScan):
            return NotImplemented
        names = [f for f, _ in sensor_msgs.LaserScan.__msgfields__]
        return all(_same(getattr(self, f), getattr(other, f)) for f in names)

    __hash__ = None  # type: ignore[assignment]  # mutable, as the dataclass it stands for


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(a, b))
    return a == b


def scan_msg(r: ScanReading) -> sensor_msgs.LaserScan:
    """The reading as a LaserScan; a lazy one (``LazyLaserScan``) while its ranges are not cast."""
    msg = (_LaserScan if r.cast else LazyLaserScan)(
        _Header(stamp(r.stamp), r.frame_id),
        r.angle_min, r.angle_max, r.angle_increment, r.time_increment, r.scan_time,
        r.range_min, r.range_max, r.ranges if r.cast else _NOT_CAST, r.intensities,
    )  # fmt: skip
    if not r.cast:
        msg._reading = r
    return msg


def image_msg(t: float, frame_id: str, img: np.ndarray, encoding: str) -> sensor_msgs.Image:
    msg = sensor_msgs.Image()
    msg.header.stamp = stamp(t)
    msg.header.frame_id = frame_id
    msg.height, msg.width = int(img.shape[0]), int(img.shape[1])
    msg.encoding = encoding
    data = np.ascontiguousarray(img)
    msg.step = int(data.strides[0])
    msg.data = data.view(np.uint8).reshape(-1)
    return msg


def camera_info_msg(r: ImageReading) -> sensor_msgs.CameraInfo:
    msg = sensor_msgs.CameraInfo()
    msg.header.stamp = stamp(r.stamp)
    msg.header.frame_id = r.frame_id
    msg.height, msg.width = int(r.image.shape[0]), int(r.image.shape[1])
    msg.distortion_model = "plumb_bob"
    msg.d = np.zeros(5)
    msg.k = r.K.reshape(-1).astype(np.float64)
    msg.r = np.eye(3).reshape(-1)
    p = np.zeros((3, 4))
    p[:, :3] = r.K
    msg.p = p.reshape(-1)
    return msg


def cloud_msg(
    t: float, frame_id: str, depth: np.ndarray, rgb: np.ndarray, K: np.ndarray
) -> sensor_msgs.PointCloud2:
    """An organised XYZRGB cloud from a depth image, as the Kinect plugin publishes it.

    Points are in the optical frame of ``frame_id`` (x right, y down, z along the view):
    ``x = (u - cx) z / fx``, ``y = (v - cy) z / fy``, ``z = depth``; NaN depth (outside the
    cutoffs) gives NaN points, so the cloud is not dense. Layout is PCL's PointXYZRGB (x, y, z
    float32 at 0/4/8, rgb packed in a float32 at 16, 32 bytes per point).

    Parameters
    ----------
    depth : (H, W) float32 m; rgb : (H, W, 3) uint8; K : (3, 3) intrinsics of both images.
    """
    h, w = depth.shape
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    z = depth.astype(np.float32)
    u = np.arange(w, dtype=np.float32)[None, :]
    v = np.arange(h, dtype=np.float32)[:, None]
    pts = np.zeros((h, w, 8), np.float32)
    pts[..., 0] = (u - np.float32(cx)) * z / np.float32(fx)
    pts[..., 1] = (v - np.float32(cy)) * z / np.float32(fy)
    pts[..., 2] = z
    c = rgb.astype(np.uint32)
    pts[..., 4] = ((c[..., 0] << 16) | (c[..., 1] << 8) | c[..., 2]).view(np.float32)
    msg = sensor_msgs.PointCloud2()
    msg.header.stamp = stamp(t)
    msg.header.frame_id = frame_id
    msg.height, msg.width = h, w
    F = sensor_msgs.PointField
    msg.fields = [
        F(name=n, offset=o, datatype=F.FLOAT32, count=1)
        for n, o in (("x", 0), ("y", 4), ("z", 8), ("rgb", 16))
    ]
    msg.is_bigendian = False
    msg.point_step = 32
    msg.row_step = 32 * w
    msg.data = pts.view(np.uint8).reshape(-1)
    msg.is_dense = False
    return msg


def joint_state_msg(r: JointStateReading) -> sensor_msgs.JointState:
    msg = sensor_msgs.JointState()
    msg.header.stamp = stamp(r.stamp)
    msg.name = list(r.names)
    msg.position = np.asarray(r.position, np.float64)
    msg.velocity = np.asarray(r.velocity, np.float64)
    msg.effort = np.asarray(r.effort, np.float64)
    return msg


def contacts_msg(t: float, contacts: list[Contact]) -> gazebo_msgs.ContactsState:
    msg = gazebo_msgs.ContactsState()
    msg.header.stamp = stamp(t)
    msg.header.frame_id = "world"
    for c in contacts:
        s = gazebo_msgs.ContactState()
        s.info = f"{c.model1} touches {c.model2}"
        s.collision1_name = f"{c.model1}::{c.link1}"
        s.collision2_name = f"{c.model2}::{c.link2}"
        v = geometry_msgs.Vector3()
        v.x, v.y, v.z = c.position
        s.contact_positions = [v]
        s.depths = np.array([c.depth])
        msg.states.append(s)
    return msg


def model_states_msg(engine) -> gazebo_msgs.ModelStates:
    """Pose and twist (world frame) of every model, as gazebo publishes ``model_states``."""
    msg = gazebo_msgs.ModelStates()
    for name in engine.models:
        pos, quat = engine.model_pose(name)
        lin, ang = engine.model_twist(name)
        pose = geometry_msgs.Pose()
        pose.position.x, pose.position.y, pose.position.z = (float(v) for v in pos)
        o = pose.orientation
        o.w, o.x, o.y, o.z = (float(v) for v in quat)
        twist = geometry_msgs.Twist()
        twist.linear.x, twist.linear.y, twist.linear.z = (float(v) for v in lin)
        twist.angular.x, twist.angular.y, twist.angular.z = (float(v) for v in ang)
        msg.name.append(name)
        msg.pose.append(pose)
        msg.twist.append(twist)
    return msg
