"""One TrajectoryPlannerROS cycle with vx_samples 10 x vtheta_samples 40, sim_time 2 s.

Local costmap 4 x 4 m at 0.05 m (the tutorial's local_costmap_params) on the Willow map,
robot radius 0.15. Prints the time per compute_velocity_commands (target <= 5 ms).
"""

import time
from pathlib import Path

import numpy as np

from fleetsim.nav.controllers import TrajectoryPlanner, TrajectoryPlannerParams
from fleetsim.nav.costmap import LayeredCostmap
from fleetsim.nav.map_io import load_map
from fleetsim.nav.planners import NavFn

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[1].parent / "shared"


def main() -> None:
    m = load_map(str(SHARED / "data/maps/willow-full.yaml"))
    glob = LayeredCostmap.from_params({"robot_radius": 0.15, "observation_sources": ""}, "g")
    glob.set_map(m)
    glob.update_map(0, 0, 0)
    local = LayeredCostmap.from_params(
        {
            "rolling_window": True,
            "width": 4.0,
            "height": 4.0,
            "resolution": 0.05,
            "robot_radius": 0.15,
            "observation_sources": "",
        },
        "local_costmap",
    )
    local.set_map(m)
    start = (20.6, 15.0, 0.0)
    path = NavFn(glob.costmap).create_plan(start, (40.0, 40.0, 0.0))
    params = TrajectoryPlannerParams(
        vx_samples=10, vtheta_samples=40, sim_time=2.0, holonomic_robot=False, max_vel_x=0.8
    )
    tp = TrajectoryPlanner(local.costmap, local.footprint, params)
    tp.set_plan(path)
    local.update_map(*start)
    tp.compute_velocity_commands(start, (0.0, 0.0, 0.0))  # compile
    x, y, th = start
    v = (0.3, 0.0, 0.0)
    times, cpu = [], []
    for _ in range(60):
        local.update_map(x, y, th)
        t, c = time.perf_counter(), time.process_time()
        cmd = tp.compute_velocity_commands((x, y, th), v)
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        x += cmd.vx * np.cos(th) * 0.1
        y += cmd.vx * np.sin(th) * 0.1
        th += cmd.vtheta * 0.1
        v = cmd
    n = 10 * 40 + 40 + 1
    print(
        f"{n} samples, sim_time 2 s: median {1e3 * np.median(times):.2f} ms, "
        f"best {1e3 * min(times):.2f} ms, worst {1e3 * max(times):.2f} ms per cycle "
        f"(cpu median {1e3 * np.median(cpu):.2f} ms)"
    )


if __name__ == "__main__":
    main()
