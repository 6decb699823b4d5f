"""The ``amcl`` node: ROS 1 amcl's topics, services, parameters and tf, over `ParticleFilter`.

Interface (names relative to the node's namespace, e.g. ``/lizi1``):

- subscribes ``scan`` (sensor_msgs/LaserScan), ``initialpose``
  (geometry_msgs/PoseWithCovarianceStamped, what a viewer's "2D pose estimate" sends) and,
  with ``use_map_topic``, ``map`` (nav_msgs/OccupancyGrid); otherwise calls ``static_map``
  (retried every second until a map server answers);
- publishes ``amcl_pose`` (PoseWithCovarianceStamped, latched), ``particlecloud`` (PoseArray,
  latched; at most ``gui_publish_rate`` Hz when set) and the ``global_frame_id -> odom_frame_id``
  transform on ``/tf`` dated ``transform_tolerance`` into the future (``tf_broadcast``);
- serves ``global_localization`` and ``request_nomotion_update`` (std_srvs/Empty) and
  ``set_map`` (nav_msgs/SetMap).

Frames: ``odom_frame_id`` and ``base_frame_id`` get the robot's ``tf_prefix`` (a frame already
spelled with it is left alone); ``global_frame_id`` is the one shared map frame and is not
prefixed. Bad input (no map yet, an initial pose off the map, a scan whose frames are not in tf
yet, a map that cannot be used) is logged and skipped; it never stops the run.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fleetsim.errors import ExtrapolationError, FleetsimError, TransformError
from fleetsim.msgs import geometry_msgs, nav_msgs, sensor_msgs, std_msgs, std_srvs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.runtime import Node
from fleetsim.tf import (
    MessageFilter,
    TransformBroadcaster,
    make_transform_stamped,
    resolve_frame_once,
)
from fleetsim.tf.names import normalize_frame
from fleetsim.tf.patience import TransformPatience
from fleetsim.tf.transforms import compose_pose2d, inverse_pose2d

from .estimate import covariance_3x3
from .filter import ParticleFilter
from .grid_map import AmclMap, LocalizationError
from .params import AmclParams
from .scan import beams_from_scan

MAP_RETRY_PERIOD = 1.0  # s of sim time between static_map attempts
SCAN_QUEUE_SIZE = 100  # scans waiting for their odometry in tf (amcl's laser_scan_filter_)

#: s of sim time before a missing map service is reported (nodes start in any order)
MAP_GRACE = 1.0


def _yaw_of(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def _quaternion(yaw: float) -> geometry_msgs.Quaternion:
    return geometry_msgs.Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


class Amcl(Node):
    """amcl for one robot namespace (a drop-in for ``fake_localization`` in a launch file)."""

    Params = AmclParams

    def __init__(self, runtime, name: str = "amcl", namespace: str = "/", **kw: Any) -> None:
        super().__init__(runtime, name, namespace, **kw)
        p: AmclParams = self.params
        self.odom_frame = resolve_frame_once(self.tf_prefix, p.odom_frame_id)
        self.base_frame = resolve_frame_once(self.tf_prefix, p.base_frame_id)
        self.global_frame = normalize_frame(p.global_frame_id)
        self.filter = ParticleFilter(p, self.rng, None)
        self.map_received = False
        self._tf_patience = TransformPatience()
        self._pending_initial_pose: geometry_msgs.PoseWithCovarianceStamped | None = None
        self._laser_poses: dict[str, np.ndarray] = {}
        self._map_to_odom: np.ndarray | None = None
        self._last_cloud_time = -math.inf
        self.pose_pub = self.create_publisher(
            geometry_msgs.PoseWithCovarianceStamped, "amcl_pose", queue_size=2, latch=True
        )
        self.cloud_pub = self.create_publisher(
            geometry_msgs.PoseArray, "particlecloud", queue_size=2, latch=True
        )
        self.tf_pub = TransformBroadcaster(self) if p.tf_broadcast else None
        _ = self.tf_buffer  # subscribe the runtime's buffer to /tf now, not at the first scan
        self._pending_scans = MessageFilter(
            self.tf_buffer,
            self._process_scan,
            SCAN_QUEUE_SIZE,
            frames=lambda scan: (self.odom_frame, self.base_frame),
        )
        self._scan_sub = self.create_subscription(
            sensor_msgs.LaserScan, "scan", self.on_scan, queue_size=1
        )
        self._scans_heard = False
        # amcl on the wrong topic publishes no map -> odom, and the costmaps then report a
        # missing 'map' frame, which blamed tf, not amcl
        self.warn_while_silent(
            self._scan_sub,
            lambda: self._scans_heard,
            "no scan received",
            "no pose estimate and no map -> odom transform until one comes (remap 'scan' to "
            "the laser's topic)",
        )
        self.create_subscription(
            geometry_msgs.PoseWithCovarianceStamped, "initialpose", self.on_initial_pose, 2
        )
        self.create_service(std_srvs.Empty, "global_localization", self.on_global_localization)
        self.create_service(std_srvs.Empty, "request_nomotion_update", self.on_nomotion_update)
        self.create_service(nav_msgs.SetMap, "set_map", self.on_set_map)
        if p.use_map_topic:
            self.create_subscription(nav_msgs.OccupancyGrid, "map", self.on_map, queue_size=1)
        else:
            self._map_client = self.create_client(nav_msgs.GetMap, "static_map")
            self._map_timer = self.create_timer(MAP_RETRY_PERIOD, self._request_map)
            self._request_map()
        if p.save_pose_rate:
            self.create_timer(1.0 / p.save_pose_rate, self._save_pose)

    # ----- logging helpers -----
    # ----- map -----
    def _request_map(self) -> None:
        if self.map_received:
            return
        client = self._map_client
        if not client.service_is_ready():
            if self.now() >= MAP_GRACE:  # map_server may come up a moment later
                self._warn_once("static_map", self._no_map_service_text(client.name))
            return
        try:
            resp = client.call(nav_msgs.GetMap.Request())
        except FleetsimError as err:
            self._warn_once("static_map_call", f"static_map call failed: {err}")
            return
        self.on_map(resp.map)
        if self.map_received:
            self._map_timer.cancel()

    def _no_map_service_text(self, name: str) -> str:
        """What to do when ``static_map`` is not there: name a map service elsewhere in the
        graph (map_server's global ``/static_map`` for an amcl in a robot's namespace)."""
        base = name.rsplit("/", 1)[-1]
        others = sorted(s for s in self.runtime.graph.services if s.rsplit("/", 1)[-1] == base)
        if others:
            return (
                f"waiting for the map: no service {name}, but {others[0]} is there; add "
                f'<remap from="{base}" to="{others[0]}"/> to the amcl node, or set '
                "use_map_topic with the map topic remapped"
            )
        return f"waiting for the map: no service {name}; start map_server, or set use_map_topic"

    def on_map(self, msg: nav_msgs.OccupancyGrid) -> None:
        """Use a new map (amcl's handleMapMessage); ``first_map_only`` keeps the first."""
        if self.map_received and self.params.first_map_only:
            return
        grid = self._grid_from(msg)
        if grid is None:
            return
        self._use_map(grid)
        if self._pending_initial_pose is not None:
            pending, self._pending_initial_pose = self._pending_initial_pose, None
            self.on_initial_pose(pending)

    def _grid_from(self, msg: nav_msgs.OccupancyGrid) -> AmclMap | None:
        try:
            return AmclMap.shared_from_grid_msg(msg, source=f"{self.full_name} map")
        except LocalizationError as err:
            self.get_logger().error(f"ignoring map: {err}")
            return None

    def _use_map(self, grid: AmclMap) -> None:
        """Switch to ``grid``; particles around ``~initial_pose_*`` as now in the param tree."""
        self.map_received = True
        self.get_logger().info(
            f"received a {grid.width} x {grid.height} map @ {grid.resolution:.3f} m/cell"
        )
        self.filter.grid = grid
        self._map_to_odom = None
        p = self.params

        def saved(key: str) -> float:  # save_pose may have updated these
            value = self.get_param(f"~{key}", getattr(p, key))
            return float(value) if isinstance(value, int | float) else float(getattr(p, key))

        mean = np.array([saved("initial_pose_x"), saved("initial_pose_y"), saved("initial_pose_a")])
        cov = np.diag([saved("initial_cov_xx"), saved("initial_cov_yy"), saved("initial_cov_aa")])
        try:
            self.filter.set_initial_pose(mean, cov)
        except LocalizationError as err:
            self.get_logger().error(f"{err}; spreading particles over the free space instead")
            self.filter.global_localization()

    def on_set_map(self, req: Any) -> Any:
        grid = self._grid_from(req.map)
        if grid is None:
            return nav_msgs.SetMap.Response(success=False)
        self._use_map(grid)
        self.on_initial_pose(req.initial_pose)
        return nav_msgs.SetMap.Response(success=True)

    # ----- initial pose and services -----
    def on_initial_pose(self, msg: geometry_msgs.PoseWithCovarianceStamped) -> None:
        frame = normalize_frame(msg.header.frame_id)
        if frame and frame != self.global_frame:
            self.get_logger().warning(
                f"ignoring initial pose in frame '{frame}'; initial poses must be in the global "
                f"frame '{self.global_frame}'"
            )
            return
        if self.filter.grid is None:
            self._pending_initial_pose = msg  # applied when the map arrives
            return
        pose = msg.pose.pose
        mean = np.array([pose.position.x, pose.position.y, _yaw_of(pose.orientation)])
        mean = self._motion_since(msg.header.stamp, mean)
        try:
            self.filter.set_initial_pose(mean, covariance_3x3(msg.pose.covariance))
        except LocalizationError as err:
            self.get_logger().error(f"ignoring initial pose: {err}")
            return
        self.get_logger().info(
            f"setting pose ({self.now():.3f}): {mean[0]:.3f} {mean[1]:.3f} {mean[2]:.3f}"
        )
        self._map_to_odom = None

    def _motion_since(self, stamp: Any, mean: np.ndarray) -> np.ndarray:
        """Apply the odometry motion between ``stamp`` and now to a pose (as amcl does)."""
        t = stamp.to_sec() if hasattr(stamp, "to_sec") else float(stamp)
        if t <= 0.0:
            return mean
        buf = self.tf_buffer
        try:
            then = np.array(buf.lookup_pose2d(self.odom_frame, self.base_frame, t))
            now = np.array(buf.lookup_pose2d(self.odom_frame, self.base_frame, 0.0))
        except FleetsimError:
            return mean
        return compose_pose2d(mean, compose_pose2d(inverse_pose2d(then), now))

    def on_global_localization(self, req: Any) -> Any:
        try:
            self.filter.global_localization()
        except LocalizationError as err:
            self.get_logger().error(f"global_localization: {err}")
        else:
            self.get_logger().info(
                f"initializing with uniform distribution ({self.filter.particle_count} particles)"
            )
            self._map_to_odom = None
        return std_srvs.Empty.Response()

    def on_nomotion_update(self, req: Any) -> Any:
        self.filter.request_nomotion_update()
        return std_srvs.Empty.Response()

    def _save_pose(self) -> None:
        """Store the estimate in ``~initial_pose_*`` / ``~initial_cov_*`` (amcl's save_pose)."""
        if self._map_to_odom is None:
            return
        est = self.filter.estimate
        cov = est.covariance
        for key, value in (
            ("initial_pose_x", est.pose[0]),
            ("initial_pose_y", est.pose[1]),
            ("initial_pose_a", est.pose[2]),
            ("initial_cov_xx", cov[0, 0]),
            ("initial_cov_yy", cov[1, 1]),
            ("initial_cov_aa", cov[5, 5]),
        ):
            self.set_param(f"~{key}", float(value))

    # ----- the scan callback -----
    def on_scan(self, scan: sensor_msgs.LaserScan) -> None:
        """Queue the scan and process every queued one whose odometry is in tf.

        As ROS amcl's tf ``MessageFilter``: a scan whose ``odom -> base`` transform at its stamp
        has not arrived yet (the simulator publishes a scan before the tf of the same step) waits
        for it; the next tf message retries the queue.
        """
        self._scans_heard = True
        if self.filter.grid is None:
            self._warn_once("no_map", "received a scan but no map yet; waiting for the map")
            return
        self._pending_scans.add(scan)

    def _process_scan(self, scan: sensor_msgs.LaserScan) -> bool:
        """Run the filter on one scan; False when tf cannot answer for its stamp yet."""
        stamp = scan.header.stamp.to_sec()
        laser_frame = normalize_frame(scan.header.frame_id) or self.base_frame
        buf = self.tf_buffer
        try:
            if laser_frame not in self._laser_poses:
                self._laser_poses[laser_frame] = np.array(
                    buf.lookup_pose2d(self.base_frame, laser_frame, 0.0)
                )
            odom_pose = np.array(buf.lookup_pose2d(self.odom_frame, self.base_frame, stamp))
        except ExtrapolationError as err:
            try:
                newest = buf.latest_common_time(self.odom_frame, self.base_frame)
            except TransformError:
                newest = None
            if newest is not None and newest < stamp:
                return False  # tf has not caught up with this scan yet: wait for it
            self._warn_once("tf_old", f"dropping a scan older than tf's history: {err}")
            return True
        except FleetsimError as err:
            # a frame not there yet in the first moments (the laser's static transform follows
            # its first period) is waited for; reported once it stays missing (tf.patience)
            if self._tf_patience.missing_too_long(laser_frame, self.now()):
                self._warn_once(f"tf:{laser_frame}", f"skipping scans until tf is available: {err}")
            else:
                self.get_logger().debug(f"scan skipped until tf is available: {err}")
            return True
        self._tf_patience.found(laser_frame)
        if self.filter.grid is None:
            return True
        if not self.filter.needs_update(odom_pose):  # not moved enough: the scan is not read
            self._send_map_to_odom_if_known(stamp)
            return True
        p = self.params
        try:
            beams = beams_from_scan(
                scan.ranges,
                scan.angle_min,
                scan.angle_increment,
                scan.range_min,
                scan.range_max,
                p.laser_max_beams,
                p.laser_model_type,
                p.laser_min_range,
                p.laser_max_range,
            )
        except LocalizationError as err:
            self._warn_once("scan", f"skipping scan: {err}")
            return True
        self.filter.laser_pose = self._laser_poses[laser_frame]
        result = self.filter.update(odom_pose, beams)
        if result.updated:
            self._publish_cloud(scan.header.stamp)
        if result.estimate_changed:
            self._publish_pose(scan.header.stamp, odom_pose)
        self._send_map_to_odom_if_known(stamp)
        return True

    def _send_map_to_odom_if_known(self, stamp: float) -> None:
        if self._map_to_odom is not None and self.tf_pub is not None:
            self._send_map_to_odom(stamp)

    # ----- outputs -----
    def _publish_cloud(self, stamp: Time) -> None:
        rate = self.params.gui_publish_rate
        now = self.now()
        if rate is not None and rate > 0 and now - self._last_cloud_time < 1.0 / rate:
            return
        self._last_cloud_time = now
        # Built only for a reader (thousands of Pose messages): with nobody subscribed the
        # latched publisher keeps the builder, so a later subscriber still gets this cloud.
        parts = self.filter.particles.copy()
        frame = self.global_frame

        def make() -> geometry_msgs.PoseArray:
            half = 0.5 * parts[:, 2]
            Pose, Point, Quaternion = (
                geometry_msgs.Pose,
                geometry_msgs.Point,
                geometry_msgs.Quaternion,
            )
            poses = [
                Pose(
                    position=Point(x=x, y=y, z=0.0),
                    orientation=Quaternion(x=0.0, y=0.0, z=z, w=w),
                )
                for x, y, z, w in zip(
                    parts[:, 0].tolist(),
                    parts[:, 1].tolist(),
                    np.sin(half).tolist(),
                    np.cos(half).tolist(),
                )
            ]
            header = std_msgs.Header(stamp=stamp, frame_id=frame)
            return geometry_msgs.PoseArray(header=header, poses=poses)

        self.cloud_pub.publish_lazily(make)

    def _publish_pose(self, stamp: Time, odom_pose: np.ndarray) -> None:
        est = self.filter.estimate
        x, y, yaw = (float(v) for v in est.pose)
        msg = geometry_msgs.PoseWithCovarianceStamped(
            header=std_msgs.Header(stamp=stamp, frame_id=self.global_frame),
            pose=geometry_msgs.PoseWithCovariance(
                pose=geometry_msgs.Pose(
                    position=geometry_msgs.Point(x=x, y=y, z=0.0), orientation=_quaternion(yaw)
                ),
                covariance=np.asarray(est.covariance, dtype=np.float64).ravel(),
            ),
        )
        self.pose_pub.publish(msg)
        # map -> odom = map -> base (estimate) (+) inverse(odom -> base)
        self._map_to_odom = compose_pose2d(est.pose, inverse_pose2d(odom_pose))

    def _send_map_to_odom(self, stamp: float) -> None:
        x, y, yaw = self._map_to_odom
        q = _quaternion(float(yaw))
        self.tf_pub.send_transform(
            make_transform_stamped(
                self.global_frame,
                self.odom_frame,
                stamp + self.params.transform_tolerance,
                (float(x), float(y), 0.0),
                (q.x, q.y, q.z, q.w),
            )
        )
