"""The observation sources of a costmap: subscriptions, and readings waiting for the update.

Each obstacle-layer source (``observation_sources``) subscribes to its ``topic``; a reading is
projected (`fleetsim.nav.costmap.readings`) and moved into the costmap's global frame with tf
at its stamp (`Costmap2DROS._to_global`). A source without ``observation_persistence`` keeps
only its newest reading in the layer, so its readings wait here and the update reads the newest
one tf can place, instead of every one at its sensor's rate (a 40 Hz laser, a 5 Hz costmap: an
eighth of the work, the same observations). A source with persistence reads each reading as it
comes, since all within the window count.
"""

from __future__ import annotations

from collections import deque
from typing import TYPE_CHECKING, Any

import numpy as np

from fleetsim.errors import FleetsimError
from fleetsim.msgs import get_type, sensor_msgs
from fleetsim.nav.costmap.obstacle_layer import ObstacleLayer
from fleetsim.nav.costmap.readings import points_from_cloud1, points_from_cloud2, points_from_scan
from fleetsim.nav.errors import CostmapError
from fleetsim.runtime.node import SILENT_AFTER, SILENT_REPEAT
from fleetsim.tf import resolve_frame_once
from fleetsim.tf.names import normalize_frame

if TYPE_CHECKING:
    from fleetsim.nav.costmap.costmap_ros import Costmap2DROS

#: readings kept per source until the next update reads the newest one tf can place
UNREAD_KEPT = 4


def _scan_points(msg: Any, sp: Any, where: str) -> np.ndarray:
    return points_from_scan(msg, sp.inf_is_valid)


def _cloud2_points(msg: Any, sp: Any, where: str) -> np.ndarray:
    return points_from_cloud2(msg, where)


def _cloud1_points(msg: Any, sp: Any, where: str) -> np.ndarray:
    return points_from_cloud1(msg)


class ObservationSources:
    """The observation sources of one `Costmap2DROS`."""

    def __init__(self, costmap: Costmap2DROS) -> None:
        self.costmap = costmap
        #: (layer, source) -> sim time the newest reading read into the layer came
        self.last_reading: dict[tuple[str, str], float] = {}
        # (layer, source) -> (readings not read yet, newest last, with when they came; the
        # function that reads one)
        self._unread: dict[tuple[str, str], tuple[deque, Any]] = {}
        #: whether a source has an expected_update_rate (then `is_current` reads the readings
        #: that wait, to know when each source was last heard from)
        self.watched = False
        # sources not heard from yet: (layer, source) -> (subscription, sim time subscribed)
        self._silent: dict[tuple[str, str], tuple[Any, float]] = {}
        # sim time of the first update with a robot pose since the costmap (re)started: the
        # silence is counted from there (a robot spawned late, costmaps shut down until a goal)
        self.armed_at: float | None = None

    def subscribe(self, layer: ObstacleLayer, source: str) -> Any:
        """Subscribe ``source`` of ``layer`` to its topic; returns the subscription."""
        cm = self.costmap
        sp = layer.buffers[source].params
        self.watched = self.watched or sp.expected_update_rate > 0
        where = f"{cm.ns}/{layer.name}/{source}"
        if sp.data_type == "LaserScan":
            msg_type, convert = sensor_msgs.LaserScan, _scan_points
        elif sp.data_type == "PointCloud2":
            msg_type, convert = sensor_msgs.PointCloud2, _cloud2_points
        else:
            try:
                msg_type = get_type("sensor_msgs/PointCloud")
            except FleetsimError:
                raise CostmapError(
                    f"{where}: data_type PointCloud (sensor_msgs/PointCloud, ROS 1's old cloud) "
                    "is not available; publish PointCloud2 and set data_type: PointCloud2, or "
                    "use data_type: LaserScan"
                ) from None
            convert = _cloud1_points
        sensor_frame = (
            resolve_frame_once(cm.node.tf_prefix, sp.sensor_frame) if sp.sensor_frame else ""
        )

        key = (layer.name, source)

        def ingest(msg: Any, heard: float) -> bool:
            """Project and move one reading into the layer; False when it was dropped."""
            try:
                points = convert(msg, sp, where)
            except CostmapError as err:
                cm._warn(f"bad:{where}", f"ignoring a reading: {err}")
                return False
            frame = normalize_frame(msg.header.frame_id)
            stamp = msg.header.stamp.to_sec()
            moved = cm._to_global(frame, stamp, where)
            if moved is None:
                return False
            rot, trans = moved
            origin = trans
            if sensor_frame and sensor_frame != frame:
                # its own key: the message frame's lookup just succeeded, which would restart
                # the patience of a shared one on every reading, and a sensor_frame tf never
                # has (a typo) went unreported while the source dropped every reading
                at = cm._to_global(sensor_frame, stamp, f"{where} (sensor_frame)")
                if at is None:
                    return False
                origin = at[1]
            layer.add_observation(source, origin, points @ rot.T + trans, stamp)
            self.last_reading[key] = heard
            return True

        if sp.observation_persistence > 0.0:  # every reading in the window counts: read it now

            def on_reading(msg: Any) -> None:
                self._silent.pop(key, None)  # heard, stopped or not
                if not cm.stopped:
                    ingest(msg, cm.node.now())

        else:  # only the newest reading counts: keep it until the next update reads it
            unread: deque = deque(maxlen=UNREAD_KEPT)
            self._unread[key] = (unread, ingest)

            def on_reading(msg: Any) -> None:
                self._silent.pop(key, None)  # heard, stopped or not
                if not cm.stopped:
                    unread.append((msg, cm.node.now()))

        sub = cm.node.create_subscription(msg_type, sp.topic, on_reading, 1)
        self._silent[key] = (sub, cm.node.now())
        return sub

    def warn_silent(self) -> None:
        """Warn (every `SILENT_REPEAT` s) about each source that has had no reading in the
        `SILENT_AFTER` s since it subscribed or the costmap's first update with a pose (after
        a start), whichever came last, naming its topic and, when nobody publishes there, the
        topics of its type that have a publisher (a laser on ``base_scan`` or ``/scan`` for a source
        reading ``scan``: the costmap would otherwise hold no obstacle of it, silently, as in
        ROS unless ``expected_update_rate`` is set)."""
        cm = self.costmap
        now = cm.node.now()
        if self.armed_at is None:
            self.armed_at = now
        for (layer, source), (sub, subscribed) in self._silent.items():
            since = max(subscribed, self.armed_at)
            if now - since < SILENT_AFTER:
                continue
            text = (
                f"{layer}/{source}: no reading on {sub.topic.name} in {now - since:.0f} s"
                f"{cm.node.unpublished_hint(sub)}: the layer marks nothing from it (check the "
                "source's topic)"
            )
            cm._warn(f"silent:{layer}/{source}", text, SILENT_REPEAT)

    def read_unread(self) -> None:
        """Feed each source's newest reading that tf can place (the ones before it would be
        replaced by it in the layer anyway, observation_persistence being 0)."""
        for unread, ingest in self._unread.values():
            while unread:
                msg, heard = unread.pop()
                if ingest(msg, heard):
                    unread.clear()

    def drop_unread(self) -> None:
        """Forget the readings not read yet (the costmap was cleared or stopped)."""
        for unread, _ in self._unread.values():
            unread.clear()
