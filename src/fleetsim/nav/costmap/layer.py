"""The costmap layer plugin base class, as costmap_2d's Layer / CostmapLayer.

A layered costmap update runs in two passes over its plugins, in order:

1. ``update_bounds(robot_x, robot_y, robot_yaw, bounds)`` - each layer updates its own state
   and grows the world-frame box that needs recomputing;
2. ``update_costs(master, x0, y0, xn, yn)`` - each layer writes its costs into the master grid
   for cells ``[x0, xn) x [y0, yn)``.

`CostmapLayer` is a layer that keeps its own grid the size of the master and offers
costmap_2d's ways of combining it into the master (true overwrite, overwrite, maximum).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from fleetsim.nav.costmap.costmap_2d import NO_INFORMATION, Costmap2D

if TYPE_CHECKING:
    from fleetsim.nav.costmap.layered_costmap import LayeredCostmap


@dataclass
class Bounds:
    """A world-frame box (m) that needs its costs recomputed; empty when min > max."""

    min_x: float = np.inf
    min_y: float = np.inf
    max_x: float = -np.inf
    max_y: float = -np.inf

    def touch(self, x: float, y: float) -> None:
        self.min_x, self.min_y = min(self.min_x, x), min(self.min_y, y)
        self.max_x, self.max_y = max(self.max_x, x), max(self.max_y, y)

    def include(self, min_x: float, min_y: float, max_x: float, max_y: float) -> None:
        self.touch(min_x, min_y)
        self.touch(max_x, max_y)

    @property
    def empty(self) -> bool:
        return self.min_x > self.max_x or self.min_y > self.max_y


class Layer:
    """One costmap plugin. Subclasses override the hooks they need."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.enabled = True
        self.current = True
        self.layered: LayeredCostmap | None = None

    def initialize(self, layered: LayeredCostmap) -> None:
        """Attach to the layered costmap (called once, in plugin order)."""
        self.layered = layered

    def match_size(self) -> None:
        """The master grid changed size, resolution or origin."""

    def on_footprint_changed(self) -> None:
        """The robot footprint (and so the inscribed radius) changed."""

    def reset(self) -> None:
        """Forget everything sensed (clear_costmaps)."""

    def update_bounds(self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds):
        """Update internal state and grow ``bounds`` to cover every cell that changed."""

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        """Write this layer's costs into ``master`` for cells ``[x0, xn) x [y0, yn)``."""


def combined_max(master: np.ndarray, layer: np.ndarray) -> np.ndarray:
    """costmap_2d's updateWithMax: layer cells that are known and higher win.

    master, layer : same-shape uint8 windows. Returns the new master window.
    """
    take = (layer != NO_INFORMATION) & ((master == NO_INFORMATION) | (master < layer))
    return np.where(take, layer, master)


@njit(cache=True)
def combine_max_into(master, layer, unknown):
    """`combined_max` written into ``master`` in place, compiled (every obstacle layer's update
    of every robot; NumPy's five passes and a copy cost ~20 us a window)."""
    for r in range(master.shape[0]):
        for c in range(master.shape[1]):
            v = layer[r, c]
            m = master[r, c]
            if v != unknown and (m == unknown or m < v):
                master[r, c] = v


def combined_overwrite(master: np.ndarray, layer: np.ndarray) -> np.ndarray:
    """costmap_2d's updateWithOverwrite: every known layer cell replaces the master's."""
    return np.where(layer != NO_INFORMATION, layer, master)


class CostmapLayer(Layer):
    """A layer with its own grid, kept the size, resolution and origin of the master."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.grid = Costmap2D(0, 0, 1.0)

    def default_value(self) -> int:
        return NO_INFORMATION

    def match_size(self) -> None:
        assert self.layered is not None
        m = self.layered.costmap
        self.grid.default_value = self.default_value()
        self.grid.resize_map(m.size_x, m.size_y, m.resolution, m.origin_x, m.origin_y)

    def reset(self) -> None:
        self.grid.reset_map()

    def update_with_true_overwrite(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int):
        master.costs[y0:yn, x0:xn] = self.grid.costs[y0:yn, x0:xn]

    def update_with_overwrite(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int):
        w = np.s_[y0:yn, x0:xn]
        master.costs[w] = combined_overwrite(master.costs[w], self.grid.costs[w])

    def update_with_max(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int):
        w = np.s_[y0:yn, x0:xn]
        combine_max_into(master.costs[w], self.grid.costs[w], NO_INFORMATION)

    def clear_area(self, x0: int, y0: int, xn: int, yn: int, invert: bool = False) -> None:
        """Set cells to NO_INFORMATION outside (or, ``invert``, inside) the open box.

        As CostmapLayer::clearArea: a cell is kept when ``x0 < x < xn and y0 < y < yn``
        (strict), unless ``invert``.
        """
        g = self.grid.costs
        xs = np.arange(g.shape[1])
        ys = np.arange(g.shape[0])
        inside = ((ys > y0) & (ys < yn))[:, None] & ((xs > x0) & (xs < xn))[None, :]
        g[inside == invert] = NO_INFORMATION
