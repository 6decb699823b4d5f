"""``predictive_follower``: follow a marker while keeping it in the camera's view (issue 19).

The tutorial's follow_marker hands each sighting to move_base as a goal and lets it drive
freely, so the camera often turns away and the marker is lost. This node plans with the
camera in mind instead, as its own node publishing ``cmd_vel`` with move_base's safety (its own
rolling ``~local_costmap`` from the laser, the robot's footprint, velocity and acceleration
limits):

1. each ``fiducial_transforms`` sighting of ``~marker_id`` is placed in ``map`` (the marker's
   re-oriented frame, as follow_marker does) and folded into a CTRV Kalman filter
   (`fleetsim.apps.target_tracker`); its estimate goes out on ``~target_pose``
   (PoseWithCovarianceStamped) and its prediction over the horizon on ``~predicted_path``;
2. every control cycle a sampling MPC (`fleetsim.apps.follower_mpc`) rolls every velocity sample
   out over the local costmap and scores it against the predicted target: inside the field of
   view and detection range (strong cost), ``follow_distance`` behind it, clear of walls and
   of the target, smooth; the best sample's first command goes out on ``cmd_vel`` and its
   rollout on ``~local_plan``;
3. when the marker is not seen, the MPC keeps chasing the prediction (up to ``max_lead`` s past
   the last sighting) for ``search_predicted_for`` s: where the prediction says it went; then
   for ``search_last_seen_for`` s it looks at where it was last seen; then it falls back to the
   tutorial's exploration (``~exploration``, through the move_base action, as follow_marker's),
   which the next sighting cancels.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import numpy as np

from fleetsim.apps.exploration import Exploration, Follower, pose_stamped
from fleetsim.apps.follow_marker import MARKER_TO_MARKER, OtherMarkersWatch
from fleetsim.apps.follower_mpc import costs_without_target, rollout_costs, velocity_samples
from fleetsim.apps.predictive_follower_params import PredictiveFollowerParams
from fleetsim.apps.target_tracker import TargetTracker, TrackerParams
from fleetsim.errors import TransformError
from fleetsim.msgs import fiducial_msgs, geometry_msgs, nav_msgs, std_msgs
from fleetsim.nav.controllers.rollout import new_velocity
from fleetsim.nav.costmap.costmap_ros import Costmap2DROS
from fleetsim.nav.costmap.footprint import outline_points
from fleetsim.runtime import Node
from fleetsim.runtime.params import load_params
from fleetsim.tf.patience import TransformPatience
from fleetsim.tf.quaternions import quaternion_from_yaw, yaw_from_quaternion
from fleetsim.tf.transforms import compose_transforms

TRACK, SEARCH_PREDICTED, SEARCH_LAST_SEEN, EXPLORE = (
    "track",
    "search_predicted",
    "search_last_seen",
    "explore",
)


class PredictiveFollower(Follower, Node):
    """Keeps a marker in view: tracker + sampling MPC + search. State: the tracker, the mode,
    the last command."""

    Params = PredictiveFollowerParams

    def __init__(self, runtime, name: str = "predictive_follower", namespace: str = "/", **kw):
        super().__init__(runtime, name, namespace, **kw)
        p: PredictiveFollowerParams = self.params
        where = self.full_name
        self.tracker = TargetTracker(
            load_params(
                TrackerParams, p.tracker, where=f"{where}/tracker", logger=self.get_logger()
            )
        )
        self.exploration = Exploration.create(self, p.exploration, where=f"{where}/exploration")
        self.costmap = Costmap2DROS(self, "local_costmap")
        self.map_frame = "map"
        self.base_frame = self.frame(p.robot_frame)
        self.camera_frame = self.frame(p.camera_frame)
        self.steps = max(1, round(p.horizon / p.time_step))
        self.samples = velocity_samples(
            p.min_vel_x, p.max_vel_x, p.max_vel_theta, p.vx_samples, p.vtheta_samples
        )
        self.geometry = np.array(
            [
                p.camera_hfov / 2,
                p.fov_margin,
                p.detection_range,
                p.min_range,
                p.follow_distance,
                p.min_gap,
                p.face_angle,
            ]
        )
        self.weights = np.array(
            [
                p.fov_weight,
                p.out_of_view_cost,
                p.follow_weight,
                p.obstacle_weight,
                p.smooth_weight,
                p.face_weight,
                p.uncertainty_scale,
            ]
        )
        self.accel = np.array([p.acc_lim_x, p.acc_lim_theta])
        self._outline: tuple[Any, np.ndarray] | None = None
        self.camera_x: float | None = None
        self.velocity = np.zeros(2)
        self.command = np.zeros(2)
        self.mode = TRACK
        self.started = self.now()
        self.sightings = 0
        self.trail: deque[tuple[float, float, float]] = deque()  # stamp, x, y in map
        self.infeasible_cycles = 0
        self._patience = TransformPatience()
        self.others_watch = OtherMarkersWatch(self, self.params.marker_id)
        self.cmd_pub = self.create_publisher(geometry_msgs.Twist, "cmd_vel", 1)
        self.pose_pub = self.create_publisher(
            geometry_msgs.PoseWithCovarianceStamped, "~target_pose", 1
        )
        self.path_pub = self.create_publisher(nav_msgs.Path, "~predicted_path", 1)
        self.plan_pub = self.create_publisher(nav_msgs.Path, "~local_plan", 1)
        self.create_subscription(nav_msgs.Odometry, "odom", self.on_odom, 1)
        self.create_subscription(
            fiducial_msgs.FiducialTransformArray, "fiducial_transforms", self.on_fiducials, 1
        )
        self.create_timer(1.0 / p.controller_frequency, self.control_cycle)

    # -- inputs ----------------------------------------------------------------------------------
    def on_odom(self, msg: nav_msgs.Odometry) -> None:
        t = msg.twist.twist
        self.velocity = np.array([t.linear.x, t.angular.z])

    def on_fiducials(self, msg: fiducial_msgs.FiducialTransformArray) -> None:
        found = next((t for t in msg.transforms if t.fiducial_id == self.params.marker_id), None)
        self.others_watch.saw(msg, msg.header.stamp.to_sec(), found is not None)
        if found is None:
            return
        tr, q = found.transform.translation, found.transform.rotation
        tvec = np.array([tr.x, tr.y, tr.z])
        marker = compose_transforms(tvec, np.array([q.x, q.y, q.z, q.w]), *MARKER_TO_MARKER)
        try:
            map_camera = self.tf_buffer.lookup_arrays(
                self.map_frame, msg.header.frame_id, msg.header.stamp
            )
        except TransformError as err:
            if self._patience.missing_too_long("map", self.now()):
                self._warn("map", f"cannot place the marker in {self.map_frame}: {err}")
            return
        self._patience.found("map")
        t, q_m = compose_transforms(*map_camera, *marker)
        fix = np.array([t[0], t[1], yaw_from_quaternion(q_m)])
        stamp = msg.header.stamp.to_sec()
        if self.tracker.update(stamp, fix, distance=float(np.linalg.norm(tvec))):
            self.sightings += 1
            x, y = self.tracker.x[:2]
            if not self.trail or math.hypot(x - self.trail[-1][1], y - self.trail[-1][2]) > 0.05:
                self.trail.append((stamp, float(x), float(y)))
            while self.trail and self.trail[0][0] < stamp - self.params.trail_time:
                self.trail.popleft()
            if self.exploration.is_exploring():
                self.exploration.cancel()

    # -- the control loop ------------------------------------------------------------------------
    def _mode(self, now: float) -> str:
        p = self.params
        if self.tracker.last_fix is None:
            return EXPLORE if now - self.started > p.search_predicted_for else SEARCH_LAST_SEEN
        since = now - self.tracker.last_fix[0]
        if since <= p.search_predicted_for:
            return TRACK
        if since <= p.search_predicted_for + p.search_last_seen_for:
            return SEARCH_LAST_SEEN
        return EXPLORE

    def _targets_in_map(self, now: float) -> tuple[np.ndarray, np.ndarray]:
        """The target's predicted (x, y, heading) over the horizon and their sd, in map."""
        p = self.params
        if self.mode == TRACK:
            start = min(now, self.tracker.last_fix[0] + p.max_lead)
            means, covs = self.tracker.predicted_states(start, p.time_step, self.steps)
            if now > start:  # searching: the prediction stops at max_lead past the sighting
                means[:] = means[0]
            sd = np.sqrt(np.trace(covs, axis1=1, axis2=2))
            return means[:, :3], sd
        fix = self.tracker.last_fix[1]
        sd = math.sqrt(float(np.trace(self.tracker.cov[:2, :2])))
        return np.tile(fix, (self.steps, 1)), np.full(self.steps, sd)

    def _outline_points(self) -> np.ndarray:
        fp = self.costmap.footprint
        if self._outline is None or self._outline[0] is not fp:
            res = self.costmap.costmap.resolution
            self._outline = (fp, outline_points(np.asarray(fp, float), res))
        return self._outline[1]

    def _camera_offset(self) -> float | None:
        if self.camera_x is None:
            try:
                t, _ = self.tf_buffer.lookup_arrays(self.base_frame, self.camera_frame, 0.0)
            except TransformError as err:
                self._warn("camera", f"no camera pose on the robot yet: {err}")
                return None
            self.camera_x = float(t[0])
        return self.camera_x

    def _costs_without_target(self, cm, ox: float, oy: float, oth: float) -> np.ndarray:
        """The local costmap less the target's own marks along its track (see
        `costs_without_target`), the track moved from map into the costmap's frame."""
        xy = np.asarray([*((x, y) for _, x, y in self.trail), tuple(self.tracker.x[:2])], float)
        c, s = math.cos(oth), math.sin(oth)
        track = np.column_stack(
            [ox + c * xy[:, 0] - s * xy[:, 1], oy + s * xy[:, 0] + c * xy[:, 1]]
        )
        return costs_without_target(
            cm.costs, cm.origin_x, cm.origin_y, cm.resolution, track, self.params.target_radius
        )

    def publish_command(self, v: float, w: float) -> None:
        self.command = np.array([v, w])
        self.cmd_pub.publish(
            geometry_msgs.Twist(
                linear=geometry_msgs.Vector3(x=float(v)), angular=geometry_msgs.Vector3(z=float(w))
            )
        )

    def control_cycle(self) -> None:
        now = self.now()
        mode = self._mode(now)
        if mode == EXPLORE:
            if self.mode != EXPLORE:
                self.publish_command(0.0, 0.0)  # hand over to move_base
                self.get_logger().info("marker lost: exploring")
            self.mode = mode
            self.exploration.start()
            return
        if self.exploration.is_exploring():
            self.mode = EXPLORE
            return  # cancelled on a sighting; wait until move_base has let go
        self.mode = mode
        if self.tracker.last_fix is None or not self.costmap.initialized:
            return
        pose = self.costmap.robot_pose()
        camera_x = self._camera_offset()
        if pose is None or camera_x is None:
            return
        try:
            ox, oy, oth = self.tf_buffer.lookup_pose2d(self.costmap.global_frame, self.map_frame)
        except TransformError as err:
            self._warn("odom", f"cannot move the prediction into the local costmap: {err}")
            return
        targets_map, sd = self._targets_in_map(now)
        self.publish_prediction(targets_map)
        c, s = math.cos(oth), math.sin(oth)
        targets = np.column_stack(
            [
                ox + c * targets_map[:, 0] - s * targets_map[:, 1],
                oy + s * targets_map[:, 0] + c * targets_map[:, 1],
                targets_map[:, 2] + oth,
            ]
        )
        cm = self.costmap.costmap
        p = self.params
        costs, poses = rollout_costs(
            self._costs_without_target(cm, ox, oy, oth),
            cm.origin_x,
            cm.origin_y,
            cm.resolution,
            self._outline_points(),
            np.array(pose, float),
            self.velocity,
            self.samples,
            self.accel,
            p.time_step,
            np.ascontiguousarray(targets),
            np.ascontiguousarray(sd),
            camera_x,
            self.geometry,
            self.weights,
            self.command,
        )
        best = int(np.argmin(costs))
        if not np.isfinite(costs[best]):
            self.infeasible_cycles += 1
            self._warn("stuck", "every velocity sample collides: stopping")
            self.publish_command(0.0, 0.0)
            return
        dt = 1.0 / p.controller_frequency
        v = new_velocity(self.samples[best, 0], self.velocity[0], p.acc_lim_x, dt)
        w = new_velocity(self.samples[best, 1], self.velocity[1], p.acc_lim_theta, dt)
        self.publish_command(v, w)
        self.publish_plan(poses[best])

    # -- outputs ---------------------------------------------------------------------------------
    def publish_prediction(self, targets_map: np.ndarray) -> None:
        stamp = self.now_msg()
        x, cov = self.tracker.x, self.tracker.cov
        c6 = np.zeros((6, 6))
        c6[:2, :2] = cov[:2, :2]
        c6[5, 5] = cov[2, 2]
        c6[:2, 5] = cov[:2, 2]
        c6[5, :2] = cov[2, :2]
        self.pose_pub.publish(
            geometry_msgs.PoseWithCovarianceStamped(
                header=std_msgs.Header(stamp=stamp, frame_id=self.map_frame),
                pose=geometry_msgs.PoseWithCovariance(
                    pose=pose_stamped(
                        self.map_frame,
                        stamp,
                        np.array([x[0], x[1], 0.0]),
                        quaternion_from_yaw(float(x[2])),
                    ).pose,
                    covariance=c6.reshape(-1),
                ),
            )
        )
        self.path_pub.publish(self._path(self.map_frame, targets_map))

    def publish_plan(self, poses: np.ndarray) -> None:
        self.plan_pub.publish(self._path(self.costmap.global_frame, poses))

    def _path(self, frame: str, rows: np.ndarray) -> Any:
        stamp = self.now_msg()
        return nav_msgs.Path(
            header=std_msgs.Header(stamp=stamp, frame_id=frame),
            poses=[
                pose_stamped(
                    frame, stamp, np.array([r[0], r[1], 0.0]), quaternion_from_yaw(float(r[2]))
                )
                for r in rows
            ],
        )

    def destroy(self) -> None:
        self.costmap.destroy()
        super().destroy()
