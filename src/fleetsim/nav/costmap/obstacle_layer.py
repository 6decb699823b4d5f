"""The obstacle layer (costmap_2d::ObstacleLayer): marking and clearing from sensor data.

Sensors arrive as `Observation` arrays already in the costmap's global frame (the node layer
converts LaserScan / PointCloud messages with tf; `laser_scan_points` does the projection):
each source marks (endpoints within ``obstacle_range`` become LETHAL) and/or clears (cells on
the Bresenham line from the sensor origin towards each point, up to ``raytrace_range``, become
FREE). Clearing runs before marking, as in costmap_2d.
"""

from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numba import njit

from fleetsim.nav.costmap.costmap_2d import FREE_SPACE, LETHAL_OBSTACLE, NO_INFORMATION
from fleetsim.nav.costmap.footprint import footprint_at, polygon_cells
from fleetsim.nav.costmap.layer import Bounds, CostmapLayer
from fleetsim.nav.costmap.raytrace import clear_along_rays
from fleetsim.nav.errors import CostmapError
from fleetsim.runtime import load_params, param
from fleetsim.runtime.param_tree import ParamDict

_log = logging.getLogger("fleetsim.nav.costmap")
_RANGE_DEFAULTS = {"obstacle_range": 2.5, "raytrace_range": 3.0}


@dataclass(frozen=True)
class ObservationSourceParams:
    """One entry of ``observation_sources`` (its own ``<layer>/<source>/`` namespace)."""

    topic: str = param("", help="sensor topic; empty means the source's name")
    sensor_frame: str = param("", help="frame of the sensor origin; empty: the message's frame")
    observation_persistence: float = param(
        0.0, unit="s", range=(0.0, None), help="how long to keep readings (0: latest only)"
    )
    expected_update_rate: float = param(
        0.0, unit="s", range=(0.0, None), help="max time between readings (0: never stale)"
    )
    data_type: str = param(
        "PointCloud", choices=("LaserScan", "PointCloud", "PointCloud2"), help="message type"
    )
    min_obstacle_height: float = param(0.0, unit="m", help="points below this are dropped")
    max_obstacle_height: float = param(2.0, unit="m", help="points above this are dropped")
    inf_is_valid: bool = param(False, help="LaserScan +inf ranges become range_max readings")
    clearing: bool = param(False, help="raytrace free space with this source")
    marking: bool = param(True, help="mark obstacles with this source")
    obstacle_range: float = param(2.5, unit="m", range=(0.0, None), help="max marking range")
    raytrace_range: float = param(3.0, unit="m", range=(0.0, None), help="max clearing range")


@dataclass(frozen=True)
class ObstacleLayerParams:
    """Parameters of ``costmap_2d::ObstacleLayer`` (in ``<layer name>/``)."""

    enabled: bool = param(True, help="whether the layer contributes to the costmap")
    observation_sources: str = param("", help="space-separated source names")
    max_obstacle_height: float = param(2.0, unit="m", help="marking ignores points above this")
    obstacle_range: float = param(2.5, unit="m", range=(0.0, None), help="sources' default")
    raytrace_range: float = param(3.0, unit="m", range=(0.0, None), help="sources' default")
    track_unknown_space: bool | None = param(
        None, help="start cells unknown rather than free (unset: the costmap's setting)"
    )
    footprint_clearing_enabled: bool = param(True, help="clear the cells under the robot")
    combination_method: int = param(
        1, choices=(0, 1), help="0 overwrite the master, 1 keep the maximum"
    )


@dataclass
class Observation:
    """One sensor reading in the costmap's global frame.

    origin : (3,) sensor position, m. points : (N, 3) hit points, m.
    """

    origin: np.ndarray
    points: np.ndarray
    obstacle_range: float
    raytrace_range: float
    stamp: float = 0.0


