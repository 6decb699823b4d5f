"""The robots layer: other robots' footprints from ``/position_share`` as lethal cells.

Nav2 issue 1318 proposed a ``RobotsLayer`` fed by the robots' shared footprints, because a
laser mounted above (or below) the other robots' bodies does not see them; collvoid's
position_share_controller does the same job by publishing ``stationary_robots``. As collvoid,
only robots slower than ``still_speed`` are marked (moving robots are the local planner's
business, and marking them would make the global planner chase their wake), each footprint
scaled by ``static_scale`` and padded by this robot's inscribed radius (costmap_2d's
padFootprint), so that a plan keeps this robot's body clear of theirs. In a local costmap whose
planner checks the robot's footprint against lethal cells (TrajectoryPlannerROS), ``padding``
of a few cm (the shared poses' error) with ``cost: 254`` and a ``still_speed`` above any
robot's marks every other robot's body: how a robot whose laser passes above the others'
bodies sees them at all (slam_explore's two hunters).

The cells get ``cost`` (default 252, just below costmap_2d's inscribed cost), not a lethal
one: navfn then plans around a parked robot where there is room, and still finds a plan when a
robot stands on the goal or in a passage with no way round (as in a swap, where every goal is
another robot's start) - the local planner deals with that robot when it is reached. A lethal
cost (``cost: 254``) would also be inflated by an inflation layer after this one::

    plugins:
      - {name: static_layer, type: costmap_2d::StaticLayer}
      - {name: robots_layer, type: fleetsim::RobotsLayer}
      - {name: inflation_layer, type: costmap_2d::InflationLayer}

A laser that does see the other robots marks their bodies in the obstacle layers, and every
cell a moving robot was seen in stays lethal until a ray of this robot's sensor passes through
it again: in a crowd the cells behind the other robots are never swept, and eight turtlebot3
burgers on the circle of 8 stood in a ring of their own wakes (32 robots 20 s without progress
in 5 seeds). With ``clear_robots`` (a fleetsim addition, on by default) the layer erases from
the obstacle layers of its costmap the cells under every other robot on the move (at
``still_speed`` or faster), its shared footprint padded by ``seen_padding`` and by how far it
moves in ``SEEN_LAG`` (the age of a scan and of a shared pose), at every update: a moving
robot's image never outlives the update it was marked in. A wall under the padding is marked
again by the next scan that sees it (the static layer's walls are not touched). By default a
robot standing still keeps its image, which is where it is (the local planner tells parked
robots it sees from those it does not by it), and gets this layer's marks. With
``clear_still_robots`` (for a global costmap) the obstacle layers' cells under those marks are
erased, so that only the marks (``cost``, not lethal, not inflated) stay there while it stands:
three jackals in the Willow map, whose lasers see each other, had no global plan for 10-15 s
after their goals went out, since each goal is another jackal's start and its lethal, inflated
image made navfn refuse the goal until the aggressive reset cleared the obstacle layer. A
parked robot then has no inflation round it in the global costmap, as the robots that lasers
do not see (the lizis) never had. Layers before this one in ``plugins`` are cleared after
their marking (``update_bounds``), layers after it before their costs reach the master grid
(``update_costs``).

The layer keeps no grid of its own: each update it clears where robots were last marked (by
widening the bounds, so the layers below rewrite those cells) and marks where they are now. The
robot's own id (``robot_id``, else its tf_prefix) is skipped. Shared poses are in ``map``; a
costmap in another frame reaches it through tf.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.errors import TransformError
from fleetsim.nav.costmap.footprint import padded_footprint, polygon_cells
from fleetsim.nav.costmap.layer import Bounds, Layer
from fleetsim.nav.costmap.obstacle_layer import ObstacleLayer
from fleetsim.runtime import param

MAP_FRAME = "map"
#: s; how old a scan's image of another robot can be against that robot's shared pose (a 10 Hz
#: /position_share message and a scan of 5 Hz or more), times its speed: padding for clearing
SEEN_LAG = 0.3


@dataclass(frozen=True)
class RobotsLayerParams:
    """``robots_layer`` parameters."""

    enabled: bool = param(True, help="mark other robots at all")
    still_speed: float = param(
        0.05, unit="m/s", range=(0.0, None), help="robots slower than this are marked"
    )
    static_scale: float = param(
        0.95, range=(0.0, None), help="scale of the marked footprints (collvoid's)"
    )
    max_distance: float = param(
        50.0, unit="m", range=(0.0, None), help="robots farther from this one are not marked"
    )
    robot_id: str = param("", help="this robot's id on /position_share (empty: tf_prefix)")
    cost: int = param(252, range=(1, 254), help="cost of the cells under a marked robot")
    clear_robots: bool = param(
        True,
        help="erase the moving robots' bodies, as the sensors saw them, from this costmap's "
        "obstacle layers (fleetsim)",
    )
    clear_still_robots: bool = param(
        False,
        help="erase from the obstacle layers the cells this layer marks (at cost) under the "
        "robots standing still: in a global costmap, where a robot's laser image, lethal and "
        "inflated, closes a passage or the goal it stands on to navfn; not in a local costmap "
        "whose collvoid planner tells parked robots its sensors see by their image (fleetsim)",
    )
    seen_padding: float = param(
        0.1,
        unit="m",
        range=(0.0, None),
        help="added round a robot's shared footprint for clear_robots (two 5 cm cells: the "
        "cells its outline's hits fall in)",
    )
    eps: float = param(
        0.1,
        range=(0.0, 0.999),
        help="the fleet's eps (collvoid's, as me_publisher's and the local planner's): a "
        "robot sharing a covariance is marked as its body plus that quantile of its spread",
    )
    padding: float = param(
        -1.0,
        unit="m",
        range=(-1.0, None),
        help="added round the marked footprints; -1: this robot's inscribed radius (for a "
        "planner of the robot's centre); >= 0 in a local costmap whose planner checks the "
        "footprint itself",
    )


class RobotsLayer(Layer):
    """Other robots' footprints, from /position_share (see the module doc)."""

    Params = RobotsLayerParams

    def __init__(self, name: str, params: RobotsLayerParams | None = None) -> None:
        super().__init__(name)
        self.params = params or RobotsLayerParams()
        self.enabled = self.params.enabled
        self.table: Any = None  # a NeighbourTable, once connected
        self.now = lambda: 0.0
        self.to_frame = lambda: (0.0, 0.0, 0.0)  # map pose in the costmap's frame
        self.robot_id = self.params.robot_id
        self.polygons: list[np.ndarray] = []  # marked now, costmap frame
        self._last: list[np.ndarray] = []
        self._grow = 0.0
        self.seen: list[np.ndarray] = []  # other robots' padded bodies now, costmap frame

    def connect(self, costmap_ros: Any) -> None:
        """Listen to /position_share through the costmap's node (Costmap2DROS calls this)."""
        from fleetsim.nav.multirobot.position_share import PositionShare

        node = costmap_ros.node
        self.table = PositionShare(node, eps=self.params.eps).table
        self.now = node.now
        self.robot_id = self.params.robot_id or node.tf_prefix or node.namespace.strip("/")
        frame = costmap_ros.global_frame
        if frame != MAP_FRAME:
            self.to_frame = lambda: node.tf_buffer.lookup_pose2d(frame, MAP_FRAME, 0.0)

    def set_robots(self, polygons: list[np.ndarray]) -> None:
        """Mark these (K, 2) polygons (costmap frame) at the next update (no subscription)."""
        self.table = None
        self.polygons = [np.asarray(p, dtype=np.float64) for p in polygons]

    def _polygons_now(self, robot_x: float, robot_y: float) -> tuple[list, list]:
        """The footprints to mark (robots standing still, scaled and padded for planning) and
        the bodies to clear (the robots on the move, `clear_robots`), in the costmap's frame."""
        if self.table is None:
            return self.polygons, []
        p = self.params
        try:
            tx, ty, tyaw = self.to_frame()
        except TransformError:
            return [], []
        rot = np.array([[np.cos(tyaw), -np.sin(tyaw)], [np.sin(tyaw), np.cos(tyaw)]])

        def placed(r, body):
            c, s = np.cos(r.yaw), np.sin(r.yaw)
            return (body @ np.array([[c, s], [-s, c]]) + [r.x, r.y]) @ rot.T + [tx, ty]

        marked, seen = [], []
        for r in self.table.fresh(self.now()):
            if r.robot_id == self.robot_id:
                continue
            centre = rot @ [r.x, r.y] + [tx, ty]
            if np.hypot(centre[0] - robot_x, centre[1] - robot_y) > p.max_distance:
                continue
            speed = float(np.hypot(r.vx, r.vy))
            if speed < p.still_speed:
                # its body and spread by direction (its shared footprint is padded by its
                # widest spread all round: a lizi parked with amcl closed a 2 m corridor)
                mark = placed(r, r.outline(p.eps, p.static_scale, self._grow))
                marked.append(mark)
                if p.clear_still_robots:  # under its mark only: nothing erased goes unmarked
                    seen.append(mark)
            elif p.clear_robots:
                pad = p.seen_padding + SEEN_LAG * speed
                seen.append(placed(r, padded_footprint(r.footprint, pad)))
        return marked, seen

    def _clear_seen(self, after: bool) -> None:
        """Erase the other robots' bodies (``self.seen``) from the obstacle layers before this
        one in the costmap's plugins (``after`` False: their marking is done) or after it."""
        if not self.seen or self.layered is None:
            return
        layers = self.layered.layers
        k = layers.index(self)
        for layer in layers[k + 1 :] if after else layers[:k]:
            if isinstance(layer, ObstacleLayer) and layer.enabled:
                for poly in self.seen:
                    rows, cols = polygon_cells(layer.grid, poly)
                    layer.clear_cells(rows, cols)

    def on_footprint_changed(self) -> None:
        pad = self.params.padding
        if pad < 0:
            pad = self.layered.inscribed_radius if self.layered is not None else 0.0
        self._grow = pad

    def update_bounds(self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds):
        if not self.enabled:
            return
        self.polygons, self.seen = self._polygons_now(robot_x, robot_y)
        for poly in (*self._last, *self.polygons, *self.seen):
            lo, hi = poly.min(axis=0), poly.max(axis=0)
            bounds.include(lo[0], lo[1], hi[0], hi[1])
        self._last = list(self.polygons)
        self._clear_seen(after=False)

    def update_costs(self, master, x0: int, y0: int, xn: int, yn: int) -> None:
        if not self.enabled:
            return
        self._clear_seen(after=True)
        for poly in self.polygons:
            rows, cols = polygon_cells(master, poly)
            keep = (cols >= x0) & (cols < xn) & (rows >= y0) & (rows < yn)
            r, c = rows[keep], cols[keep]
            master.costs[r, c] = np.maximum(master.costs[r, c], self.params.cost)
