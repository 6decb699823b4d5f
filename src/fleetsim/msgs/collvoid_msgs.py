"""collvoid_msgs: what each robot shares about itself on ``/position_share``.

``PoseTwistWithCovariance`` carries collvoid's fields (robot_id, radius, holo_robot, controlled,
holonomic_velocity, pose, twist, footprint) with ROS 2 type names. The pose and footprint are in
the shared ``map`` frame; ``footprint`` is the robot's outline around its pose (robot frame,
already inflated by the localization uncertainty) and ``radius`` the circumscribed radius of
that outline. ``holonomic_velocity`` is the velocity the robot is tracking in the map frame.
"""

from __future__ import annotations

from fleetsim.msgs.fields import bool_, float64, string
from fleetsim.msgs.geometry_msgs import (
    PolygonStamped,
    PoseWithCovariance,
    TwistWithCovariance,
    Vector3,
)
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("collvoid_msgs/msg/PoseTwistWithCovariance")
class PoseTwistWithCovariance:
    header: Header
    robot_id: string
    radius: float64
    holo_robot: bool_
    controlled: bool_ = True
    holonomic_velocity: Vector3
    pose: PoseWithCovariance
    twist: TwistWithCovariance
    footprint: PolygonStamped