def laser_scan_points(
    ranges: np.ndarray,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    inf_is_valid: bool = False,
) -> np.ndarray:
    """LaserScan ranges as points in the sensor frame, as laser_geometry's projectLaser.

    Readings outside ``[range_min, range_max)`` are dropped; with ``inf_is_valid`` a +inf
    reading becomes ``range_max - 1e-4`` first (ObstacleLayer's laserScanValidInfCallback).
    ranges : (B,) m. Returns (N, 3) m with z = 0.
    """
    r = np.asarray(ranges, dtype=np.float64)
    cos_a, sin_a = _beam_directions(float(angle_min), float(angle_increment), r.shape[0])
    inf_range = float(range_max - 1e-4)  # in the message's own float type, as before
    inf_is_valid = bool(inf_is_valid)
    return _projected(r, cos_a, sin_a, float(range_min), float(range_max), inf_is_valid, inf_range)


@functools.lru_cache(maxsize=256)
def _beam_directions(angle_min: float, angle_increment: float, n: int):
    """Cosines and sines (B,) of a scan's beam angles ``angle_min + angle_increment * i``,
    kept per scan geometry (a laser's is the same in every scan; NumPy's cos and sin of a
    beam are the same whichever beams are taken with it)."""
    angles = angle_min + angle_increment * np.arange(n)
    cos_a, sin_a = np.cos(angles), np.sin(angles)
    cos_a.flags.writeable = sin_a.flags.writeable = False
    return cos_a, sin_a


@njit(cache=True)
def _projected(r, cos_a, sin_a, range_min, range_max, inf_is_valid, inf_range):
    """`laser_scan_points`' points from ranges (B,) and beam directions, compiled (each
    costmap reads a scan at its update; NumPy's dozen calls cost ~50 us a scan)."""
    out = np.empty((r.shape[0], 3))
    n = 0
    for i in range(r.shape[0]):
        v = r[i]
        if inf_is_valid and v == np.inf:
            v = inf_range
        if np.isfinite(v) and v >= range_min and v < range_max:
            out[n, 0] = v * cos_a[i]
            out[n, 1] = v * sin_a[i]
            out[n, 2] = 0.0
            n += 1
    return out[:n].copy()


