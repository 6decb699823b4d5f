"""The inflation layer (costmap_2d::InflationLayer): costs that decay away from obstacles.

For a cell at distance d (m, between cell centres) from the nearest LETHAL cell:

* d = 0: LETHAL_OBSTACLE (254);
* d <= inscribed_radius: INSCRIBED_INFLATED_OBSTACLE (253);
* otherwise, up to ``ceil(inflation_radius / resolution)`` cells:
  ``(INSCRIBED - 1) * exp(-cost_scaling_factor * (d - inscribed_radius))``, truncated;
* beyond: no inflation.

Distances are exact Euclidean distances (`squared_distances_to`; costmap_2d's wavefront
approximates the same distance to the nearest obstacle cell).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from fleetsim.nav.costmap.costmap_2d import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from fleetsim.nav.costmap.layer import Bounds, Layer
from fleetsim.runtime import param


@dataclass(frozen=True)
class InflationLayerParams:
    """Parameters of ``costmap_2d::InflationLayer`` (in ``<layer name>/``)."""

    enabled: bool = param(True, help="whether the layer contributes to the costmap")
    inflation_radius: float = param(
        0.55, unit="m", range=(0.0, None), help="distance to which costs are inflated"
    )
    cost_scaling_factor: float = param(
        10.0, unit="1/m", range=(0.0, None), help="exponential decay rate of inflated costs"
    )
    inflate_unknown: bool = param(False, help="also write inflated costs over unknown cells")


def costs_from_distances(
    distances: np.ndarray,
    resolution: float,
    inscribed_radius: float,
    inflation_radius: float,
    cost_scaling_factor: float,
) -> np.ndarray:
    """Inflation costs of distances to the nearest lethal cell.

    distances : (...) distance in cells between cell centres. resolution : m per cell.
    inscribed_radius, inflation_radius : m. cost_scaling_factor : 1/m.
    Returns (...) uint8 costs (0 beyond ``ceil(inflation_radius / resolution)`` cells).
    """
    d = np.asarray(distances, dtype=np.float64)
    meters = d * resolution
    decay = np.exp(-cost_scaling_factor * (meters - inscribed_radius))
    out = ((INSCRIBED_INFLATED_OBSTACLE - 1) * decay).astype(np.int64)
    out = np.where(meters <= inscribed_radius, INSCRIBED_INFLATED_OBSTACLE, out)
    out = np.where(d == 0, LETHAL_OBSTACLE, out)
    cell_radius = max(0.0, np.ceil(inflation_radius / resolution))
    out = np.where(d > cell_radius, 0, out)
    return np.clip(out, 0, 255).astype(np.uint8)


class InflationLayer(Layer):
    """Inflates the LETHAL cells of the master grid by the robot's inscribed radius."""

    Params = InflationLayerParams

    def __init__(self, name: str = "inflation_layer", params: InflationLayerParams | None = None):
        super().__init__(name)
        self.params = params or InflationLayerParams()
        self.enabled = self.params.enabled
        self._need_full = True
        self._table_key: tuple | None = None
        self._table = np.zeros(1, np.uint8)

    @property
    def inscribed_radius(self) -> float:
        return self.layered.inscribed_radius if self.layered is not None else 0.0

    def match_size(self) -> None:
        self._need_full = True

    def on_footprint_changed(self) -> None:
        self._need_full = True

    def reset(self) -> None:
        self._need_full = True

    def update_bounds(self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds):
        if self._need_full:
            m = self.layered.costmap  # type: ignore[union-attr]
            bounds.include(
                m.origin_x,
                m.origin_y,
                m.origin_x + m.size_x * m.resolution,
                m.origin_y + m.size_y * m.resolution,
            )
            self._need_full = False
        elif not bounds.empty:
            r = self.params.inflation_radius
            bounds.include(bounds.min_x - r, bounds.min_y - r, bounds.max_x + r, bounds.max_y + r)

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        if not self.enabled or xn <= x0 or yn <= y0:
            return
        p = self.params
        pad = master.cell_distance(p.inflation_radius) + 1
        # sources out to the inflation radius beyond the window can reach it
        ax0, ay0 = max(x0 - pad, 0), max(y0 - pad, 0)
        axn, ayn = min(xn + pad, master.size_x), min(yn + pad, master.size_y)
        area = master.costs[ay0:ayn, ax0:axn]
        cell_radius = int(max(0.0, np.ceil(p.inflation_radius / master.resolution)))
        key = (master.resolution, self.inscribed_radius, p.inflation_radius, p.cost_scaling_factor)
        if self._table_key != key:  # costs of every squared distance (cells) that inflates
            self._table = costs_from_distances(
                np.sqrt(np.arange(cell_radius * cell_radius + 1, dtype=np.float64)), *key
            )
            self._table_key = key
        _inflate(
            area, y0 - ay0, x0 - ax0, yn - ay0, xn - ax0, self._table,
            LETHAL_OBSTACLE, NO_INFORMATION, INSCRIBED_INFLATED_OBSTACLE, p.inflate_unknown,
            master.costs[y0:yn, x0:xn],
        )  # fmt: skip


