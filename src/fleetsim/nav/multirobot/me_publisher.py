"""``collvoid/me_publisher``: a robot tells the others where it is, on ``/position_share``.

Every ``1 / publish_me_frequency`` s the node looks up its base in ``global_frame`` (newest tf)
and publishes a `collvoid_msgs.PoseTwistWithCovariance`:

* ``robot_id``: ``~name``, else the robot's ``tf_prefix``, else its namespace without slashes;
* ``footprint``: ``~footprint`` (``[[x, y], ...]``, robot frame; else the footprint of the
  costmap ``~costmap`` names, a fleetsim addition; else a ``~robot_radius`` circle) padded by
  the localization uncertainty, ``radius`` its circumscribed radius;
* the uncertainty: the x/y covariance of the latest ``particlecloud`` (amcl's PoseArray,
  relative name, so it is ``/lizi1/particlecloud``), shared in ``pose.covariance``; the
  footprint is padded by its widest 1 - ``eps`` spread (a 2-D Gaussian's, along the major
  axis: `widest_spread`), capped at twice the robot radius, so a consumer that ignores the
  covariance keeps clear of the robot in every direction, and one that reads it takes the
  padding off again (`uncertainty.shared_padding`) and pads by the spread in the direction
  that matters (issue 18). fake_localization's cloud is the one true pose: a cloud of one pose
  (or none) counts as zero uncertainty and a zero covariance, as before any cloud arrives;
* ``pose`` (map frame), ``twist`` (``odom``'s twist, base frame) and ``holonomic_velocity``
  (that velocity turned into the map frame);
* ``controlled``: ``~controlled``, and - once ``move_base/status`` has been heard - only while
  move_base has a goal pending or active. A robot parked at its goal does not avoid anyone, so
  the others take the whole avoidance on themselves and do not wait for it to yield.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.errors import ParameterError, TransformError
from fleetsim.msgs import actionlib_msgs, collvoid_msgs, geometry_msgs, nav_msgs
from fleetsim.nav.costmap.footprint import (
    footprint_from_param,
    footprint_from_radius,
    footprint_radii,
    padded_footprint,
)
from fleetsim.nav.multirobot.position_share import TOPIC, XY_COVARIANCE
from fleetsim.nav.multirobot.uncertainty import cloud_covariance, widest_spread
from fleetsim.runtime import Node, param
from fleetsim.tf import resolve_frame_once
from fleetsim.tf.names import normalize_frame
from fleetsim.tf.quaternions import quaternion_from_yaw

#: s of sim time without a transform before the node warns (tf comes up a moment late)
TF_GRACE = 2.0


@dataclass(frozen=True)
class MePublisherParams:
    """``me_publisher`` private parameters (collvoid's names and defaults)."""

    publish_me_frequency: float = param(
        10.0, unit="Hz", range=(1e-6, None), help="rate of the /position_share messages"
    )
    eps: float = param(
        0.1,
        range=(0.0, 0.999),
        help="share of the position spread allowed outside the padding (the fleet's: the "
        "planners take the padding off with theirs)",
    )
    holo_robot: bool = param(False, help="the robot is holonomic")
    controlled: bool = param(True, help="the robot avoids others (else they avoid it fully)")
    base_frame: str = param("base_link", help="the robot's base frame (tf_prefix applied)")
    global_frame: str = param("/map", help="the shared frame poses are published in")
    name: str = param("", help="robot_id (empty: the tf_prefix, else the namespace)")
    footprint: str | list = param("[]", help="robot polygon [[x, y], ...] in the base frame")
    robot_radius: float = param(
        0.2, unit="m", range=(0.0, None), help="circular robot when no footprint is given"
    )
    costmap: str = param(
        "",
        help="a costmap's namespace (e.g. move_base_node/local_costmap) whose footprint, "
        "footprint_padding or robot_radius is shared when ~footprint is not given (fleetsim "
        "addition: collvoid's planner-side agent takes its local costmap's footprint)",
    )


class MePublisher(Node):
    """Publishes this robot's id, pose, velocity and inflated footprint on /position_share."""

    Params = MePublisherParams

    def __init__(self, runtime, name: str = "me_publisher", namespace: str = "/", **kw: Any):
        super().__init__(runtime, name, namespace, **kw)
        p: MePublisherParams = self.params
        self.footprint = self._footprint(p)
        self.robot_radius = footprint_radii(self.footprint)[1]
        self.robot_id = p.name or self.tf_prefix or self.namespace.strip("/").replace("/", "_")
        self.base_frame = resolve_frame_once(self.tf_prefix, p.base_frame)
        self.global_frame = normalize_frame(p.global_frame)
        self._covariance: np.ndarray | None = None
        self._body_vel = (0.0, 0.0, 0.0)
        self._navigating: bool | None = None  # None until move_base/status is heard
        self._started = self.now()
        self.pub = self.create_publisher(collvoid_msgs.PoseTwistWithCovariance, TOPIC, 10)
        self.create_subscription(geometry_msgs.PoseArray, "particlecloud", self.on_cloud, 1)
        self.create_subscription(nav_msgs.Odometry, "odom", self.on_odom, 1)
        self.create_subscription(
            actionlib_msgs.GoalStatusArray, "move_base/status", self.on_status, 1
        )
        _ = self.tf_buffer
        self.create_timer(1.0 / p.publish_me_frequency, self.publish_me)

    def _footprint(self, p: MePublisherParams) -> np.ndarray:
        """``~footprint``; else the footprint of the costmap ``~costmap`` names (its
        ``footprint`` padded by ``footprint_padding``, or its ``robot_radius``); else a
        ``~robot_radius`` circle."""
        if not (isinstance(p.footprint, str) and p.footprint.strip() in ("", "[]")):
            return footprint_from_param(p.footprint, f"{self.full_name}/footprint")
        if p.costmap:
            ns = p.costmap.rstrip("/")
            value = self.get_param(f"{ns}/footprint")
            if value is not None and not (isinstance(value, str) and value.strip() in ("", "[]")):
                where = f"{self.resolve_name(ns)}/footprint (~costmap)"
                padding = float(self.get_param(f"{ns}/footprint_padding", 0.0))
                return padded_footprint(footprint_from_param(value, where), padding)
            radius = self.get_param(f"{ns}/robot_radius")
            if radius is None:
                raise ParameterError(
                    f"{self.full_name}: ~costmap is {p.costmap!r}, but "
                    f"{self.resolve_name(ns)} has neither a footprint nor a robot_radius"
                )
            return footprint_from_radius(float(radius))
        return footprint_from_radius(p.robot_radius)

    def on_cloud(self, msg: Any) -> None:
        self._covariance = cloud_covariance(
            np.array([[q.position.x, q.position.y] for q in msg.poses], dtype=np.float64)
        )

    def on_odom(self, msg: Any) -> None:
        t = msg.twist.twist
        self._body_vel = (t.linear.x, t.linear.y, t.angular.z)

    def on_status(self, msg: Any) -> None:
        busy = (actionlib_msgs.GoalStatus.PENDING, actionlib_msgs.GoalStatus.ACTIVE)
        self._navigating = any(st.status in busy for st in msg.status_list)

    @property
    def controlled(self) -> bool:
        """Whether the robot avoids others now (see the module doc)."""
        return self.params.controlled and self._navigating is not False

    def uncertainty(self) -> float:
        """The footprint's padding, m: the cloud's widest 1 - eps spread, capped at twice the
        robot radius; 0 without a cloud or with a cloud of one pose (fake_localization's: the
        true pose, published a moment apart from the tf the estimate comes from, so a moving
        robot would be padded by the distance it drove in between), as the planner takes it."""
        if self._covariance is None:
            return 0.0
        return widest_spread(self._covariance, self.params.eps, 2.0 * self.robot_radius)

    def publish_me(self) -> None:
        try:
            x, y, yaw = self.tf_buffer.lookup_pose2d(self.global_frame, self.base_frame, 0.0)
        except TransformError as err:
            if self.now() - self._started > TF_GRACE:
                self._warn_once("tf", f"cannot share the robot's position yet: {err}")
            return
        unc = self.uncertainty()
        fp = padded_footprint(self.footprint, unc) if unc > 0 else self.footprint
        c, s = math.cos(yaw), math.sin(yaw)
        bvx, bvy, bw = self._body_vel
        vx, vy = c * bvx - s * bvy, s * bvx + c * bvy
        msg = collvoid_msgs.PoseTwistWithCovariance(
            robot_id=self.robot_id,
            radius=footprint_radii(fp)[1],
            holo_robot=self.params.holo_robot,
            controlled=self.controlled,
        )
        msg.header.stamp = self.now_msg()
        msg.header.frame_id = self.global_frame
        msg.holonomic_velocity = geometry_msgs.Vector3(x=vx, y=vy)
        q = quaternion_from_yaw(yaw)
        msg.pose.pose = geometry_msgs.Pose(
            position=geometry_msgs.Point(x=x, y=y),
            orientation=geometry_msgs.Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]),
        )
        if self._covariance is not None:
            msg.pose.covariance[XY_COVARIANCE] = self._covariance.reshape(-1)
        msg.twist.twist.linear = geometry_msgs.Vector3(x=bvx, y=bvy)
        msg.twist.twist.angular = geometry_msgs.Vector3(z=bw)
        msg.footprint.header = msg.header
        msg.footprint.polygon.points = [
            geometry_msgs.Point32(x=float(px), y=float(py)) for px, py in fp
        ]
        self.pub.publish(msg)
