"""The inflation layer (costmap_2d::InflationLayer): costs that decay away from obstacles.

For a cell at distance d (m, between cell centres) from the nearest LETHAL cell:

* d = 0: LETHAL_OBSTACLE (254);
* d <= inscribed_radius: INSCRIBED_INFLATED_OBSTACLE (253);
* otherwise, up to ``ceil(inflation_radius / resolution)`` cells:
  ``(INSCRIBED - 1) * exp(-cost_scaling_factor * (d - inscribed_radius))``, truncated;
* beyond: no inflation.

Distances come from scipy's exact Euclidean distance transform (costmap_2d's wavefront
approximates the same distance to the nearest obstacle cell).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

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
        lethal = area == LETHAL_OBSTACLE
        if not lethal.any():
            return
        dist = ndimage.distance_transform_edt(~lethal)
        sub = np.s_[y0 - ay0 : yn - ay0, x0 - ax0 : xn - ax0]
        cost = costs_from_distances(
            dist[sub],
            master.resolution,
            self.inscribed_radius,
            p.inflation_radius,
            p.cost_scaling_factor,
        )
        old = master.costs[y0:yn, x0:xn]
        unknown = old == NO_INFORMATION
        write_unknown = (cost > 0) if p.inflate_unknown else (cost >= INSCRIBED_INFLATED_OBSTACLE)
        new = np.where(unknown, np.where(write_unknown, cost, old), np.maximum(old, cost))
        master.costs[y0:yn, x0:xn] = new
