"""Costmap2D: a uint8 cost grid with a resolution and an origin, as costmap_2d's Costmap2D.

Costs: ``FREE_SPACE`` 0, ``INSCRIBED_INFLATED_OBSTACLE`` 253, ``LETHAL_OBSTACLE`` 254,
``NO_INFORMATION`` 255. The grid is ``costs[my, mx]`` (rows are y, columns x), cell (0, 0)'s
lower-left corner at ``(origin_x, origin_y)`` in the costmap's global frame, no rotation.
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.nav.errors import CostmapError

FREE_SPACE = 0
INSCRIBED_INFLATED_OBSTACLE = 253
LETHAL_OBSTACLE = 254
NO_INFORMATION = 255


def cells_from_points(
    points: np.ndarray, origin: tuple[float, float], resolution: float
) -> np.ndarray:
    """Map cells ``(mx, my)`` of world points, without bounds checks (worldToMapNoBounds).

    points : (..., 2) x, y in the costmap frame, m. Returns (..., 2) int64 (floor division).
    """
    p = np.asarray(points, dtype=np.float64)
    ox, oy = origin
    out = np.empty(p.shape, dtype=np.int64)
    out[..., 0] = np.floor((p[..., 0] - ox) / resolution)
    out[..., 1] = np.floor((p[..., 1] - oy) / resolution)
    return out


def points_from_cells(
    cells: np.ndarray, origin: tuple[float, float], resolution: float
) -> np.ndarray:
    """World coordinates of cell centres. cells : (..., 2) (mx, my). Returns (..., 2) m."""
    c = np.asarray(cells, dtype=np.float64)
    return np.stack(
        (origin[0] + (c[..., 0] + 0.5) * resolution, origin[1] + (c[..., 1] + 0.5) * resolution),
        axis=-1,
    )


def lookup_bytes(data: np.ndarray, table: np.ndarray) -> np.ndarray:
    """``table[data]``, shaped as ``data``: each value of ``data`` read as an unsigned byte (int8
    -1 is 255; wider integers keep their low byte) replaced by its entry in the (256,) byte
    ``table`` (uint8 or int8).

    OpenCV's LUT, not NumPy's gather: the gather widens every index to 8 bytes first, and on a
    2000 x 2000 SLAM map, translated at every map and every costmap publication, it took
    9.7 ms against LUT's 1.2 ms."""
    a = np.ascontiguousarray(data)
    a = a.view(np.uint8) if a.dtype.itemsize == 1 else (a.astype(np.int64) & 0xFF).astype(np.uint8)
    if a.size == 0:
        return table[a]
    import cv2  # here: OpenCV loads in ~0.1 s, paid only by processes that translate maps

    return cv2.LUT(a.reshape(-1, a.shape[-1]) if a.ndim >= 2 else a.reshape(-1, 1), table).reshape(
        a.shape
    )


def shifted_grid(grid: np.ndarray, cell_ox: int, cell_oy: int, fill: int) -> np.ndarray:
    """A grid moved by (cell_ox, cell_oy) cells: new[y, x] = old[y + cell_oy, x + cell_ox].

    grid : (size_y, size_x, ...) array. Cells with no old counterpart get ``fill``.
    """
    new = np.full_like(grid, fill)
    sy, sx = grid.shape[:2]
    lx0, ly0 = max(cell_ox, 0), max(cell_oy, 0)
    ux, uy = min(cell_ox + sx, sx), min(cell_oy + sy, sy)
    if ux > lx0 and uy > ly0:
        new[ly0 - cell_oy : uy - cell_oy, lx0 - cell_ox : ux - cell_ox] = grid[ly0:uy, lx0:ux]
    return new


