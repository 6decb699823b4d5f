"""The map as amcl sees it: cell states, the obstacle distance field, free cells.

Cells follow ``nav_msgs/OccupancyGrid``: row ``j`` is the y index and column ``i`` the x index,
cell ``(i, j)`` covers ``[ox + i*res, ox + (i+1)*res) x [oy + j*res, oy + (j+1)*res)`` in the map
frame. States follow amcl's ``convertMap``: data 0 is free (-1), data 100 is occupied (+1),
anything else (-1 unknown, 1..99) is unknown (0).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage

from fleetsim.errors import FleetsimError

FREE = -1
UNKNOWN = 0
OCCUPIED = 1


class LocalizationError(FleetsimError):
    """A map, scan or pose that amcl cannot use (missing map, pose outside the map, ...)."""


def distances_to_obstacles(occupied: np.ndarray, resolution: float, max_dist: float) -> np.ndarray:
    """Distance from each cell centre to the nearest occupied cell centre, clipped at max_dist.

    Parameters
    ----------
    occupied : (H, W) bool
        True where the cell is an obstacle.
    resolution : float
        Cell size, m.
    max_dist : float
        Clip distance, m (amcl's ``laser_likelihood_max_dist``).

    Returns
    -------
    (H, W) float64
        Distance in m; 0 on obstacles, ``max_dist`` where no obstacle is closer.
    """
    if not occupied.any():
        return np.full(occupied.shape, float(max_dist))
    dist = ndimage.distance_transform_edt(~occupied) * resolution
    return np.minimum(dist, max_dist)


#: maps shared by amcl nodes: id(message data) -> (data, geometry, AmclMap); a few, oldest out
_SHARED: dict[int, tuple[Any, tuple, Any]] = {}
_SHARED_KEPT = 4


@dataclass(frozen=True, eq=False)
class AmclMap:
    """An occupancy map in amcl's three states, with cached derived fields.

    Attributes
    ----------
    occ_state : (H, W) int8
        -1 free, 0 unknown, +1 occupied.
    resolution : float
        Cell size, m.
    origin_x, origin_y : float
        Map-frame position of the corner of cell (0, 0), m.
    """

    occ_state: np.ndarray
    resolution: float
    origin_x: float = 0.0
    origin_y: float = 0.0
    _cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        occ = np.ascontiguousarray(self.occ_state, dtype=np.int8)
        if occ.ndim != 2 or occ.size == 0:
            raise LocalizationError(
                f"amcl map: occupancy must be a non-empty (height, width) array, "
                f"got shape {occ.shape}"
            )
        if not np.isin(occ, (FREE, UNKNOWN, OCCUPIED)).all():
            raise LocalizationError("amcl map: occ_state values must be -1, 0 or +1")
        if not (np.isfinite(self.resolution) and self.resolution > 0):
            raise LocalizationError(f"amcl map: resolution must be > 0 m, got {self.resolution!r}")
        occ.setflags(write=False)
        object.__setattr__(self, "occ_state", occ)

    @classmethod
    def from_occupancy(
        cls,
        data: np.ndarray,
        width: int,
        height: int,
        resolution: float,
        origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
        source: str = "map",
    ) -> AmclMap:
        """Build from ``OccupancyGrid`` data (int8 row-major, 0..100 or -1).

        ``origin`` is ``(x, y, yaw)`` of cell (0, 0)'s corner; like amcl, a rotated map is not
        supported and raises.
        """
        arr = np.asarray(data)
        if arr.size != width * height or width <= 0 or height <= 0:
            raise LocalizationError(
                f"{source}: data has {arr.size} cells but info says {width} x {height}"
            )
        if abs(origin[2]) > 1e-9:
            raise LocalizationError(
                f"{source}: origin yaw {origin[2]!r} rad is not supported by amcl; "
                "rotate the map image and use yaw 0"
            )
        grid = arr.reshape(height, width).astype(np.int16)
        occ = np.full(grid.shape, UNKNOWN, dtype=np.int8)
        occ[grid == 0] = FREE
        occ[grid == 100] = OCCUPIED
        return cls(occ, float(resolution), float(origin[0]), float(origin[1]))

    @classmethod
    def from_grid_msg(cls, msg: Any, source: str = "map") -> AmclMap:
        """Build from a ``nav_msgs/OccupancyGrid`` message (duck-typed on its fields)."""
        info = msg.info
        pos = info.origin.position
        q = info.origin.orientation
        yaw = float(np.arctan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z)))
        return cls.from_occupancy(
            msg.data, info.width, info.height, info.resolution, (pos.x, pos.y, yaw), source
        )

    @classmethod
    def shared_from_grid_msg(cls, msg: Any, source: str = "map") -> AmclMap:
        """`from_grid_msg`, shared by every amcl in the process that gets the same message
        (the latched map, or map_server's static_map answer: one data array): an AmclMap is
        read only, so N robots' amcls hold one map and one likelihood field, not N."""
        data = msg.data
        hit = _SHARED.get(id(data))
        if hit is not None and hit[0] is data:
            info, origin = msg.info, msg.info.origin
            if hit[1] == (info.width, info.height, info.resolution, origin):
                return hit[2]
        grid = cls.from_grid_msg(msg, source)
        if len(_SHARED) >= _SHARED_KEPT:
            _SHARED.pop(next(iter(_SHARED)))
        _SHARED[id(data)] = (
            data,
            (msg.info.width, msg.info.height, msg.info.resolution, msg.info.origin),
            grid,
        )
        return grid

    @property
    def height(self) -> int:
        return int(self.occ_state.shape[0])

    @property
    def width(self) -> int:
        return int(self.occ_state.shape[1])

    @property
    def occupied(self) -> np.ndarray:
        """(H, W) bool, True on obstacle cells."""
        return self.occ_state == OCCUPIED

    def distance_field(self, max_dist: float) -> np.ndarray:
        """(H, W) float64 distance to the nearest obstacle in m, clipped at ``max_dist``.

        Computed once per ``max_dist`` and cached (amcl's ``map_update_cspace``).
        """
        return self.cached(
            ("dist", float(max_dist)),
            lambda: distances_to_obstacles(self.occupied, self.resolution, float(max_dist)),
        )

    def cached(self, key: tuple, factory):
        """Value derived from this map, computed by ``factory()`` once per ``key``."""
        if key not in self._cache:
            value = factory()
            if isinstance(value, np.ndarray):
                value.setflags(write=False)
            self._cache[key] = value
        return self._cache[key]

    @property
    def free_cells(self) -> np.ndarray:
        """(F, 2) int64 ``(i, j)`` indices of free cells (cached)."""
        if "free" not in self._cache:
            j, i = np.nonzero(self.occ_state == FREE)
            free = np.stack([i, j], axis=1).astype(np.int64)
            free.setflags(write=False)  # shared by the amcls of one map
            self._cache["free"] = free
        return self._cache["free"]

    def cells_from_points(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cell indices ``(i, j)`` (int64, possibly off-map) of map-frame points ``(..., 2)``."""
        xy = np.asarray(xy, dtype=float)
        i = np.floor((xy[..., 0] - self.origin_x) / self.resolution).astype(np.int64)
        j = np.floor((xy[..., 1] - self.origin_y) / self.resolution).astype(np.int64)
        return i, j

    def contains(self, x: float, y: float) -> bool:
        """Whether the map-frame point lies on the map."""
        i, j = self.cells_from_points(np.array([x, y]))
        return bool(0 <= i < self.width and 0 <= j < self.height)

    def random_free_poses(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """(n, 3) poses uniform over free cells (uniform within the cell), yaw in [-pi, pi).

        amcl's ``uniformPoseGenerator``; raises when the map has no free cell.
        """
        free = self.free_cells
        if len(free) == 0:
            raise LocalizationError(
                "amcl map: no free cell to place particles in (all cells occupied/unknown)"
            )
        pick = free[rng.integers(0, len(free), size=n)]
        out = np.empty((n, 3))
        jitter = rng.random((n, 2))
        out[:, 0] = self.origin_x + (pick[:, 0] + jitter[:, 0]) * self.resolution
        out[:, 1] = self.origin_y + (pick[:, 1] + jitter[:, 1]) * self.resolution
        out[:, 2] = rng.random(n) * 2.0 * np.pi - np.pi
        return out
