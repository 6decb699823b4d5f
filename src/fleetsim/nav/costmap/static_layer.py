"""The static map layer (costmap_2d::StaticLayer): costs from an occupancy grid."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from fleetsim.nav.costmap.costmap_2d import (
    FREE_SPACE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
    lookup_bytes,
)
from fleetsim.nav.costmap.footprint import footprint_at
from fleetsim.nav.costmap.layer import Bounds, CostmapLayer, combined_max
from fleetsim.nav.map_io import OccupancyMap
from fleetsim.runtime import param


@dataclass(frozen=True)
class StaticLayerParams:
    """Parameters of ``costmap_2d::StaticLayer`` (in the costmap's ``<layer name>/`` ns)."""

    enabled: bool = param(True, help="whether the layer contributes to the costmap")
    map_topic: str = param("map", help="topic the map is read from")
    unknown_cost_value: int = param(
        -1, range=(-128, 255), help="map value read as unknown (compared as an unsigned byte)"
    )
    lethal_cost_threshold: int = param(
        100, range=(0, 255), help="map values at or above this are lethal"
    )
    track_unknown_space: bool = param(
        True, help="unknown map cells stay NO_INFORMATION (else they become free)"
    )
    first_map_only: bool = param(False, help="ignore every map after the first")
    subscribe_to_updates: bool = param(False, help="also apply map_updates patches")
    trinary_costmap: bool = param(
        True, help="map values below the lethal threshold become free (else scaled)"
    )
    use_maximum: bool = param(
        False, help="combine with the master by maximum (else overwrite the master)"
    )


def costs_from_occupancy(
    data: np.ndarray,
    *,
    lethal_cost_threshold: int = 100,
    unknown_cost_value: int = -1,
    track_unknown_space: bool = True,
    trinary_costmap: bool = True,
) -> np.ndarray:
    """Costmap costs of occupancy values, as StaticLayer::interpretValue.

    data : (H, W) int8 occupancy (-1 unknown, 0..100). Values are compared as unsigned
    bytes, so -1 is 255. Returns (H, W) uint8 costs: each of the 256 byte values is
    interpreted once and the map looked up (`lookup_bytes`)."""
    table = _interpreted(
        lethal_cost_threshold, unknown_cost_value, track_unknown_space, trinary_costmap
    )
    return lookup_bytes(np.asarray(data), table)


@functools.lru_cache(maxsize=16)
def _interpreted(lethal: int, unknown_value: int, track_unknown: bool, trinary: bool) -> np.ndarray:
    """(256,) uint8: StaticLayer::interpretValue of every byte value."""
    v = np.arange(256, dtype=np.int16)
    unknown = v == (unknown_value & 0xFF)
    if trinary:
        out = np.full(v.shape, FREE_SPACE, dtype=np.uint8)
    else:
        scaled = v.astype(np.float64) / max(lethal, 1) * LETHAL_OBSTACLE
        out = np.clip(scaled, 0, 255).astype(np.uint8)
    out[v >= lethal] = LETHAL_OBSTACLE
    out[unknown] = NO_INFORMATION if track_unknown else FREE_SPACE
    out.flags.writeable = False
    return out


def _changed_cells(old: Costmap2D | None, new: Costmap2D) -> tuple[int, int, int, int] | None:
    """The bounds (x0, y0, xn, yn), end exclusive, of the cells whose costs differ between two
    maps of the same size, resolution and origin ((0, 0, 0, 0) when none does); None when there
    is no old map or its geometry differs (every cell is new).

    ROS's StaticLayer marks the whole map for update on every new map; the layers' costs outside
    the changed cells (grown by the inflation radius) are the same either way, so the update is
    the same. A SLAM map is republished whole every few seconds (gmapping's
    ``map_update_interval``) but changes around the robot: inflating all of the hunter's
    2000 x 2000 cell map took ~120 ms a map."""
    if old is None or old.geometry != new.geometry:
        return None
    diff = old.costs != new.costs
    rows = np.flatnonzero(diff.any(axis=1))
    if rows.size == 0:
        return (0, 0, 0, 0)
    cols = np.flatnonzero(diff[rows[0] : rows[-1] + 1].any(axis=0))
    return int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1


def _union(a: tuple[int, int, int, int] | None, b: tuple[int, int, int, int]):
    """The bounds covering both cell bounds (None, every cell, covers anything)."""
    if a is None:
        return None
    if a[2] <= a[0] or a[3] <= a[1]:
        return b
    if b[2] <= b[0] or b[3] <= b[1]:
        return a
    return min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3])