class Costmap2D:
    """A 2-D cost grid: ``costs`` (size_y, size_x) uint8, ``resolution`` m, ``origin`` m."""

    def __init__(
        self,
        size_x: int,
        size_y: int,
        resolution: float,
        origin_x: float = 0.0,
        origin_y: float = 0.0,
        default_value: int = FREE_SPACE,
    ) -> None:
        if not (resolution > 0 and math.isfinite(resolution)):
            raise CostmapError(f"costmap resolution must be > 0 m, got {resolution!r}")
        if size_x < 0 or size_y < 0:
            raise CostmapError(f"costmap size must be >= 0 cells, got {size_x} x {size_y}")
        self.resolution = float(resolution)
        self.origin_x = float(origin_x)
        self.origin_y = float(origin_y)
        self.default_value = int(default_value)
        self.costs = np.full((int(size_y), int(size_x)), self.default_value, dtype=np.uint8)

    # -- geometry ---------------------------------------------------------------------------
    @property
    def size_x(self) -> int:
        return int(self.costs.shape[1])

    @property
    def size_y(self) -> int:
        return int(self.costs.shape[0])

    @property
    def size_in_meters_x(self) -> float:
        return (self.size_x - 1 + 0.5) * self.resolution

    @property
    def size_in_meters_y(self) -> float:
        return (self.size_y - 1 + 0.5) * self.resolution

    @property
    def origin(self) -> tuple[float, float]:
        return (self.origin_x, self.origin_y)

    @property
    def geometry(self) -> tuple[int, int, float, tuple[float, float]]:
        """(size_x, size_y, resolution, origin): equal for two grids whose cells coincide."""
        return (self.size_x, self.size_y, self.resolution, self.origin)

    def cell_distance(self, world_dist: float) -> int:
        """Cells spanned by a world distance (costmap_2d's cellDistance: ceil, >= 0)."""
        return int(max(0.0, math.ceil(world_dist / self.resolution)))

    def world_to_map(self, wx: float, wy: float) -> tuple[int, int] | None:
        """The cell holding a world point, or None outside the grid."""
        if wx < self.origin_x or wy < self.origin_y:
            return None
        mx = int((wx - self.origin_x) / self.resolution)
        my = int((wy - self.origin_y) / self.resolution)
        if mx < self.size_x and my < self.size_y:
            return mx, my
        return None

    def cells_of(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Batched world_to_map: points (N, 2) m -> cells (N, 2) int64 and inside (N,) bool."""
        cells = cells_from_points(points, self.origin, self.resolution)
        inside = (
            (cells[..., 0] >= 0)
            & (cells[..., 1] >= 0)
            & (cells[..., 0] < self.size_x)
            & (cells[..., 1] < self.size_y)
        )
        return cells, inside

    def map_to_world(self, mx: float, my: float) -> tuple[float, float]:
        """World coordinates of a cell's centre."""
        return (
            self.origin_x + (mx + 0.5) * self.resolution,
            self.origin_y + (my + 0.5) * self.resolution,
        )

    # -- content ----------------------------------------------------------------------------
    def get_cost(self, mx: int, my: int) -> int:
        return int(self.costs[my, mx])

    def set_cost(self, mx: int, my: int, cost: int) -> None:
        self.costs[my, mx] = cost

    def reset_map(self, x0: int = 0, y0: int = 0, xn: int | None = None, yn: int | None = None):
        """Set cells ``[x0, xn) x [y0, yn)`` (default: all) to the default value."""
        self.costs[
            y0 : self.size_y if yn is None else yn, x0 : self.size_x if xn is None else xn
        ] = self.default_value

    def resize_map(
        self, size_x: int, size_y: int, resolution: float, origin_x: float, origin_y: float
    ) -> None:
        """Reshape the grid (contents reset to the default value)."""
        if not (resolution > 0 and math.isfinite(resolution)):
            raise CostmapError(f"costmap resolution must be > 0 m, got {resolution!r}")
        self.resolution = float(resolution)
        self.origin_x, self.origin_y = float(origin_x), float(origin_y)
        self.costs = np.full((int(size_y), int(size_x)), self.default_value, dtype=np.uint8)

    def update_origin(self, new_origin_x: float, new_origin_y: float) -> None:
        """Move the grid (rolling window), keeping the cells that stay inside it.

        The new origin is snapped to a whole number of cells from the old one, as costmap_2d
        does, so kept cells keep their exact world positions; newly exposed cells get the
        default value.
        """
        cell_ox = int((new_origin_x - self.origin_x) / self.resolution)
        cell_oy = int((new_origin_y - self.origin_y) / self.resolution)
        if cell_ox == 0 and cell_oy == 0:
            return
        self.costs = shifted_grid(self.costs, cell_ox, cell_oy, self.default_value)
        self.origin_x += cell_ox * self.resolution
        self.origin_y += cell_oy * self.resolution

    def copy(self) -> Costmap2D:
        out = Costmap2D(0, 0, self.resolution, self.origin_x, self.origin_y, self.default_value)
        out.costs = self.costs.copy()
        return out
