"""The voxel layer (costmap_2d::VoxelLayer, ``map_type: voxel``): a column of z voxels per cell.

Each cell holds ``z_voxels`` voxels of height ``z_resolution`` from ``origin_z``, stored as
two bit masks per column (marked, unknown; bit k is voxel k). Voxels start unknown when the
layer tracks unknown space and free otherwise.

Marking sets a point's voxel; clearing walks the 3-D line from the sensor to each point
(x, y in cells, z in voxels, cut at ``raytrace_range``) and frees every voxel on it.

Flattening rule (what the 2-D costmap sees), as costmap_2d's voxel grid:
  * a cell is LETHAL when more than ``mark_threshold`` voxels of its column are marked;
  * a column touched by clearing whose marked count is at most ``mark_threshold`` becomes
    FREE when at most ``unknown_threshold`` of its voxels are unknown, else NO_INFORMATION.
Heights outside the column: costmap_2d drops points (and whole sensors) whose z falls outside
``[origin_z, origin_z + z_voxels * z_resolution)``; here their z is clamped into the column
instead, so a planar laser mounted above the column still marks and clears (the top voxel).
Points are still filtered by ``min/max_obstacle_height`` first, exactly as in costmap_2d.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from fleetsim.nav.costmap.costmap_2d import (
    FREE_SPACE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    shifted_grid,
)
from fleetsim.nav.costmap.layer import Bounds
from fleetsim.nav.costmap.obstacle_layer import Observation, ObstacleLayer, ObstacleLayerParams
from fleetsim.nav.costmap.raytrace import ray_ends_clipped
from fleetsim.runtime import param


@dataclass(frozen=True)
class VoxelLayerParams(ObstacleLayerParams):
    """ObstacleLayer's parameters plus the voxel column's."""

    origin_z: float = param(0.0, unit="m", help="height of the bottom of the voxel column")
    z_resolution: float = param(0.2, unit="m", range=(1e-6, None), help="voxel height")
    z_voxels: int = param(10, range=(1, 16), help="voxels per column (at most 16)")
    unknown_threshold: int = param(
        15, range=(0, 16), help="unknown voxels a column may hold and still be known"
    )
    mark_threshold: int = param(
        0, range=(0, 16), help="marked voxels a column may hold and still be free"
    )
    publish_voxel_map: bool = param(False, help="publish the voxel grid (for viewing)")


@njit(cache=True)
def _popcount16(v):
    n = 0
    while v:
        v &= v - 1
        n += 1
    return n


@njit(cache=True)
def clear_voxel_rays(
    marked, unknown, costs, start, ends, max_length, mark_threshold, unknown_threshold
):
    """Free the voxels on 3-D lines from ``start`` to each end; re-flatten touched columns.

    Parameters
    ----------
    marked, unknown : (size_y, size_x) uint16 voxel bit masks, modified in place.
    costs : (size_y, size_x) uint8 layer grid, modified in place (the flattening rule).
    start : (3,) float start in grid units (x, y cells; z voxels).
    ends : (N, 3) float ends in grid units, inside the grid.
    max_length : ray length limit in xy cells.
    """
    sy, sx = costs.shape
    for i in range(ends.shape[0]):
        dx = ends[i, 0] - start[0]
        dy = ends[i, 1] - start[1]
        dz = ends[i, 2] - start[2]
        n = math.ceil(max(abs(dx), abs(dy), abs(dz)))
        dist = math.hypot(dx, dy)
        scale = 1.0 if dist == 0.0 else min(1.0, max_length / dist)
        steps = int(scale * n)
        for k in range(steps + 1):
            t = k / n if n > 0 else 0.0
            x = math.floor(start[0] + dx * t)
            y = math.floor(start[1] + dy * t)
            z = math.floor(start[2] + dz * t)
            if x < 0 or y < 0 or x >= sx or y >= sy:
                continue
            bit = np.uint16(1 << z)
            marked[y, x] &= ~bit
            unknown[y, x] &= ~bit
            if _popcount16(marked[y, x]) <= mark_threshold:
                if _popcount16(unknown[y, x]) <= unknown_threshold:
                    costs[y, x] = 0
                else:
                    costs[y, x] = 255


class VoxelLayer(ObstacleLayer):
    """An obstacle layer that keeps a voxel column per cell (see the module's flattening rule)."""

    Params = VoxelLayerParams

    def __init__(
        self, name: str = "obstacle_layer", params: VoxelLayerParams | None = None, sources=None
    ) -> None:
        super().__init__(name, params or VoxelLayerParams(), sources)
        self.marked = np.zeros((0, 0), np.uint16)
        self.unknown = np.zeros((0, 0), np.uint16)

    def _unknown_fill(self) -> int:
        return (1 << self.params.z_voxels) - 1 if self.default_value() == NO_INFORMATION else 0

    def match_size(self) -> None:
        super().match_size()
        shape = self.grid.costs.shape
        self.marked = np.zeros(shape, np.uint16)
        self.unknown = np.full(shape, self._unknown_fill(), np.uint16)

    def reset(self) -> None:
        super().reset()
        self.marked[:] = 0
        self.unknown[:] = self._unknown_fill()

    def _z_index(self, z: np.ndarray) -> np.ndarray:
        p = self.params
        return np.clip((np.asarray(z) - p.origin_z) / p.z_resolution, 0.0, p.z_voxels - 1e-6)

    def update_bounds(self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds):
        if self.layered is not None and self.layered.rolling_window:
            g = self.grid
            new_x = robot_x - g.size_in_meters_x / 2
            new_y = robot_y - g.size_in_meters_y / 2
            cx = int((new_x - g.origin_x) / g.resolution)
            cy = int((new_y - g.origin_y) / g.resolution)
            self.marked = shifted_grid(self.marked, cx, cy, 0)
            self.unknown = shifted_grid(self.unknown, cx, cy, self._unknown_fill())
        super().update_bounds(robot_x, robot_y, robot_yaw, bounds)

    def mark(self, obs: Observation, bounds: Bounds) -> None:
        pts, cells = self.marking_points(obs)
        if cells.shape[0] == 0:
            return
        bits = (1 << self._z_index(pts[:, 2]).astype(np.int64)).astype(np.uint16)
        rows, cols = cells[:, 1], cells[:, 0]
        np.bitwise_or.at(self.marked, (rows, cols), bits)
        np.bitwise_and.at(self.unknown, (rows, cols), ~bits)
        counts = np.bitwise_count(self.marked[rows, cols])
        hit = counts > self.params.mark_threshold
        self.grid.costs[rows[hit], cols[hit]] = LETHAL_OBSTACLE
        lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
        bounds.include(lo[0], lo[1], hi[0], hi[1])

    def raytrace_freespace(self, obs: Observation, bounds: Bounds) -> None:
        g = self.grid
        if g.world_to_map(obs.origin[0], obs.origin[1]) is None or obs.points.shape[0] == 0:
            return
        lo = np.array(g.origin)
        hi = lo + np.array([g.size_x, g.size_y]) * g.resolution
        ends_xy = ray_ends_clipped(obs.origin, obs.points, lo, hi)
        # z along the clipped ray keeps the original slope
        full = np.hypot(*(obs.points[:, :2] - obs.origin[:2]).T)
        part = np.hypot(*(ends_xy - obs.origin[:2]).T)
        frac = np.divide(part, full, out=np.ones_like(full), where=full > 0)
        ends_z = obs.origin[2] + (obs.points[:, 2] - obs.origin[2]) * frac
        ends = np.empty((ends_xy.shape[0], 3))
        ends[:, :2] = (ends_xy - lo) / g.resolution
        ends[:, 2] = self._z_index(ends_z)
        start = np.array(
            [
                (obs.origin[0] - lo[0]) / g.resolution,
                (obs.origin[1] - lo[1]) / g.resolution,
                float(self._z_index(obs.origin[2])),
            ]
        )
        clear_voxel_rays(
            self.marked,
            self.unknown,
            g.costs,
            start,
            np.ascontiguousarray(ends),
            float(g.cell_distance(obs.raytrace_range)),
            self.params.mark_threshold,
            self.params.unknown_threshold,
        )
        r = obs.raytrace_range
        ox, oy = obs.origin[0], obs.origin[1]
        bounds.include(
            max(ox - r, lo[0]), max(oy - r, lo[1]), min(ox + r, hi[0]), min(oy + r, hi[1])
        )

    def clear_cells(self, rows: np.ndarray, cols: np.ndarray) -> None:
        """Forget the marked voxels of these columns, and the obstacles they made."""
        self.marked[rows, cols] = 0
        super().clear_cells(rows, cols)

    def update_costs(self, master, x0: int, y0: int, xn: int, yn: int) -> None:
        if self.params.footprint_clearing_enabled and self.layered is not None:
            from fleetsim.nav.costmap.footprint import footprint_at, polygon_cells

            x, y, yaw = self._robot
            rows, cols = polygon_cells(self.grid, footprint_at(self.layered.footprint, x, y, yaw))
            self.marked[rows, cols] = 0
            self.grid.costs[rows, cols] = FREE_SPACE
        super().update_costs(master, x0, y0, xn, yn)
