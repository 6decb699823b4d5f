"""navfn on the whole Willow Garage map at 0.05 m (the 0.1 m map upsampled x2), corner to corner.

Prints the planning time per query (target <= 100 ms; ROS navfn is reported at ~146 ms for a
75 m path). Asserts nothing about time.
"""

import time
from pathlib import Path

import numpy as np

from fleetsim.nav.costmap import LayeredCostmap
from fleetsim.nav.map_io import OccupancyMap, load_map
from fleetsim.nav.planners import NavFn

#: the Willow map in the shared data folder beside the repository (../shared from its root)
MAP = Path(__file__).resolve().parents[1].parent / "shared/data/maps/willow-full.yaml"


def main() -> None:
    m = load_map(MAP)
    fine = OccupancyMap(np.repeat(np.repeat(m.data, 2, 0), 2, 1), m.resolution / 2, m.origin)
    lc = LayeredCostmap.from_params({"robot_radius": 0.2, "observation_sources": ""}, "global")
    lc.set_map(fine)
    lc.update_map(0.0, 0.0, 0.0)
    nf = NavFn(lc.costmap)
    w, h = lc.costmap.size_x * 0.05, lc.costmap.size_y * 0.05
    queries = {
        "corner to corner (SW -> NE)": ((0.12, 0.12, 0.0), (w - 0.12, h - 0.12, 0.0)),
        "corner to corner (SE -> NW)": ((w - 0.12, 0.12, 0.0), (0.12, h - 0.12, 0.0)),
        "lesson start (20.6, 15) -> (40, 50)": ((20.6, 15.0, 0.0), (40.0, 50.0, 0.0)),
    }
    print(f"map {lc.costmap.size_x} x {lc.costmap.size_y} cells at 0.05 m")
    nf.create_plan(*queries["lesson start (20.6, 15) -> (40, 50)"])  # compile
    for name, (s, g) in queries.items():
        times, cpu = [], []
        for _ in range(5):
            t, c = time.perf_counter(), time.process_time()
            path = nf.create_plan(s, g)
            times.append(time.perf_counter() - t)
            cpu.append(time.process_time() - c)
        print(
            f"{name}: path {path.length:.1f} m, {len(path)} poses, "
            f"median {1e3 * np.median(times):.1f} ms, best {1e3 * min(times):.1f} ms "
            f"(cpu median {1e3 * np.median(cpu):.1f} ms)"
        )


if __name__ == "__main__":
    main()
