"""One MPPIController cycle with batch_size 2000 x time_steps 56 (model_dt 0.05), one core.

Local costmap 4 x 4 m at 0.05 m (rolling window, inflation 0.55 m) on the Willow map, robot
radius 0.15, navfn plan; the critics of Nav2's README example (CostCritic with the footprint).
``--jackal``: the BARN jackal's padded 0.62 x 0.54 m rectangle with its 0.30 m inflation, which
falls short of its corners (its footprint is laid wherever a lethal cell is within reach).
``--centre``: CostCritic without the footprint (the centre cell's cost decides, as the lizi's
shipped ``mppi_params.yaml`` and Nav2's advice for an inflation covering the robot).
The process is pinned to one CPU and numba runs single-threaded. Prints the median and p95 of
compute_velocity_commands over 100 cycles, wall and thread CPU time (target <= 10 ms; Nav2 runs
it at 30-50 Hz in C++).

    PYTHONPATH=src .venv/bin/python benchmarks/mppi_cycle.py [--batch-size 2000]
"""

import argparse
import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import time
from pathlib import Path

import numpy as np

from fleetsim.nav.controllers.mppi import MPPIController, load_mppi
from fleetsim.nav.costmap import LayeredCostmap
from fleetsim.nav.map_io import load_map
from fleetsim.nav.planners import NavFn

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[1].parent / "shared"
CRITICS = [
    "ConstraintCritic", "CostCritic", "GoalCritic", "GoalAngleCritic", "PathAlignCritic",
    "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic",
]  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--batch-size", type=int, default=2000)
    ap.add_argument("--time-steps", type=int, default=56)
    ap.add_argument("--cycles", type=int, default=100)
    ap.add_argument("--jackal", action="store_true", help="the BARN jackal's footprint")
    ap.add_argument(
        "--centre",
        action="store_true",
        help="CostCritic consider_footprint false (the lizi's shipped mppi_params.yaml)",
    )
    a = ap.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    m = load_map(str(SHARED / "data/maps/willow-full.yaml"))
    glob = LayeredCostmap.from_params({"robot_radius": 0.15, "observation_sources": ""}, "g")
    glob.set_map(m)
    glob.update_map(0, 0, 0)
    robot = {"robot_radius": 0.15}
    if a.jackal:
        robot = {"footprint": [[-0.26, -0.22], [-0.26, 0.22], [0.26, 0.22], [0.26, -0.22]],
                 "footprint_padding": 0.05, "inflation_radius": 0.30}  # fmt: skip
    local = LayeredCostmap.from_params(
        {"rolling_window": True, "width": 4.0, "height": 4.0, "resolution": 0.05,
         "observation_sources": "", **robot},
        "local_costmap",
    )  # fmt: skip
    local.set_map(m)
    start = (20.6, 15.0, 0.0)
    path = NavFn(glob.costmap).create_plan(start, (40.0, 40.0, 0.0))
    ns = {
        "batch_size": a.batch_size,
        "time_steps": a.time_steps,
        "critics": CRITICS,
        "CostCritic": {"consider_footprint": not a.centre, "near_goal_distance": 1.0},
        "controller_frequency": 20.0,
    }
    params, ack, critics = load_mppi(ns, "benchmark/MPPIController")

    class _Costmap:  # what from_namespace reads of a Costmap2DROS
        costmap, footprint, layered = local.costmap, local.footprint, local

    class _Node:
        class runtime:  # noqa: N801
            rng = staticmethod(lambda name: np.random.default_rng(0))

    ctl = MPPIController.from_namespace(_Node, _Costmap, ns, "benchmark/MPPIController")
    ctl.set_plan(path)
    local.update_map(*start)
    ctl.compute_velocity_commands(start, (0.0, 0.0, 0.0))  # compile
    x, y, th = start
    v = (0.0, 0.0, 0.0)
    times, cpu = [], []
    for _ in range(a.cycles):
        local.update_map(x, y, th)
        t, c = time.perf_counter(), time.thread_time()
        cmd = ctl.compute_velocity_commands((x, y, th), v)
        times.append(time.perf_counter() - t)
        cpu.append(time.thread_time() - c)
        x += cmd.vx * np.cos(th) * 0.05
        y += cmd.vx * np.sin(th) * 0.05
        th += cmd.vtheta * 0.05
        v = cmd
    ms, cpu_ms = np.array(times) * 1e3, np.array(cpu) * 1e3
    robot_kind = "jackal" if a.jackal else "r 0.15"
    robot_kind += " centre cell only" if a.centre else " footprint"
    print(
        f"MPPIController cycle, {params.batch_size} samples x {params.time_steps} steps, "
        f"{len(critics)} critics, {robot_kind}, one core (target <= 10 ms):\n"
        f"  wall: median {np.median(ms):.2f} ms, p95 {np.percentile(ms, 95):.2f} ms\n"
        f"  CPU (the thread's own, less disturbed by other load): median "
        f"{np.median(cpu_ms):.2f} ms, p95 {np.percentile(cpu_ms, 95):.2f} ms\n"
        f"  robot moved to ({x:.2f}, {y:.2f}); load average {os.getloadavg()[0]:.1f}"
    )


if __name__ == "__main__":
    main()
