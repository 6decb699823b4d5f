"""``follow_marker`` (grobot_navigation): keep a robot behind an ArUco marker with move_base.

Driven entirely by ``fiducial_transforms`` (fiducial_msgs/FiducialTransformArray, one per camera
frame, empty when nothing was seen), as grobot's ``MarkerFollower`` is. For each message:

1. the marker ``~marker_id`` is not in it: when more than 4 s of image time have passed since
   the last update, start the exploration (`fleetsim.apps.exploration`; a running one is left
   alone);
2. it is, and an exploration runs: cancel it (once) and count this as an update, no goal;
3. otherwise re-orient the marker's pose (camera optical frame) by RPY(0, pi/2, pi/2), so that
   x points into the marker's face and z up, and look it up in ``base_footprint`` at the image
   stamp: closer than twice the target offset (0.8 m -> 1.6 m, planar) counts as an update
   without a goal (move_base finishes the last one);
4. else look it up in ``map``, apply the offset ``~marker_to_target_pose`` (x, y; yaw 0), keep
   x, y and yaw, publish that on ``move_base_simple/goal``, broadcast ``map -> target`` and count
   it as an update.

A tf failure means no update (and a warning once it has lasted tf's grace period).
Every 5 s ``move_base/clear_costmaps`` is called (the
moving target's stale obstacle marks). Unlike the original, which constructs its errors without
throwing them, wrong parameters are `ParameterError`s naming the parameter; every parameter
has the tutorial's launch value as its default (the original has none).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.apps.exploration import Exploration, Follower, pose_stamped
from fleetsim.errors import ServiceError, TransformError
from fleetsim.msgs import fiducial_msgs, geometry_msgs, std_srvs
from fleetsim.runtime import Node, param
from fleetsim.runtime.params import load_params
from fleetsim.tf import TransformBroadcaster, make_transform_stamped
from fleetsim.tf.patience import TransformPatience
from fleetsim.tf.quaternions import quaternion_from_euler, quaternion_from_yaw, yaw_from_quaternion
from fleetsim.tf.transforms import compose_transforms

#: the marker is lost after this much image time without an update (s)
UPDATE_TIMEOUT = 4.0
#: s of image time with other markers seen and ours never before that is warned about
OTHERS_ONLY_TIME = 10.0
#: images with other markers needed for that warning: a glimpse of another robot's marker
#: while the follower explores for its own is no sign of a wrong marker_id
OTHERS_MIN_IMAGES = 10


class OtherMarkersWatch:
    """Warns once when `OTHERS_ONLY_TIME` s of image time after the camera first saw a marker
    it has still not seen the followed ``marker_id`` (an id the marker does not carry, or one
    outside the detector's dictionary, which a follower cannot check: it only explores).
    Shared by the tutorial's follower and the predictive one."""

    def __init__(self, node: Node, marker_id: int) -> None:
        self.node = node
        self.marker_id = marker_id
        self.others: set[int] = set()  # ids seen while ours never was
        self.images = 0  # images that showed them
        self.since: float | None = None
        self.ours_seen = False

    def saw(self, msg: fiducial_msgs.FiducialTransformArray, stamp: float, ours: bool) -> None:
        """One detection message, at image time ``stamp``; ``ours``: it holds ``marker_id``."""
        if ours:
            self.ours_seen = True
        if self.ours_seen:
            return
        ids = {t.fiducial_id for t in msg.transforms}
        if ids:
            self.others |= ids
            self.images += 1
            if self.since is None:
                self.since = stamp
        # judged on every image, with markers or none: a follower exploring for its marker
        # turns away from the one it saw (the predictive follower never saw it again)
        if (
            self.since is not None
            and stamp - self.since >= OTHERS_ONLY_TIME
            and self.images >= OTHERS_MIN_IMAGES
        ):
            seen = ", ".join(str(i) for i in sorted(self.others))
            self.node._warn_once(
                "others",
                f"following marker_id {self.marker_id}, but for {stamp - self.since:.0f} s the "
                f"camera has seen only marker ids {seen}; is ~marker_id the id the marker "
                "carries?",
            )


#: period of the move_base/clear_costmaps calls (s)
CLEAR_COSTMAPS_PERIOD = 5.0
#: the fixed re-orientation of the ArUco frame: x into the face, z up
MARKER_TO_MARKER = (np.zeros(3), quaternion_from_euler(0.0, math.pi / 2, math.pi / 2))
#: the frame follow_marker broadcasts its goal as
TARGET_FRAME = "target"


@dataclass(frozen=True)
class FollowMarkerParams:
    """follow_marker's private parameters (the original has no defaults: the tutorial's launch)."""

    marker_id: int = param(0, range=(0, None), help="the fiducial_id to follow")
    marker_to_target_pose: dict = param(
        {"x": -0.8, "y": 0.0}, help="the desired robot pose in the re-oriented marker frame"
    )
    exploration: dict = param(
        {"strategy": "rotate", "robot_frame": "base_footprint"},
        help="what to do when the marker is lost (strategy, robot_frame, target_pose)",
    )


@dataclass(frozen=True)
class MarkerToTargetPose:
    x: float = param(-0.8, unit="m", help="offset along the marker's heading (negative: behind)")
    y: float = param(0.0, unit="m", help="offset to the marker's left")


class FollowMarker(Follower, Node):
    """Turns marker observations into move_base goals; explores when the marker is lost."""

    Params = FollowMarkerParams

    def __init__(self, runtime, name: str = "follow_marker", namespace: str = "/", **kw: Any):
        super().__init__(runtime, name, namespace, **kw)
        p: FollowMarkerParams = self.params
        offset = load_params(
            MarkerToTargetPose,
            p.marker_to_target_pose,
            where=f"{self.full_name}/marker_to_target_pose",
            logger=self.get_logger(),
        )
        self.offset = np.array([offset.x, offset.y, 0.0])
        self.exploration = Exploration.create(
            self, p.exploration, where=f"{self.full_name}/exploration"
        )
        self.base_frame = self.frame("base_footprint")
        self.map_frame = "map"
        self.last_update: float = 0.0  # image time of the last update (ros::Time(0) at start)
        self.goals_sent = 0
        self.others_watch = OtherMarkersWatch(self, self.params.marker_id)
        self._patience = TransformPatience()  # tf failures are reported once they last
        self.goal_pub = self.create_publisher(geometry_msgs.PoseStamped, "move_base_simple/goal")
        self.tf_pub = TransformBroadcaster(self)
        _ = self.tf_buffer  # listen to /tf from now on
        self.clear_client = self.create_client(std_srvs.Empty, "move_base/clear_costmaps")
        self.create_subscription(
            fiducial_msgs.FiducialTransformArray, "fiducial_transforms", self.on_fiducials, 1
        )
        self.create_timer(CLEAR_COSTMAPS_PERIOD, self.clear_costmaps)

    def _lookup(self, key: str, target: str, source: str, stamp: Any):
        """``target <- source`` at ``stamp``, or None (warned about once the failure has lasted
        tf's grace period: localization starts a little after the first images)."""
        try:
            found = self.tf_buffer.lookup_arrays(target, source, stamp)
        except TransformError as err:
            if self._patience.missing_too_long(key, self.now()):
                self._warn_once(key, f"cannot place the marker in {target}: {err}")
            return None
        self._patience.found(key)
        return found

    def clear_costmaps(self) -> None:
        """Call move_base/clear_costmaps and ignore the result, as the original does."""
        try:
            self.clear_client.call(std_srvs.Empty.Request())
        except ServiceError as err:
            self._warn_once("clear", f"cannot clear costmaps: {err}")

    def on_fiducials(self, msg: fiducial_msgs.FiducialTransformArray) -> None:
        stamp = msg.header.stamp.to_sec()
        found = next((t for t in msg.transforms if t.fiducial_id == self.params.marker_id), None)
        self.others_watch.saw(msg, stamp, found is not None)
        if found is None:
            if stamp - self.last_update > UPDATE_TIMEOUT:
                self.exploration.start()
            return
        if self.exploration.is_exploring():
            self.exploration.cancel()
            self.last_update = stamp
            return
        tr, q = found.transform.translation, found.transform.rotation
        marker = compose_transforms(
            np.array([tr.x, tr.y, tr.z]), np.array([q.x, q.y, q.z, q.w]), *MARKER_TO_MARKER
        )
        camera = msg.header.frame_id
        base_camera = self._lookup("base", self.base_frame, camera, msg.header.stamp)
        if base_camera is None:
            return
        in_base = compose_transforms(*base_camera, *marker)
        if 0.5 * np.hypot(in_base[0][0], in_base[0][1]) < np.hypot(*self.offset[:2]):
            self.last_update = stamp  # too close: move_base finishes the last goal
            return
        map_camera = self._lookup("map", self.map_frame, camera, msg.header.stamp)
        if map_camera is None:
            return
        in_map = compose_transforms(*map_camera, *marker)
        t, q_t = compose_transforms(*in_map, self.offset, np.array([0.0, 0.0, 0.0, 1.0]))
        t = np.array([t[0], t[1], 0.0])
        q_t = quaternion_from_yaw(yaw_from_quaternion(q_t))
        self.goal_pub.publish(pose_stamped(self.map_frame, msg.header.stamp, t, q_t))
        self.tf_pub.send_transform(
            make_transform_stamped(self.map_frame, TARGET_FRAME, msg.header.stamp, t, q_t)
        )
        self.goals_sent += 1
        self.last_update = stamp