@dataclass
class ObservationBuffer:
    """Recent readings of one source (costmap_2d's ObservationBuffer)."""

    name: str
    params: ObservationSourceParams
    observations: list[Observation] = field(default_factory=list)

    def add(self, origin: Any, points: Any, stamp: float = 0.0) -> None:
        """Store a reading, keeping only points within the source's height band."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        o = np.asarray(origin, dtype=np.float64).reshape(3)
        p = self.params
        pts = _in_height_band(pts, float(p.min_obstacle_height), float(p.max_obstacle_height))
        obs = Observation(o, pts, p.obstacle_range, p.raytrace_range, stamp)
        if p.observation_persistence <= 0.0:
            self.observations = [obs]
        else:
            keep = [x for x in self.observations if stamp - x.stamp <= p.observation_persistence]
            self.observations = [*keep, obs]


def _searched(key: str, *namespaces: dict) -> Any:
    for ns in namespaces:
        if key in ns:
            return ns[key]
    return _RANGE_DEFAULTS[key]


class ObstacleLayer(CostmapLayer):
    """Marks and clears a 2-D grid from observation buffers."""

    Params = ObstacleLayerParams

    def __init__(
        self,
        name: str = "obstacle_layer",
        params: ObstacleLayerParams | None = None,
        sources: dict[str, ObservationSourceParams] | None = None,
    ) -> None:
        super().__init__(name)
        self.params = params or ObstacleLayerParams()
        self.enabled = self.params.enabled
        self.buffers = {n: ObservationBuffer(n, s) for n, s in (sources or {}).items()}
        self._robot = (0.0, 0.0, 0.0)

    @classmethod
    def from_namespace(
        cls, name: str, ns: dict[str, Any], parent: dict[str, Any], where: str = ""
    ) -> ObstacleLayer:
        """Build from the layer's namespace dict; per-source ranges fall back upwards."""
        where = f"{where}/{name}" if where else name
        source_names = str(ns.get("observation_sources", "")).split()
        params = load_params(cls.Params, ns, where, ignore=frozenset(source_names))
        sources = {}
        for src in source_names:
            raw = ns.get(src)
            if not isinstance(raw, dict):
                raise CostmapError(
                    f"{where}: observation source '{src}' is listed in observation_sources but "
                    f"'{where}/{src}' is not a mapping (give it data_type, topic, marking, ...)"
                )
            raw = ParamDict.copy_of(raw)
            for key in _RANGE_DEFAULTS:
                raw.setdefault(key, _searched(key, ns, parent))
            raw.setdefault("topic", src)
            sources[src] = load_params(ObservationSourceParams, raw, f"{where}/{src}")
        return cls(name, params, sources)

    def default_value(self) -> int:
        track = self.params.track_unknown_space
        if track is None:
            track = bool(self.layered and self.layered.track_unknown_space)
        return NO_INFORMATION if track else FREE_SPACE

    def add_observation(self, source: str, origin: Any, points: Any, stamp: float = 0.0):
        """Feed one reading of ``source``: origin (3,) and points (N, 3) in the global frame."""
        if source not in self.buffers:
            raise CostmapError(
                f"{self.name}: no observation source '{source}'; known: "
                f"{', '.join(self.buffers) or 'none (set observation_sources)'}"
            )
        self.buffers[source].add(origin, points, stamp)

    def reset(self) -> None:
        super().reset()
        for b in self.buffers.values():
            b.observations = []

    # -- the update ---------------------------------------------------------------------------
    def update_bounds(self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds):
        lc = self.layered
        assert lc is not None
        if lc.rolling_window:
            self.grid.update_origin(
                robot_x - self.grid.size_in_meters_x / 2, robot_y - self.grid.size_in_meters_y / 2
            )
        self._robot = (robot_x, robot_y, robot_yaw)
        if not self.enabled:
            return
        for buf in self.buffers.values():
            if buf.params.clearing:
                for obs in buf.observations:
                    self.raytrace_freespace(obs, bounds)
        for buf in self.buffers.values():
            if buf.params.marking:
                for obs in buf.observations:
                    self.mark(obs, bounds)
        if self.params.footprint_clearing_enabled:
            poly = footprint_at(lc.footprint, robot_x, robot_y, robot_yaw)
            bounds.include(*poly.min(axis=0), *poly.max(axis=0))

    def marking_points(self, obs: Observation) -> tuple[np.ndarray, np.ndarray]:
        """The points of ``obs`` that mark: within obstacle_range, under max_obstacle_height
        and on the grid; returns them (K, 3) and their cells (K, 2) (x, y indices)."""
        g = self.grid
        return _marking(
            np.ascontiguousarray(obs.points, dtype=np.float64),
            np.asarray(obs.origin, dtype=np.float64),
            float(self.params.max_obstacle_height),
            float(obs.obstacle_range**2),
            g.origin_x,
            g.origin_y,
            g.resolution,
            g.size_x,
            g.size_y,
        )

    def mark(self, obs: Observation, bounds: Bounds) -> None:
        """Set the cells of points within range and under max_obstacle_height to LETHAL."""
        pts, cells = self.marking_points(obs)
        if cells.shape[0] == 0:
            return
        self.grid.costs[cells[:, 1], cells[:, 0]] = LETHAL_OBSTACLE
        lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
        bounds.include(lo[0], lo[1], hi[0], hi[1])

    def raytrace_freespace(self, obs: Observation, bounds: Bounds) -> None:
        """Clear the cells between the sensor and each point, up to raytrace_range."""
        g = self.grid
        start = g.world_to_map(obs.origin[0], obs.origin[1])
        if start is None:
            _log.warning(
                "%s: the sensor origin (%.2f, %.2f) is outside the costmap; it cannot clear",
                self.name,
                obs.origin[0],
                obs.origin[1],
            )
            return
        if obs.points.shape[0] == 0:
            return
        lo = (g.origin_x, g.origin_y)
        hi = (g.origin_x + g.size_x * g.resolution, g.origin_y + g.size_y * g.resolution)
        ox, oy = float(obs.origin[0]), float(obs.origin[1])
        clear_along_rays(
            g.costs, ox, oy, obs.points, lo[0], lo[1], hi[0], hi[1], g.resolution,
            start[0], start[1], g.cell_distance(obs.raytrace_range), FREE_SPACE,
        )  # fmt: skip
        r = obs.raytrace_range
        bounds.include(
            max(ox - r, lo[0]), max(oy - r, lo[1]), min(ox + r, hi[0]), min(oy + r, hi[1])
        )

    def clear_cells(self, rows: np.ndarray, cols: np.ndarray) -> None:
        """Forget the obstacles this layer has marked in these cells (another robot's body
        as this robot's sensors saw it: `RobotsLayer`'s ``clear_robots``). Unknown cells stay
        unknown."""
        cells = self.grid.costs[rows, cols]
        hit = cells == LETHAL_OBSTACLE
        self.grid.costs[rows[hit], cols[hit]] = FREE_SPACE

    def update_costs(self, master, x0: int, y0: int, xn: int, yn: int) -> None:
        if not self.enabled or xn <= x0 or yn <= y0:
            return
        if self.params.footprint_clearing_enabled:
            x, y, yaw = self._robot
            rows, cols = polygon_cells(self.grid, footprint_at(self.layered.footprint, x, y, yaw))
            self.grid.costs[rows, cols] = FREE_SPACE
        if self.params.combination_method == 0:
            self.update_with_overwrite(master, x0, y0, xn, yn)
        else:
            self.update_with_max(master, x0, y0, xn, yn)


