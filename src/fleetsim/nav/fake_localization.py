"""The ``fake_localization`` node: perfect localization from the simulator's ground truth.

As ROS's fake_localization: each ``base_pose_ground_truth`` (nav_msgs/Odometry, the pose of the
robot's base in the simulator's world) is turned into the ``global_frame_id -> odom_frame_id``
transform that makes ``map -> odom -> base`` equal to that pose, using ``odom -> base`` from tf
at the message's stamp. The transform is dated ``transform_tolerance`` into the future, as
amcl's is. The same pose goes out on ``amcl_pose`` (PoseWithCovarianceStamped, latched) and as
the single pose of ``particlecloud`` (PoseArray, latched).

``delta_x``, ``delta_y``, ``delta_yaw`` give the simulator's origin in the map; the pose
published is ``offset * ground_truth`` with ``offset = (-delta_x, -delta_y, -delta_yaw)``, as
fake_localization.cpp builds it. An ``initialpose`` (PoseWithCovarianceStamped in the global
frame) shifts the offset so that the robot is localized at that pose from then on.

Frames: ``odom_frame_id`` and ``base_frame_id`` get the robot's ``tf_prefix`` (a frame already
spelled with the prefix, as the seeds' launch files write ``$(arg robot_name)/odom``, is left
alone); ``global_frame_id`` (default ``/map``) is resolved the same way, so ``/map`` is ``map``.
A message whose transform is not in tf yet is kept (up to 100, as ROS's message filter) and
retried when the next one arrives; it is reported only when tf stays silent for the grace period
(`fleetsim.tf.patience`). No ground truth at all for that long is reported with what provides
it (the p3d plugin).

Rate: ROS's node does this for every message (100 Hz from a p3d plugin). The transform is dated
``transform_tolerance`` ahead, so consumers looking up ``map -> base`` at the present need a new
one only every ``transform_tolerance``; ``publish_rate`` (a fleetsim addition, 20 Hz; 0: every
message as ROS) publishes the newest ground truth at that rate (and at least twice per
``transform_tolerance``), so what users see (tf, amcl_pose, particlecloud) is the same, and the
per-robot cost is a fifth of it.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Any

from fleetsim.errors import ExtrapolationError, TransformError
from fleetsim.msgs import geometry_msgs, nav_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.runtime import Node, param
from fleetsim.tf import TransformBroadcaster, make_transform_stamped, resolve_frame_once
from fleetsim.tf.fastmath import Transform7, compose, invert
from fleetsim.tf.names import normalize_frame
from fleetsim.tf.patience import GRACE, TransformPatience

#: messages waiting for their odom -> base transform (tf2_ros::MessageFilter's queue size)
QUEUE_SIZE = 100


@dataclass(frozen=True)
class FakeLocalizationParams:
    """``fake_localization`` private parameters (ROS names and defaults)."""

    odom_frame_id: str = param("odom", help="odometry frame (tf_prefix applied)")
    base_frame_id: str = param("base_link", help="robot base frame (tf_prefix applied)")
    global_frame_id: str = param("/map", help="frame the pose is published in")
    delta_x: float = param(0.0, unit="m", help="x of the simulator origin in the map")
    delta_y: float = param(0.0, unit="m", help="y of the simulator origin in the map")
    delta_yaw: float = param(0.0, unit="rad", help="yaw of the simulator origin in the map")
    transform_tolerance: float = param(
        0.1, unit="s", range=(0.0, None), help="how far into the future the tf is dated"
    )
    publish_rate: float = param(
        20.0,
        unit="Hz",
        range=(0.0, None),
        help="tf and pose rate, at least 2 / transform_tolerance; 0: every message "
        "(fleetsim addition)",
    )


def _pose7(pose: Any) -> Transform7:
    """A Pose as a transform tuple, its quaternion normalised."""
    p, q = pose.position, pose.orientation
    n = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
    if not n > 0.0:
        return (p.x, p.y, p.z, 0.0, 0.0, 0.0, 1.0)
    return (p.x, p.y, p.z, q.x / n, q.y / n, q.z / n, q.w / n)


def _pose_msg(t: Transform7) -> geometry_msgs.Pose:
    return geometry_msgs.Pose(
        position=geometry_msgs.Point(x=t[0], y=t[1], z=t[2]),
        orientation=geometry_msgs.Quaternion(x=t[3], y=t[4], z=t[5], w=t[6]),
    )


class FakeLocalization(Node):
    """Publishes ``map -> odom`` from ground truth, for one robot namespace."""

    Params = FakeLocalizationParams

    def __init__(
        self, runtime, name: str = "fake_localization", namespace: str = "/", **kw: Any
    ) -> None:
        super().__init__(runtime, name, namespace, **kw)
        p: FakeLocalizationParams = self.params
        prefix = self.tf_prefix
        self.odom_frame = resolve_frame_once(prefix, p.odom_frame_id)
        self.base_frame = resolve_frame_once(prefix, p.base_frame_id)
        self.global_frame = resolve_frame_once(prefix, p.global_frame_id)
        # offset = (-delta_x, -delta_y) translation, -delta_yaw rotation (fake_localization.cpp)
        half = -p.delta_yaw / 2.0
        self.offset: Transform7 = (
            -p.delta_x, -p.delta_y, 0.0, 0.0, 0.0, math.sin(half), math.cos(half)
        )  # fmt: skip
        self._pending: deque[nav_msgs.Odometry] = deque(maxlen=QUEUE_SIZE)
        self._patience = TransformPatience()
        period = 1.0 / p.publish_rate if p.publish_rate > 0 else 0.0
        self._period_ns = round(min(period, p.transform_tolerance / 2) * 1e9)
        self._published_ns: int | None = None  # stamp of the newest ground truth published
        self._heard: float | None = None  # sim time of the newest ground truth received
        self._started = self.now()
        self.tf_pub = TransformBroadcaster(self)
        _ = self.tf_buffer  # the runtime's buffer listens to /tf from now on
        self.pose_pub = self.create_publisher(
            geometry_msgs.PoseWithCovarianceStamped, "amcl_pose", queue_size=1, latch=True
        )
        self.cloud_pub = self.create_publisher(
            geometry_msgs.PoseArray, "particlecloud", queue_size=1, latch=True
        )
        self.truth_sub = self.create_subscription(
            nav_msgs.Odometry, "base_pose_ground_truth", self.on_ground_truth, QUEUE_SIZE
        )
        self.create_timer(1.0, self._check_ground_truth)
        self.create_subscription(
            geometry_msgs.PoseWithCovarianceStamped, "initialpose", self.on_initial_pose, 1
        )

    # -- ground truth --------------------------------------------------------------------------
    def on_ground_truth(self, msg: nav_msgs.Odometry) -> None:
        """Queue the message when it is due, and publish every queued one whose odom -> base
        is in tf."""
        self._heard = self.now()
        self._warned.discard("silent")
        last = self._published_ns
        if (
            not self._pending  # nothing waiting for tf
            and last is not None
            and msg.header.stamp.to_nsec() - last < self._period_ns
        ):
            return  # the tf published last still covers the present
        self._pending.append(msg)
        while self._pending:
            if not self._update(self._pending[0]):
                return
            self._published_ns = self._pending.popleft().header.stamp.to_nsec()

    def _check_ground_truth(self) -> None:
        """Say so when no ground truth has come for the grace period, and what provides it."""
        now = self.now()
        silent = now - (self._started if self._heard is None else self._heard)
        if silent < GRACE:
            return
        since = "since the start" if self._heard is None else f"since {self._heard:.2f} s"
        self._warn_once(
            "silent",
            f"no ground truth on {self.truth_sub.topic.name} {since} ({silent:.1f} s), so no "
            f"{self.global_frame} -> {self.odom_frame} transform: it comes from the simulator's "
            'p3d plugin, a <gazebo><plugin filename="libgazebo_ros_p3d.so"> on the robot\'s '
            "base with <topicName>base_pose_ground_truth</topicName> (or remap "
            "base_pose_ground_truth to the topic it publishes)",
        )

    def _update(self, msg: nav_msgs.Odometry) -> bool:
        """Publish tf and pose for one message; False when tf cannot answer yet."""
        stamp = msg.header.stamp
        try:
            ob = self.tf_buffer.lookup_tuple(self.odom_frame, self.base_frame, stamp)
        except ExtrapolationError as err:
            newest = self._newest_odom_time()
            if newest is not None and newest > stamp.to_sec():
                self._warn_once("old", f"dropping ground truth older than tf's history: {err}")
                return True  # too old ever to be answered: drop it
            return False
        except TransformError as err:
            if self._patience.missing_too_long("lookup", self.now()):
                waited = self._patience.missing_for("lookup", self.now())
                self._warn_once(
                    "lookup",
                    f"waiting for tf {self.odom_frame} -> {self.base_frame} for {waited:.1f} s: "
                    f"{err}; is odometry published, and are odom_frame_id / base_frame_id / "
                    "tf_prefix right?",
                )
            return False
        self._patience.found("lookup")
        # one transform in plain floats (tf.fastmath): NumPy's per-call overhead was most of it
        mb = compose(self.offset, _pose7(msg.pose.pose))
        mo = compose(mb, invert(ob))  # map -> odom = (map -> base) * (odom -> base)^-1
        future = Time.from_nsec(stamp.to_nsec() + round(self.params.transform_tolerance * 1e9))
        self.tf_pub.send_transform(
            make_transform_stamped(self.global_frame, self.odom_frame, future, mo[:3], mo[3:])
        )
        # built only for a reader (nobody subscribes in a fleet's stack; both are latched, so a
        # later subscription gets these)
        frame = self.global_frame
        self.pose_pub.publish_lazily(
            lambda: geometry_msgs.PoseWithCovarianceStamped(
                header=std_msgs.Header(stamp=stamp, frame_id=frame),
                pose=geometry_msgs.PoseWithCovariance(pose=_pose_msg(mb)),
            )
        )
        self.cloud_pub.publish_lazily(
            lambda: geometry_msgs.PoseArray(
                header=std_msgs.Header(stamp=stamp, frame_id=frame), poses=[_pose_msg(mb)]
            )
        )
        return True

    def _newest_odom_time(self) -> float | None:
        try:
            return self.tf_buffer.latest_common_time(self.odom_frame, self.base_frame)
        except TransformError:
            return None

    # -- initial pose ----------------------------------------------------------------------------
    def on_initial_pose(self, msg: geometry_msgs.PoseWithCovarianceStamped) -> None:
        """Shift the offset so that the robot is now at ``msg``'s pose (initPoseReceived)."""
        frame = normalize_frame(msg.header.frame_id) if msg.header.frame_id else ""
        if frame != self.global_frame:
            self.get_logger().warning(
                f"Frame ID of 'initialpose' ({frame}) is different from the global frame "
                f"{self.global_frame}"
            )
        try:
            bm = self.tf_buffer.lookup_tuple(self.base_frame, self.global_frame, msg.header.stamp)
        except TransformError as err:
            self.get_logger().warning(f"ignoring initialpose: failed to look up the robot: {err}")
            return
        self.offset = compose(compose(_pose7(msg.pose.pose), bm), self.offset)