class StaticLayer(CostmapLayer):
    """Holds the latest map (as costs); static maps size the master unless it rolls."""

    Params = StaticLayerParams

    def __init__(self, name: str = "static_layer", params: StaticLayerParams | None = None):
        super().__init__(name)
        self.params = params or StaticLayerParams()
        self.enabled = self.params.enabled
        self.map_grid: Costmap2D | None = None  # the map's own grid (its resolution, origin)
        self._has_updated_data = False
        #: the map's cells (x0, y0, xn, yn) that the last map changed, or None: all of them
        self._changed: tuple[int, int, int, int] | None = None
        #: the rolling window's frame in the map's frame, (x, y, yaw) m, rad, for this update, or
        #: None where they are the same frame (Costmap2DROS sets it from tf before each update)
        self.window_in_map: tuple[float, float, float] | None = None
        #: False while tf cannot place the map in the rolling window: the layer adds nothing
        self.window_placed = True
        #: the frame of the map last taken ("": none given), set by Costmap2DROS
        self.map_frame = ""

    def set_map(self, occupancy: OccupancyMap) -> bool:
        """Take a new map (the ``map`` topic callback). Returns False if it was ignored."""
        if self.map_grid is not None and self.params.first_map_only:
            return False
        p = self.params
        grid = Costmap2D(
            occupancy.width,
            occupancy.height,
            occupancy.resolution,
            occupancy.origin[0],
            occupancy.origin[1],
            NO_INFORMATION,
        )
        grid.costs = costs_from_occupancy(
            occupancy.data,
            lethal_cost_threshold=p.lethal_cost_threshold,
            unknown_cost_value=p.unknown_cost_value,
            track_unknown_space=p.track_unknown_space,
            trinary_costmap=p.trinary_costmap,
        )
        changed = _changed_cells(self.map_grid, grid)
        if self._has_updated_data and changed is not None:  # the last map is not applied yet
            changed = _union(self._changed, changed)
        self._changed = changed
        self.map_grid = grid
        assert self.layered is not None
        lc = self.layered
        if not lc.rolling_window:
            m = lc.costmap
            if m.geometry != grid.geometry:
                lc.resize_map(
                    grid.size_x, grid.size_y, grid.resolution, grid.origin_x, grid.origin_y
                )
            self.grid.costs = grid.costs.copy()
        self._has_updated_data = True
        return True

    def match_size(self) -> None:
        super().match_size()
        g = self.map_grid
        rolling = self.layered is not None and self.layered.rolling_window
        if g is not None and not rolling and self.grid.costs.shape == g.costs.shape:
            self.grid.costs = g.costs.copy()

    def reset(self) -> None:
        # The static map is not sensor data: a reset re-applies it.
        self._has_updated_data = True
        self._changed = None

    def update_bounds(self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds):
        g = self.map_grid
        if g is None:
            return
        rolling = self.layered.rolling_window  # type: ignore[union-attr]
        if not rolling and not self._has_updated_data:
            return
        x0, y0, xn, yn = (
            (0, 0, g.size_x, g.size_y) if rolling or self._changed is None else self._changed
        )
        self._has_updated_data = False
        self._changed = None
        if xn <= x0 or yn <= y0:  # the same map again
            return
        res = g.resolution
        ax, ay = g.origin_x + x0 * res, g.origin_y + y0 * res
        bx, by = g.origin_x + xn * res, g.origin_y + yn * res
        if rolling and self.window_in_map is not None:  # the map's corners in the window
            tx, ty, yaw = self.window_in_map
            corners = np.array([(x - tx, y - ty) for x in (ax, bx) for y in (ay, by)])
            inside = footprint_at(corners, 0.0, 0.0, -yaw)
            (ax, ay), (bx, by) = inside.min(axis=0), inside.max(axis=0)
        bounds.include(ax, ay, bx, by)

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        if not self.enabled or self.map_grid is None or xn <= x0 or yn <= y0:
            return
        if not self.layered.rolling_window:  # type: ignore[union-attr]
            if self.params.use_maximum:
                self.update_with_max(master, x0, y0, xn, yn)
            else:
                self.update_with_true_overwrite(master, x0, y0, xn, yn)
            return
        if not self.window_placed:
            return
        # Rolling window: look each master cell's centre up in the map, through the transform
        # between the window's frame and the map's (costmap_2d's StaticLayer transforms each
        # cell by tf's map <- global transform: a local costmap in odom holds the map's walls
        # where amcl's map -> odom puts them)
        mx, my = np.meshgrid(np.arange(x0, xn), np.arange(y0, yn))
        centres = np.stack(
            (
                master.origin_x + (mx + 0.5) * master.resolution,
                master.origin_y + (my + 0.5) * master.resolution,
            ),
            axis=-1,
        )
        if self.window_in_map is not None:
            centres = footprint_at(centres.reshape(-1, 2), *self.window_in_map).reshape(
                centres.shape
            )
        cells, inside = self.map_grid.cells_of(centres)
        window = master.costs[y0:yn, x0:xn]
        values = np.full(window.shape, NO_INFORMATION, dtype=np.uint8)
        values[inside] = self.map_grid.costs[cells[inside][:, 1], cells[inside][:, 0]]
        if self.params.use_maximum:
            master.costs[y0:yn, x0:xn] = combined_max(window, values)
        else:
            master.costs[y0:yn, x0:xn] = np.where(inside, values, window)
