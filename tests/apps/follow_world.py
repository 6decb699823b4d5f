"""A kinematic world for follow_marker tests, no simulator: a follower whose tf is published
(map -> odom -> base_footprint -> camera_rgb_optical_frame as the waffle's), a fake move_base
(action ``/move_base`` and ``move_base_simple/goal``, reached at 0.5 m/s and 1 rad/s,
``move_base/clear_costmaps`` counted) and a camera that reports a marker whose map pose the test
sets (None: not seen) as aruco_detect would, on ``fiducial_transforms`` at 10 Hz."""

from __future__ import annotations

import math

import numpy as np

from fleetsim.msgs import fiducial_msgs, geometry_msgs, move_base_msgs, std_msgs, std_srvs
from fleetsim.runtime import Node
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster, make_transform_stamped
from fleetsim.tf.quaternions import (
    quaternion_from_euler,
    quaternion_from_matrix,
    quaternion_from_yaw,
    yaw_from_quaternion,
)
from fleetsim.tf.transforms import compose_transforms, inverse_transform

CAMERA = "camera_rgb_optical_frame"
#: waffle: base_footprint -> camera_rgb_optical_frame
CAMERA_MOUNT = (
    np.array([0.069, -0.047, 0.117]),
    quaternion_from_euler(-math.pi / 2, 0, -math.pi / 2),
)


def marker_rotation(heading: float) -> np.ndarray:
    """Quaternion of an ArUco frame on the back of a robot heading ``heading`` (x right as seen
    from behind, y up, z out of the face, i.e. backwards)."""
    f = np.array([math.cos(heading), math.sin(heading), 0.0])
    up = np.array([0.0, 0.0, 1.0])
    z = -f
    x = np.cross(up, z)
    return quaternion_from_matrix(np.column_stack([x, up, z]))


class FollowWorld(Node):
    def __init__(self, runtime, start=(0.0, 0.0, 0.0), action="/move_base"):
        super().__init__(runtime, "follow_world")
        self.x, self.y, self.yaw = start
        self.marker: tuple[float, float, float] | None = None  # x, y, heading in map
        self.simple_goals: list[tuple[float, float, float]] = []
        self.action_goals: list[tuple[float, float, float]] = []
        self.clears: list[float] = []
        self.target: tuple[float, float, float] | None = None
        self.tf = TransformBroadcaster(self)
        StaticTransformBroadcaster(self).send_transform(
            make_transform_stamped("base_footprint", CAMERA, self.now_msg(), *CAMERA_MOUNT)
        )
        self.server = self.create_action_server(
            move_base_msgs.MoveBase, action, goal_callback=self.on_action_goal
        )
        self.create_subscription(
            geometry_msgs.PoseStamped, "/move_base_simple/goal", self.on_simple_goal, 10
        )
        self.create_service(std_srvs.Empty, "/move_base/clear_costmaps", self.on_clear)
        self.fid_pub = self.create_publisher(
            fiducial_msgs.FiducialTransformArray, "/fiducial_transforms", 1
        )
        self.publish_tf()
        self.create_timer(0.05, self.step)
        self.create_timer(0.1, self.camera)

    @staticmethod
    def _pose(msg) -> tuple[float, float, float]:
        p, q = msg.pose.position, msg.pose.orientation
        return p.x, p.y, yaw_from_quaternion([q.x, q.y, q.z, q.w])

    def on_simple_goal(self, msg) -> None:
        self.simple_goals.append(self._pose(msg))
        if self.server.is_active():
            self.server.set_preempted(text="preempted by a simple goal")
        self.target = self._pose(msg)

    def on_action_goal(self) -> None:
        goal = self.server.accept_new_goal()
        self.action_goals.append(self._pose(goal.target_pose))
        self.target = self._pose(goal.target_pose)

    def on_clear(self, req):
        self.clears.append(self.now())
        return std_srvs.Empty.Response()

    def publish_tf(self) -> None:
        stamp = self.now_msg()
        self.tf.send_transform(
            [
                make_transform_stamped("map", "odom", stamp),
                make_transform_stamped(
                    "odom", "base_footprint", stamp, (self.x, self.y, 0.0),
                    quaternion_from_yaw(self.yaw),
                ),
            ]
        )  # fmt: skip

    def step(self) -> None:
        s = self.server
        if s.is_active() and s.is_preempt_requested() and not s.is_new_goal_available():
            s.set_preempted(text="canceled")
            self.target = None
        if self.target is not None:
            gx, gy, gyaw = self.target
            d = math.hypot(gx - self.x, gy - self.y)
            v = min(d, 0.5 * 0.05)
            if d > 1e-9:
                self.x += (gx - self.x) / d * v
                self.y += (gy - self.y) / d * v
            err = math.remainder(gyaw - self.yaw, math.tau)
            self.yaw += max(-0.05, min(0.05, err))
            if d < 1e-6 and abs(math.remainder(gyaw - self.yaw, math.tau)) < 1e-6:
                self.target = None
                if s.is_active():
                    s.set_succeeded(text="goal reached")
        self.publish_tf()

    def marker_in_camera(self) -> tuple[np.ndarray, np.ndarray]:
        mx, my, mh = self.marker
        t_map_base = (np.array([self.x, self.y, 0.0]), quaternion_from_yaw(self.yaw))
        t_map_cam = compose_transforms(*t_map_base, *CAMERA_MOUNT)
        return compose_transforms(
            *inverse_transform(*t_map_cam), np.array([mx, my, 0.3]), marker_rotation(mh)
        )

    def camera(self) -> None:
        msg = fiducial_msgs.FiducialTransformArray(
            header=std_msgs.Header(stamp=self.now_msg(), frame_id=CAMERA)
        )
        if self.marker is not None:
            t, q = self.marker_in_camera()
            msg.transforms.append(
                fiducial_msgs.FiducialTransform(
                    fiducial_id=0,
                    transform=geometry_msgs.Transform(
                        translation=geometry_msgs.Vector3(*map(float, t)),
                        rotation=geometry_msgs.Quaternion(*map(float, q)),
                    ),
                )
            )
        self.fid_pub.publish(msg)
