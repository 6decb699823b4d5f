"""geometry_msgs: points, vectors, poses, transforms, twists, wrenches, polygons."""

from __future__ import annotations

from fleetsim.msgs.fields import Arr, Seq, float32, float64, string
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("geometry_msgs/msg/Point")
class Point:
    x: float64
    y: float64
    z: float64


@message("geometry_msgs/msg/Point32")
class Point32:
    x: float32
    y: float32
    z: float32


@message("geometry_msgs/msg/PointStamped")
class PointStamped:
    header: Header
    point: Point


@message("geometry_msgs/msg/Vector3")
class Vector3:
    x: float64
    y: float64
    z: float64


@message("geometry_msgs/msg/Vector3Stamped")
class Vector3Stamped:
    header: Header
    vector: Vector3


@message("geometry_msgs/msg/Quaternion")
class Quaternion:
    """A rotation as a unit quaternion; the default is the identity (w=1, as in ROS 2)."""

    x: float64
    y: float64
    z: float64
    w: float64 = 1.0


@message("geometry_msgs/msg/QuaternionStamped")
class QuaternionStamped:
    header: Header
    quaternion: Quaternion


@message("geometry_msgs/msg/Pose")
class Pose:
    position: Point
    orientation: Quaternion


@message("geometry_msgs/msg/Pose2D")
class Pose2D:
    x: float64
    y: float64
    theta: float64


@message("geometry_msgs/msg/PoseStamped")
class PoseStamped:
    header: Header
    pose: Pose


@message("geometry_msgs/msg/PoseWithCovariance")
class PoseWithCovariance:
    """Pose with a row-major 6x6 covariance over (x, y, z, rot x, rot y, rot z)."""

    pose: Pose
    covariance: Arr[float64, 36]


@message("geometry_msgs/msg/PoseWithCovarianceStamped")
class PoseWithCovarianceStamped:
    header: Header
    pose: PoseWithCovariance


@message("geometry_msgs/msg/PoseArray")
class PoseArray:
    header: Header
    poses: Seq[Pose]


@message("geometry_msgs/msg/Transform")
class Transform:
    translation: Vector3
    rotation: Quaternion


@message("geometry_msgs/msg/TransformStamped")
class TransformStamped:
    """Transform from frame ``child_frame_id`` to frame ``header.frame_id``."""

    header: Header
    child_frame_id: string
    transform: Transform


@message("geometry_msgs/msg/Twist")
class Twist:
    linear: Vector3
    angular: Vector3


@message("geometry_msgs/msg/TwistStamped")
class TwistStamped:
    header: Header
    twist: Twist


@message("geometry_msgs/msg/TwistWithCovariance")
class TwistWithCovariance:
    """Twist with a row-major 6x6 covariance over (vx, vy, vz, wx, wy, wz)."""

    twist: Twist
    covariance: Arr[float64, 36]


@message("geometry_msgs/msg/TwistWithCovarianceStamped")
class TwistWithCovarianceStamped:
    header: Header
    twist: TwistWithCovariance


@message("geometry_msgs/msg/Accel")
class Accel:
    linear: Vector3
    angular: Vector3


@message("geometry_msgs/msg/AccelStamped")
class AccelStamped:
    header: Header
    accel: Accel


@message("geometry_msgs/msg/Wrench")
class Wrench:
    force: Vector3
    torque: Vector3


@message("geometry_msgs/msg/WrenchStamped")
class WrenchStamped:
    header: Header
    wrench: Wrench


@message("geometry_msgs/msg/Polygon")
class Polygon:
    points: Seq[Point32]


@message("geometry_msgs/msg/PolygonStamped")
class PolygonStamped:
    header: Header
    polygon: Polygon
