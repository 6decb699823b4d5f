"""The ``gmapping/slam_gmapping`` node: ROS 1 slam_gmapping's topics, service, tf and parameters.

Interface (names relative to the node's namespace, e.g. ``/lizi1``):

- subscribes ``scan`` (sensor_msgs/LaserScan); the odometry comes from tf
  (``odom_frame -> base_frame`` at each scan's stamp; a scan waits for it, as gmapping's
  ``tf::MessageFilter`` does);
- publishes ``map`` (nav_msgs/OccupancyGrid) and ``map_metadata`` (latched) every
  ``map_update_interval`` of scan time, ``~entropy`` (std_msgs/Float64, latched) and the
  ``map_frame -> odom_frame`` transform every ``transform_publish_period`` (no faster than the
  simulator publishes), dated ``tf_delay`` ahead;
- serves ``dynamic_map`` (nav_msgs/GetMap).

Frames get the robot's ``tf_prefix``, the map frame too (gmapping resolves all three), so two
robots in namespaces map on their own (``lizi1/map``). Bad input is reported naming the topic
and frame: a scan whose beam count changes is dropped with an error, a laser that is not level
is refused, an upside-down one is mirrored with a warning, missing odometry tf is warned about.

With ``peer_frames`` (a fleetsim addition) the beams that end on another robot, found through
tf, are left out of matching and mapping (`fleetsim.slam.peers`); a scan waits briefly for a
peer's tf, and a peer missing from it is warned about once, naming its frame.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fleetsim.errors import ExtrapolationError, FleetsimError, ParameterError, TransformError
from fleetsim.msgs import nav_msgs, sensor_msgs, std_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.map_io import OccupancyMap
from fleetsim.nav.map_server import grid_msg_from_map
from fleetsim.runtime import Node
from fleetsim.tf import (
    MessageFilter,
    TransformBroadcaster,
    make_transform_stamped,
    resolve_frame_once,
)
from fleetsim.tf.quaternions import rotate_vector
from fleetsim.tf.transforms import compose_pose2d, inverse_pose2d

from .errors import SlamError
from .filter import Beams, GmappingFilter
from .params import GmappingParams, gmapping_params
from .peers import PeerLookup, beams_clear_of_peers, peers_in_base

SCAN_QUEUE_SIZE = 5  # gmapping's tf::MessageFilter queue
TF_GRACE = 1.0  # s of sim time before missing odometry or laser tf is reported
DEFAULT_SIM_PERIOD = 0.01  # s: the simulator's publish period when no simulator node is found


class SlamGmapping(Node):
    """slam_gmapping for one robot namespace."""

    Params = GmappingParams

    def __init__(
        self, runtime, name: str = "slam_gmapping", namespace: str = "/", **kw: Any
    ) -> None:
        super().__init__(runtime, name, namespace, **kw)
        p: GmappingParams = self.params
        prefix = self.tf_prefix
        self.base_frame = resolve_frame_once(prefix, p.base_frame)
        self.odom_frame = resolve_frame_once(prefix, p.odom_frame)
        self.map_frame = resolve_frame_once(prefix, p.map_frame)
        self.peer_frames = [str(f).lstrip("/") for f in p.peer_frames]
        if self.base_frame in self.peer_frames:
            raise ParameterError(
                f"{self.full_name}: peer_frames {p.peer_frames} holds the robot's own base "
                f"frame {self.base_frame}; list the other robots' base frames"
            )
        self.peer_beams_dropped = 0  # beams left out as ending on a peer, over the run
        self.filter: GmappingFilter | None = None
        self.map_to_odom = np.zeros(3)
        self.grid_msg: nav_msgs.OccupancyGrid | None = None
        self._last_map_time = -math.inf
        self._beam_count: int | None = None
        self._mirrored = False
        self._scans_seen = 0
        self.scan_topic = self.resolve_name("scan")
        self.map_pub = self.create_publisher(nav_msgs.OccupancyGrid, "map", 1, latch=True)
        self.meta_pub = self.create_publisher(nav_msgs.MapMetaData, "map_metadata", 1, latch=True)
        self.entropy_pub = self.create_publisher(std_msgs.Float64, "~entropy", 1, latch=True)
        self.create_service(nav_msgs.GetMap, "dynamic_map", self.on_dynamic_map)
        self.tf_pub = TransformBroadcaster(self)
        _ = self.tf_buffer  # subscribe the runtime's buffer to /tf now
        # a scan waits on its own robot's odometry edges, not on every /tf message (the laser's
        # static transform, should it come late, is retried with the next odometry)
        self._pending = MessageFilter(
            self.tf_buffer,
            self._process,
            SCAN_QUEUE_SIZE,
            frames=lambda scan: (self.odom_frame, self.base_frame),
        )
        self._scan_sub = self.create_subscription(
            sensor_msgs.LaserScan, "scan", self.on_scan, queue_size=5
        )
        # a laser on base_scan for gmapping's scan had left the map unmade without a word
        self.warn_while_silent(
            self._scan_sub,
            lambda: self._scans_seen > 0,
            "no scan received",
            "no map until one comes (remap 'scan' to the laser's topic)",
        )
        self.tf_period = self._tf_period(p.transform_publish_period)
        if self.tf_period > 0:
            self.create_timer(self.tf_period, self._publish_transform)

    def _load_params(self) -> Any:
        values = self.runtime.params.get(self.full_name, {})
        return gmapping_params(
            values if isinstance(values, dict) else {}, self.full_name, self.get_logger()
        )

    def _tf_period(self, period: float) -> float:
        """``transform_publish_period``, capped at the simulator's publish period."""
        if period <= 0:
            return 0.0
        sim_period = DEFAULT_SIM_PERIOD
        for node in self.runtime.graph.nodes.values():
            value = getattr(getattr(node, "params", None), "update_period", None)
            if type(node).__name__ == "Simulator" and isinstance(value, float):
                sim_period = value
        if period < sim_period:
            self.get_logger().info(
                f"transform_publish_period {period:g} s is faster than the simulator publishes; "
                f"broadcasting map -> odom every {sim_period:g} s"
            )
            return sim_period
        return period

    # ----- scans -----
    def on_scan(self, scan: sensor_msgs.LaserScan) -> None:
        self._scans_seen += 1
        if (self._scans_seen - 1) % self.params.throttle_scans:
            return
        self._pending.add(scan)

    def _process(self, scan: sensor_msgs.LaserScan) -> bool:
        """Run the filter on one scan; False when tf has not caught up with its stamp."""
        stamp = scan.header.stamp.to_sec()
        buf = self.tf_buffer
        try:
            odom = np.array(buf.lookup_pose2d(self.odom_frame, self.base_frame, stamp))
        except ExtrapolationError as err:
            try:
                newest = buf.latest_common_time(self.odom_frame, self.base_frame)
            except TransformError:
                newest = None
            if newest is not None and newest < stamp:
                return False
            self._warn_once("tf_old", f"dropping a scan on {self.scan_topic} older than tf: {err}")
            return True
        except FleetsimError as err:
            if self.now() >= TF_GRACE:
                self._warn_once(
                    "no_odom",
                    f"no odometry for the scans on {self.scan_topic}: cannot look up "
                    f"{self.odom_frame} -> {self.base_frame} ({err}); is the robot's odometry "
                    "tf published (the drive plugin's publishOdomTF)?",
                )
            return True
        try:
            if self.filter is None:
                self._start(scan)
            beams = self._beams(scan)
        except _NoLaserTransform as err:
            if self.now() < TF_GRACE:  # the laser's (static) transform is on its way: wait
                return False
            self._warn_once(f"scan:{err}", str(err))
            return True
        except SlamError as err:
            self._warn_once(f"scan:{err}", str(err))
            return True
        if self.peer_frames:
            found = peers_in_base(
                self.tf_buffer, self.base_frame, self.peer_frames, stamp, self.now(), TF_GRACE
            )
            if found.wait:
                return False
            if found.skip:  # the first moments: a scan from before the peers' first tf
                return True
            beams = self._off_peers(beams, found)
        assert self.filter is not None
        result = self.filter.process(odom, stamp, beams)
        if result.updated:
            self.map_to_odom = compose_pose2d(self.filter.best_pose, inverse_pose2d(odom))
            if (
                self.grid_msg is None
                or stamp - self._last_map_time > self.params.map_update_interval
            ):
                self._last_map_time = stamp
                self._publish_map(scan.header.stamp)
        return True

    def _start(self, scan: sensor_msgs.LaserScan) -> None:
        """Set the filter up from the first scan: laser pose and ranges (gmapping's initMapper)."""
        frame = scan.header.frame_id.lstrip("/") or self.base_frame
        try:
            tf = self.tf_buffer.lookup_transform(self.base_frame, frame, 0.0).transform
        except FleetsimError as err:
            raise _NoLaserTransform(
                f"cannot place the laser of {self.scan_topic}: no transform from "
                f"{self.base_frame} to its frame '{frame}' ({err})"
            ) from None
        q = tf.rotation
        up = rotate_vector((q.x, q.y, q.z, q.w), (0.0, 0.0, 1.0))
        if abs(abs(up[2]) - 1.0) > 1e-3:
            raise SlamError(
                f"the laser frame '{frame}' of {self.scan_topic} is not level (its z axis is "
                f"{up.round(3).tolist()} in {self.base_frame}); slam_gmapping needs a planar laser"
            )
        self._mirrored = up[2] < 0
        if self._mirrored:
            self.get_logger().warning(
                f"the laser frame '{frame}' of {self.scan_topic} is mounted upside down; "
                "mirroring its beams"
            )
        x_axis = rotate_vector((q.x, q.y, q.z, q.w), (1.0, 0.0, 0.0))
        t = tf.translation
        laser = np.array([t.x, t.y, math.atan2(x_axis[1], x_axis[0])])
        p = self.params
        max_range = p.maxRange if p.maxRange is not None else float(scan.range_max) - 0.01
        usable = p.maxUrange if p.maxUrange is not None else max_range
        usable = min(usable, max_range)
        self._beam_count = len(scan.ranges)
        self.filter = GmappingFilter(p, self.rng, laser, max_range, usable)
        self.get_logger().info(
            f"mapping with {p.particles} particles, {self._beam_count} beams, laser '{frame}', "
            f"maxRange {max_range:g} m, maxUrange {usable:g} m"
        )

    def _beams(self, scan: sensor_msgs.LaserScan) -> Beams:
        n = len(scan.ranges)
        if n != self._beam_count:
            raise SlamError(
                f"dropping scans on {self.scan_topic} (frame '{scan.header.frame_id}'): "
                f"{n} beams, but the first scan had {self._beam_count}; gmapping needs every "
                "scan to have the same beam count"
            )
        ranges = np.asarray(scan.ranges, dtype=np.float64).copy()
        ranges[ranges < scan.range_min] = scan.range_max  # as slam_gmapping does
        angles = scan.angle_min + scan.angle_increment * np.arange(n)
        if self._mirrored:
            angles = -angles
        assert self.filter is not None
        keep = np.isfinite(ranges) & (ranges > 0.0) & (ranges <= self.filter.max_range)
        return Beams(ranges[keep], angles[keep])

    def _off_peers(self, beams: Beams, found: PeerLookup) -> Beams:
        """The beams that do not end on a peer found (`fleetsim.slam.peers`)."""
        for frame, why in found.missing.items():
            self._warn_once(
                f"peer:{frame}",
                f"keeping the beams of {self.scan_topic} that may end on the peer {frame}: {why}; "
                "they may map that robot as an obstacle",
            )
        for frame in self.peer_frames:
            if frame not in found.missing:
                self._warned.discard(f"peer:{frame}")  # warn again should it go missing again
        assert self.filter is not None
        p = self.params
        keep = beams_clear_of_peers(
            beams.ranges,
            beams.angles,
            self.filter.laser,
            found.positions,
            p.peer_radius + p.peer_margin,
        )
        dropped = int(len(keep) - np.count_nonzero(keep))
        if not dropped:
            return beams
        self.peer_beams_dropped += dropped
        return Beams(beams.ranges[keep], beams.angles[keep])

    # ----- outputs -----
    def _publish_transform(self) -> None:
        # before the first scan: the identity, as gmapping's publishLoop does (map_to_odom_ starts
        # as the identity, and the first scan puts the map frame on the odometry pose); a peer's
        # slam_gmapping looks this robot up through it (fleetsim.slam.peers)
        x, y, yaw = (float(v) for v in self.map_to_odom)
        delay = self.params.tf_delay if self.params.tf_delay is not None else self.tf_period
        self.tf_pub.send_transform(
            make_transform_stamped(
                self.map_frame,
                self.odom_frame,
                self.now() + delay,
                (x, y, 0.0),
                (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)),
            )
        )

    def _publish_map(self, stamp: Time) -> None:
        assert self.filter is not None
        data, geom = self.filter.occupancy()
        occupancy = OccupancyMap(
            data=data, resolution=float(geom[2]), origin=(geom[0], geom[1], 0.0)
        )
        self.grid_msg = grid_msg_from_map(occupancy, self.map_frame, stamp)
        self.map_pub.publish(self.grid_msg)
        self.meta_pub.publish(self.grid_msg.info)
        entropy = self.filter.entropy()
        if entropy > 0.0:
            self.entropy_pub.publish(std_msgs.Float64(data=entropy))

    def on_dynamic_map(self, req: Any) -> Any:
        if self.grid_msg is None:
            raise SlamError(
                f"{self.full_name}: no map yet (no scan processed on {self.scan_topic})"
            )
        return nav_msgs.GetMap.Response(map=self.grid_msg)


class _NoLaserTransform(SlamError):
    """The laser's frame is not (yet) in tf: scans wait for it for TF_GRACE of sim time."""
