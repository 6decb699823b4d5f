"""Per-particle hit maps that share memory: copy-on-write tiles, as gmapping's
``HierarchicalArray2D`` of reference-counted patches.

Every particle has a table of tile indices (``table[p, ty, tx]``, -1 where it never saw a hit)
into one pool of ``TILE x TILE`` tiles. Resampling copies tables, not tiles: the copies share
their tiles (the reference count goes up). Registering a scan copies only the tiles it writes
to that another particle also holds. The map grows by whole tiles, so a cell's own corner (from
which its hit offsets are measured) never moves.
"""

from __future__ import annotations

import math

import numpy as np

from .scan_match import TILE, add_hits


class TiledHitMaps:
    """Endpoint (hit) maps of ``particles`` particles over the extent ``[x0, x1] x [y0, y1]``."""

    def __init__(
        self, particles: int, x0: float, y0: float, x1: float, y1: float, delta: float
    ) -> None:
        self.delta = float(delta)
        tx = max(1, math.ceil((x1 - x0) / (delta * TILE)))
        ty = max(1, math.ceil((y1 - y0) / (delta * TILE)))
        self.geom = np.array([float(x0), float(y0), self.delta])
        self.table = np.full((particles, ty, tx), -1, dtype=np.int32)
        self.pool = np.zeros((64, TILE, TILE, 3), dtype=np.float32)
        self.refs = np.zeros(64, dtype=np.int64)

    # ----- geometry -----
    @property
    def shape_cells(self) -> tuple[int, int]:
        """``(height, width)`` in cells."""
        return self.table.shape[1] * TILE, self.table.shape[2] * TILE

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(x0, y0, x1, y1)`` in m."""
        h, w = self.shape_cells
        x0, y0 = self.geom[0], self.geom[1]
        return x0, y0, x0 + w * self.delta, y0 + h * self.delta

    def growth_for(
        self, xmin: float, ymin: float, xmax: float, ymax: float, step: float
    ) -> tuple[int, int, int, int]:
        """Tiles to add ``(left, bottom, right, top)`` so that the box fits with ``step`` m to
        spare beyond it (gmapping's ``enlargeStep``); all zeros when it fits already."""
        x0, y0, x1, y1 = self.bounds
        span = self.delta * TILE

        def tiles(need: float) -> int:
            return math.ceil((need + step) / span) if need > 0 else 0

        return tiles(x0 - xmin), tiles(y0 - ymin), tiles(xmax - x1), tiles(ymax - y1)

    def grow(self, left: int, bottom: int, right: int, top: int) -> None:
        """Add whole tiles on each side (unset)."""
        self.table = np.pad(self.table, ((0, 0), (bottom, top), (left, right)), constant_values=-1)
        self.geom[0] -= left * TILE * self.delta
        self.geom[1] -= bottom * TILE * self.delta

    # ----- particles -----
    def resample(self, indices: np.ndarray) -> None:
        """Particle i becomes a copy of old particle ``indices[i]`` (tiles shared)."""
        self.table = self.table[np.asarray(indices)]
        used = self.table[self.table >= 0]
        self.refs = np.bincount(used, minlength=len(self.pool)).astype(np.int64)

    def _allocate(self, count: int) -> np.ndarray:
        free = np.flatnonzero(self.refs == 0)
        if len(free) < count:
            old = len(self.pool)
            new = max(2 * old, old + count - len(free))
            self.pool = np.concatenate(
                [self.pool, np.zeros((new - old, TILE, TILE, 3), dtype=np.float32)]
            )
            self.refs = np.concatenate([self.refs, np.zeros(new - old, dtype=np.int64)])
            free = np.flatnonzero(self.refs == 0)
        return free[:count]

    def add_scan(self, cells: np.ndarray, hits: np.ndarray) -> None:
        """Register endpoints: ``cells`` (P, B, 2) int cells and ``hits`` (P, B, 2) m, all
        inside the map (grow it first)."""
        if cells.shape[1] == 0:
            return
        n, ty, tx = self.table.shape
        p = np.repeat(np.arange(n), cells.shape[1])
        keys = np.unique(
            (p * ty + (cells[..., 1].ravel() // TILE)) * tx + (cells[..., 0].ravel() // TILE)
        )
        flat = self.table.reshape(-1)
        tiles = flat[keys]
        shared = np.zeros(len(keys), dtype=bool)
        held = tiles >= 0
        shared[held] = self.refs[tiles[held]] > 1
        need = ~held | shared
        new = self._allocate(int(need.sum()))
        src = tiles[need]
        copy = src >= 0
        self.pool[new] = 0.0
        self.pool[new[copy]] = self.pool[src[copy]]
        np.subtract.at(self.refs, src[copy], 1)
        self.refs[new] = 1
        flat[keys[need]] = new
        add_hits(self.pool, self.table, cells, hits, self.geom)

    @property
    def tiles_in_use(self) -> int:
        return int(np.count_nonzero(self.refs))
