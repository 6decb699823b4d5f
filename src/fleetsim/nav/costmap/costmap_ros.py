"""Costmap2DROS: a `LayeredCostmap` wired to topics and tf inside a node (costmap_2d's wrapper).

move_base creates two, ``global_costmap`` and ``local_costmap``; each reads its parameters from
``~<name>/`` (both the plugins form and the pre-Hydro form, see `LayeredCostmap.from_params`)
and then, as costmap_2d does:

* each static layer subscribes to its ``map_topic`` (default ``map``) resolved in the *node's*
  namespace, as StaticLayer's global node handle does: ``/lizi1/map`` for a move_base in
  ``/lizi1`` unless the launch file remaps ``map`` (the lesson remaps it to ``/map``);
* each observation source subscribes to its ``topic`` (same resolution) as ``LaserScan`` or
  ``PointCloud2``; readings are projected (laser_geometry's projectLaser) and moved into the
  costmap's ``global_frame`` with tf at the message's stamp; a reading whose stamp tf cannot
  answer is moved with the newest transform when that is within ``transform_tolerance`` of the
  stamp, and dropped otherwise (warned about when tf stays silent past the grace period of
  `fleetsim.tf.patience`); a source without ``observation_persistence`` is read at the update,
  its newest reading only (`fleetsim.nav.costmap.sources`);
* every ``1 / update_frequency`` s the robot pose (``robot_base_frame`` in ``global_frame``,
  newest tf, stale beyond ``transform_tolerance``) drives one layered update, and the robot
  footprint is published on ``~<name>/footprint`` (PolygonStamped);
* every ``1 / publish_frequency`` s the master grid goes out on ``~<name>/costmap``
  (OccupancyGrid, latched, costs translated as costmap_2d's publisher does). The whole grid is
  sent each time (there is no ``costmap_updates`` topic).

Frames get the robot's ``tf_prefix`` as ``tf::resolve`` applies it: ``/map`` is ``map``,
``base_link`` is ``lizi1/base_link`` (a frame already spelled ``lizi1/base_link`` is kept), and
a bare ``map`` is ``lizi1/map`` - write ``global_frame: /map`` for the shared map, as the
lesson's files do; the node warns when the prefixed frame is unknown but the bare one exists.

Nothing blocks: before the map or tf arrive the costmap is simply not `ready` (warned about,
retried every cycle) and move_base waits.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fleetsim.errors import TransformError
from fleetsim.msgs import geometry_msgs, nav_msgs, std_msgs
from fleetsim.nav.costmap.footprint import footprint_at, padded_footprint
from fleetsim.nav.costmap.layer import Bounds, Layer
from fleetsim.nav.costmap.layered_costmap import LayeredCostmap, occupancy_from_costs
from fleetsim.nav.costmap.obstacle_layer import ObstacleLayer
from fleetsim.nav.costmap.readings import points_from_cloud2  # noqa: F401 (its old home)
from fleetsim.nav.costmap.sources import ObservationSources
from fleetsim.nav.costmap.static_layer import StaticLayer
from fleetsim.nav.errors import CostmapError, MapError
from fleetsim.nav.map_io import OccupancyMap
from fleetsim.nav.map_server import grid_msg_from_map, map_from_grid_msg
from fleetsim.tf import resolve_frame_once
from fleetsim.tf.names import normalize_frame
from fleetsim.tf.patience import TransformPatience


class ExtraBounds(Layer):
    """A layer that only widens the next update's bounds (costmap_2d's addExtraBounds)."""

    def __init__(self) -> None:
        super().__init__("extra_bounds")
        self.pending = Bounds()

    def add(self, min_x: float, min_y: float, max_x: float, max_y: float) -> None:
        self.pending.include(min_x, min_y, max_x, max_y)

    def update_bounds(self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds):
        if not self.pending.empty:
            p = self.pending
            bounds.include(p.min_x, p.min_y, p.max_x, p.max_y)
            self.pending = Bounds()


class Costmap2DROS:
    """One costmap inside ``node``, named ``name`` (``~name/`` holds its parameters)."""

    def __init__(self, node: Any, name: str) -> None:
        self.node = node
        self.name = name
        self.ns = f"{node.full_name}/{name}"
        raw = node.runtime.params.get(self.ns, {})
        if not isinstance(raw, dict):
            raise CostmapError(f"{self.ns}: the costmap parameters must be a mapping, got {raw!r}")
        self.layered = LayeredCostmap.from_params(raw, self.ns)
        self.extra = ExtraBounds()
        self.layered.add_layer(self.extra)
        p = self.params = self.layered.params
        prefix = node.tf_prefix
        self.global_frame = resolve_frame_once(prefix, p.global_frame)
        self.robot_base_frame = resolve_frame_once(prefix, p.robot_base_frame)
        self._bare_global = normalize_frame(p.global_frame)
        self.stopped = False
        self.initialized = False  # one update ran with every static layer holding a map
        self.update_count = 0
        self.last_pose: tuple[float, float, float] | None = None
        self._patience = TransformPatience()  # missing transforms: reported when they last
        self.sources = ObservationSources(self)
        self._subs: list[Any] = []
        self._map_subs: dict[str, Any] = {}
        _ = node.tf_buffer  # listen to /tf from now on
        self.costmap_pub = node.create_publisher(
            nav_msgs.OccupancyGrid, f"~{name}/costmap", queue_size=1, latch=True
        )
        self.footprint_pub = node.create_publisher(
            geometry_msgs.PolygonStamped, f"~{name}/footprint", queue_size=1
        )
        for layer in self.layered.layers:
            if isinstance(layer, StaticLayer):
                self._subscribe_map(layer)
            elif isinstance(layer, ObstacleLayer):
                for source in layer.buffers:
                    self._subs.append(self.sources.subscribe(layer, source))
            elif hasattr(layer, "connect"):  # layers fed from topics (robots_layer)
                layer.connect(self)
        if p.update_frequency > 0:
            node.create_timer(1.0 / p.update_frequency, self.update)
        if p.publish_frequency > 0:
            node.create_timer(1.0 / p.publish_frequency, self.publish)

    # -- helpers -----------------------------------------------------------------------------
    @property
    def costmap(self):
        """The master `Costmap2D` (planners and controllers read it)."""
        return self.layered.costmap

    @property
    def footprint(self) -> np.ndarray:
        """The padded footprint polygon, (K, 2) m in the robot frame."""
        return self.layered.footprint

    @property
    def unpadded_footprint(self) -> np.ndarray:
        """The robot's body: the footprint without ``footprint_padding`` (Costmap2DROS's
        getUnpaddedRobotFootprint), (K, 2) m in the robot frame."""
        return padded_footprint(self.layered.footprint, -self.layered.params.footprint_padding)

    def _warn(self, key: str, text: str, period: float = 5.0) -> None:
        """Warn at most once every ``period`` s of sim time per key (ROS_WARN_THROTTLE)."""
        self.node._warn(f"{self.name}: {key}", f"{self.name}: {text}", period)

    def _static_layers(self) -> list[StaticLayer]:
        return [la for la in self.layered.layers if isinstance(la, StaticLayer)]

    # -- inputs --------------------------------------------------------------------------------
    def _subscribe_map(self, layer: StaticLayer) -> None:
        topic = layer.params.map_topic
        if layer.params.subscribe_to_updates:
            self._warn("updates", "subscribe_to_updates is not supported; only full maps are read")

        def on_map(msg: Any) -> None:
            if self.stopped:
                return
            where = f"{self.ns}/{layer.name}: {self.node.resolve_name(topic)}"
            try:
                occupancy = map_from_grid_msg(msg, where)
            except MapError as err:
                self.node.get_logger().error(f"ignoring map: {err}")
                return
            frame = normalize_frame(msg.header.frame_id) if msg.header.frame_id else ""
            if frame and frame != self.global_frame and not self.layered.rolling_window:
                self._warn(
                    "map_frame",
                    f"the map on {where} is in frame '{frame}' but the costmap's global_frame is "
                    f"'{self.global_frame}'; the map is used as if it were in the global frame",
                )
            # a rolling window looks its cells up in the map through tf at each update
            if layer.set_map(occupancy):
                layer.map_frame = frame

        old = self._map_subs.get(layer.name)
        if old is not None:
            old.destroy()
        sub = self.node.create_subscription(nav_msgs.OccupancyGrid, topic, on_map, 1)
        self._map_subs[layer.name] = sub
        self._subs.append(sub)

    def _to_global(self, frame: str, stamp: float, where: str):
        """(rotation (3, 3), translation (3,)) of ``frame`` in the global frame, or None."""
        buf = self.node.tf_buffer
        try:
            m = buf.lookup_matrix(self.global_frame, frame, stamp)
        except TransformError as err:
            try:
                latest = buf.latest_common_time(self.global_frame, frame)
                if abs(latest - stamp) > self.params.transform_tolerance and stamp > 0:
                    raise err
                m = buf.lookup_matrix(self.global_frame, frame, 0.0)
            except TransformError as final:
                key = f"tf:{where}"
                if self._patience.missing_too_long(key, self.node.now()):
                    waited = self._patience.missing_for(key, self.node.now())
                    self._warn(
                        key,
                        f"dropping readings of {where} in frame '{frame}' for {waited:.1f} s: "
                        f"{final}",
                    )
                    self._hint_frame()
                return None
        self._patience.found(f"tf:{where}")
        return m[:3, :3], m[:3, 3]

    def _hint_frame(self) -> None:
        if self.global_frame == self._bare_global:
            return
        known = self.node.tf_buffer.all_frames()
        if self.global_frame not in known and self._bare_global in known:
            self._warn(
                "hint",
                f"global_frame '{self.params.global_frame}' resolves to '{self.global_frame}' "
                f"under tf_prefix, which tf does not know; write '/{self._bare_global}' for the "
                "shared frame",
                period=60.0,
            )

    # -- outputs and state ---------------------------------------------------------------------
    def robot_pose(self) -> tuple[float, float, float] | None:
        """The robot's (x, y, yaw) in the global frame from the newest tf, or None (warned)."""
        buf = self.node.tf_buffer
        try:
            pose = buf.lookup_pose2d(self.global_frame, self.robot_base_frame, 0.0)
            stamp = buf.latest_common_time(self.global_frame, self.robot_base_frame)
        except TransformError as err:
            if self._patience.missing_too_long("pose", self.node.now()):
                waited = self._patience.missing_for("pose", self.node.now())
                self._warn("pose", f"cannot get the robot pose for {waited:.1f} s: {err}")
                self._hint_frame()
            return None
        self._patience.found("pose")
        now = self.node.now()
        if stamp > 0 and now - stamp > self.params.transform_tolerance:
            self._warn(
                "timeout",
                f"transform timeout. Current time: {now:.4f}, global_pose stamp: {stamp:.4f}, "
                f"tolerance: {self.params.transform_tolerance:.4f}",
            )
            return None
        return pose

    def update(self) -> bool:
        """One costmap update at the current robot pose; False when it could not run."""
        if self.stopped:
            return False
        pose = self.robot_pose()
        if pose is None:
            return False
        self.sources.read_unread()
        self.sources.warn_silent()
        self._place_maps()
        missing = [la.name for la in self._static_layers() if la.map_grid is None]
        if not missing:
            self._patience.found("map")
        elif self._patience.missing_too_long("map", self.node.now()):
            # a map server that comes up late is waited for, as tf is (5 s)
            waited = self._patience.missing_for("map", self.node.now())
            self._warn(
                "map", f"waiting {waited:.1f} s for the map on {', '.join(self._map_topics())}"
            )
        self.layered.update_map(*pose)
        self.last_pose = pose
        self.update_count += 1
        self.initialized = self.initialized or not missing
        self._publish_footprint(pose)
        return True

    def _place_maps(self) -> None:
        """Where each static layer's map lies in a rolling window's frame, from the newest tf
        (`StaticLayer.window_in_map`). Where tf does not have it the layer adds nothing this
        update, as costmap_2d's StaticLayer skips a rolling update it cannot transform (warned
        once it stays missing)."""
        if not self.layered.rolling_window:
            return
        for layer in self._static_layers():
            frame = layer.map_frame
            layer.window_in_map, layer.window_placed = None, True
            if not frame or frame == self.global_frame:
                continue
            key = f"map_tf:{layer.name}"
            try:
                place = self.node.tf_buffer.lookup_pose2d(frame, self.global_frame, 0.0)
            except TransformError as err:
                layer.window_placed = False
                if self._patience.missing_too_long(key, self.node.now()):
                    self._warn(key, f"cannot place the map of {layer.name} in the window: {err}")
                continue
            self._patience.found(key)
            # fake_localization's map -> odom is the identity up to float noise (1e-16): the
            # map is then read as it is, cell for cell
            if max(abs(v) for v in place) > 1e-9:
                layer.window_in_map = place

    def _map_topics(self) -> list[str]:
        return [self.node.resolve_name(la.params.map_topic) for la in self._static_layers()]

    def _publish_footprint(self, pose: tuple[float, float, float]) -> None:
        if self.footprint_pub.get_num_connections() == 0:
            return
        poly = footprint_at(self.footprint, *pose)
        self.footprint_pub.publish(
            geometry_msgs.PolygonStamped(
                header=std_msgs.Header(stamp=self.node.now_msg(), frame_id=self.global_frame),
                polygon=geometry_msgs.Polygon(
                    points=[geometry_msgs.Point32(x=float(x), y=float(y)) for x, y in poly]
                ),
            )
        )

    def publish(self) -> None:
        """Publish the master grid on ``~<name>/costmap`` (translated only when someone
        subscribes: costmap_2d's publisher skips a grid without subscribers too; the latched
        grid a later subscription gets is this one, from a copy of the costs)."""
        if not self.initialized or self.stopped:
            return
        m = self.costmap
        costs, res, origin = m.costs.copy(), m.resolution, (m.origin_x, m.origin_y, 0.0)
        frame, stamp = self.global_frame, self.node.now_msg()

        def make() -> nav_msgs.OccupancyGrid:
            grid = OccupancyMap(data=occupancy_from_costs(costs), resolution=res, origin=origin)
            return grid_msg_from_map(grid, frame, stamp)

        self.costmap_pub.publish_lazily(make)

    def is_current(self) -> bool:
        """Updated, and every source with an ``expected_update_rate`` heard from within it."""
        if not self.initialized or self.stopped:
            return False
        now = self.node.now()
        if self.sources.watched:  # a reading that came since the update counts as heard from
            self.sources.read_unread()
        for layer in self.layered.layers:
            if not isinstance(layer, ObstacleLayer):
                continue
            for source, buf in layer.buffers.items():
                rate = buf.params.expected_update_rate
                if rate <= 0:
                    continue
                last = self.sources.last_reading.get((layer.name, source), -math.inf)
                if now - last > rate:
                    topic = self.node.resolve_name(buf.params.topic)
                    self._warn(
                        f"stale:{source}",
                        f"the observation source '{source}' ({topic}) has not been updated for "
                        f"{now - last:.2f} s (expected_update_rate {rate:g} s)",
                    )
                    return False
        return True

    def reset_layers(self) -> None:
        """Forget all sensor data (clear_costmaps); the static map is re-applied next update."""
        self.sources.drop_unread()
        self.layered.reset_layers()

    def mark_full_update(self) -> None:
        """Recompute the whole grid at the next update (after a layer was cleared directly)."""
        m = self.costmap
        self.extra.add(
            m.origin_x,
            m.origin_y,
            m.origin_x + m.size_x * m.resolution,
            m.origin_y + m.size_y * m.resolution,
        )

    def stop(self) -> None:
        """Stop updating and reading sensors (shutdown_costmaps)."""
        self.stopped = True
        self.initialized = False
        self.sources.drop_unread()

    def start(self) -> None:
        """Resume after `stop`; static layers subscribe again (getting the latched map, as
        StaticLayer::activate does); ready again after the next update."""
        if self.stopped:
            self.stopped = False
            self.sources.last_reading.clear()
            self.sources.armed_at = None  # silence counted from the next update with a pose
            for layer in self._static_layers():
                layer.reset()
                self._subscribe_map(layer)

    def destroy(self) -> None:
        for sub in self._subs:
            sub.destroy()
        self._subs.clear()