@njit(cache=True)
def squared_distances_to(mask):
    """Exact squared Euclidean distance (cells) from each cell to the nearest True cell of
    ``mask`` (H, W); ``-1`` where ``mask`` has none. Felzenszwalb and Huttenlocher's two
    passes (column distances, then the lower envelope of parabolas along rows).

    Written here rather than calling ``scipy.ndimage.distance_transform_edt`` (the same
    distances) because the costmaps of every robot inflate a window several times a second and
    scipy's call plus the NumPy passes around it cost ~0.2 ms a window; compiled, the distance
    transform and the cost lookup together take a fraction of that.
    """
    h, w = mask.shape
    big = (h + w) * (h + w) + 1
    col = np.empty((h, w), np.int64)
    for x in range(w):
        last = -1
        for y in range(h):
            if mask[y, x]:
                last = y
            col[y, x] = y - last if last >= 0 else big
        last = -1
        for y in range(h - 1, -1, -1):
            if mask[y, x]:
                last = y
            if last >= 0 and last - y < col[y, x]:
                col[y, x] = last - y
    out = np.empty((h, w), np.int64)
    v = np.empty(w, np.int64)  # parabola apexes of the lower envelope
    z = np.empty(w + 1, np.float64)  # their boundaries
    f = np.empty(w, np.int64)
    for y in range(h):
        for x in range(w):
            g = col[y, x]
            f[x] = g * g if g < big else big * big
        k = 0
        v[0] = 0
        z[0] = -np.inf
        z[1] = np.inf
        for q in range(1, w):
            s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * (q - v[k]))
            while s <= z[k]:  # z[0] = -inf ends it
                k -= 1
                s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * (q - v[k]))
            k += 1
            v[k] = q
            z[k] = s
            z[k + 1] = np.inf
        k = 0
        for x in range(w):
            while z[k + 1] < x:
                k += 1
            d = (x - v[k]) * (x - v[k]) + f[v[k]]
            out[y, x] = d if d < big * big else -1
    return out


@njit(cache=True)
def _inflate(area, r0, c0, r1, c1, table, lethal, unknown, inscribed, inflate_unknown, out):
    """Inflate the window ``[r0:r1, c0:c1]`` of ``area`` (the master grid around it, uint8)
    into ``out`` (that window of the master grid, written in place): each cell's cost from
    ``table`` by its squared distance to the nearest lethal cell of ``area`` (0 beyond the
    table), kept when higher; an unknown cell takes it only at ``inscribed`` or above (any
    positive cost with ``inflate_unknown``)."""
    lethal_mask = area == lethal
    if not lethal_mask.any():
        return
    d2 = squared_distances_to(lethal_mask)
    n = table.shape[0]
    for r in range(r0, r1):
        for c in range(c0, c1):
            d = d2[r, c]
            cost = table[d] if 0 <= d < n else 0
            old = out[r - r0, c - c0]
            if old == unknown:
                if cost >= inscribed or (inflate_unknown and cost > 0):
                    out[r - r0, c - c0] = cost
            elif cost > old:
                out[r - r0, c - c0] = cost
