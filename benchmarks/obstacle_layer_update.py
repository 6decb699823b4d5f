"""Obstacle-layer update from one 720-beam LaserScan on rolling windows of 4x4 to 10x10 m.

Prints the time of the layer's update (clearing + marking) and of the whole costmap update
(with inflation). Target for the layer: <= 5 ms.
"""

import time

import numpy as np

from fleetsim.nav.costmap import LayeredCostmap, laser_scan_points
from fleetsim.nav.costmap.layer import Bounds


def main() -> None:
    rng = np.random.default_rng(0)
    for size in (4.0, 10.0):
        lc = LayeredCostmap.from_params(
            {
                "static_map": False,
                "rolling_window": True,
                "width": size,
                "height": size,
                "resolution": 0.05,
                "robot_radius": 0.2,
                "observation_sources": "scan",
                "scan": {"data_type": "LaserScan", "marking": True, "clearing": True},
                "obstacle_range": 2.5,
                "raytrace_range": 3.0,
            },
            "local_costmap",
        )
        layer = lc.layer("obstacle_layer")
        ranges = rng.uniform(0.3, 6.0, 720)
        pts = laser_scan_points(ranges, -np.pi, 2 * np.pi / 720, 0.05, 10.0)
        pts[:, 2] = 0.2
        lc.add_observation("scan", [0.0, 0.0, 0.2], pts)
        lc.update_map(0.0, 0.0, 0.0)  # compile
        layer_t, full_t = [], []
        for i in range(30):
            x = 0.01 * i
            t = time.perf_counter()
            layer.update_bounds(x, 0.0, 0.0, Bounds())
            layer_t.append(time.perf_counter() - t)
            t = time.perf_counter()
            lc.update_map(x, 0.0, 0.0)
            full_t.append(time.perf_counter() - t)
        print(
            f"{size:.0f}x{size:.0f} m window, 720 beams: obstacle layer "
            f"{1e3 * np.median(layer_t):.2f} ms, whole costmap update "
            f"{1e3 * np.median(full_t):.2f} ms (median of 30)"
        )


if __name__ == "__main__":
    main()