@njit(cache=True)
def _marking(pts, origin, max_height, range2, ox, oy, res, size_x, size_y):
    """`ObstacleLayer.marking_points` compiled (every costmap update of every robot): points
    (N, 3) with ``z <= max_height``, squared distance to ``origin`` (3,) below ``range2`` and a
    cell on the grid, with their cells (K, 2) int64, in their order. The same floats as the
    NumPy form: the squared distance summed x, y, z in turn, cells by `cells_from_points`."""
    keep = np.empty(pts.shape[0], np.int64)
    cells = np.empty((pts.shape[0], 2), np.int64)
    n = 0
    for i in range(pts.shape[0]):
        dx = pts[i, 0] - origin[0]
        dy = pts[i, 1] - origin[1]
        dz = pts[i, 2] - origin[2]
        if not (pts[i, 2] <= max_height and dx * dx + dy * dy + dz * dz < range2):
            continue
        mx = math.floor((pts[i, 0] - ox) / res)
        my = math.floor((pts[i, 1] - oy) / res)
        if mx >= 0 and my >= 0 and mx < size_x and my < size_y:
            keep[n] = i
            cells[n, 0] = mx
            cells[n, 1] = my
            n += 1
    out = np.empty((n, 3))
    for k in range(n):
        out[k] = pts[keep[k]]
    return out, cells[:n].copy()


@njit(cache=True)
def _in_height_band(pts, lo, hi):
    """The points (N, 3) with ``lo <= z <= hi``, in order (a copy), compiled: every reading
    of every robot's costmaps passes here."""
    keep = np.empty(pts.shape[0], np.bool_)
    n = 0
    for i in range(pts.shape[0]):
        z = pts[i, 2]
        keep[i] = z <= hi and z >= lo
        n += keep[i]
    out = np.empty((n, 3))
    k = 0
    for i in range(pts.shape[0]):
        if keep[i]:
            out[k, 0] = pts[i, 0]
            out[k, 1] = pts[i, 1]
            out[k, 2] = pts[i, 2]
            k += 1
    return out
