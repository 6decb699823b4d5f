"""Batched planar laser casting: 100 robots x 360 beams in the Willow Garage map.

Prints the time per sweep of all robots (static walls on the binned grid + the other robots,
noise and readings included) and, for scale, MuJoCo's per-ray ``mj_ray`` over every geom on a
sample of beams. Target (issue 4): <= 10 ms per sweep of 100 x 360 beams.
Usage: python benchmarks/laser_batch.py [--robots 100] [--repeats 20]
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import mujoco
import numpy as np

from fleetsim.description import load_robot
from fleetsim.sim import Engine
from fleetsim.sim.plugins.laser import LaserPlugin
from sim_rtf import ROBOT, WILLOW, free_poses


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--robots", type=int, default=100)
    ap.add_argument("--repeats", type=int, default=20)
    args = ap.parse_args()
    rng = np.random.default_rng(0)
    engine = Engine(WILLOW, rng=np.random.default_rng(0))
    robot = load_robot(ROBOT)
    entries = engine.spawn_robots(
        [(f"r{i}", robot, p) for i, p in enumerate(free_poses(engine, args.robots, rng))]
    )
    engine.advance(0.1)
    lasers = [p for e in entries for p in e.plugins if isinstance(p, LaserPlugin)]
    beams = sum(lz.samples for lz in lasers)
    engine.lasers.measure(engine, lasers, engine.time)  # compile the kernels
    times = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        engine.lasers.measure(engine, lasers, engine.time)
        times.append(time.perf_counter() - t0)
    occ = engine.lasers.occupancy.occupied
    walls = int(np.sum(engine.geom_model == engine._model_names.index("map_walls")))
    print(
        f"world: Willow map, occupancy grid {occ.shape[1]} x {occ.shape[0]} cells "
        f"({int(occ.sum())} occupied) = {walls} wall boxes in MuJoCo, {args.robots} robots"
    )
    print(
        f"batched sweep: {len(lasers)} lasers x {lasers[0].samples} beams = {beams} rays: "
        f"median {1e3 * np.median(times):.2f} ms, min {1e3 * np.min(times):.2f} ms "
        f"({1e9 * np.median(times) / beams:.0f} ns per ray)"
    )
    # MuJoCo's exact per-ray cast over all geoms, on a sample
    origins, angles, _ = lasers[0].rays(engine)
    n = 360
    gid = np.zeros(1, np.int32)
    t0 = time.perf_counter()
    for o, a in zip(origins[:n], angles[:n]):
        mujoco.mj_ray(
            engine.model, engine.data, o, np.array([np.cos(a), np.sin(a), 0.0]), None, 1, -1, gid
        )
    per_ray = (time.perf_counter() - t0) / n
    print(
        f"mj_ray reference: {1e6 * per_ray:.1f} us per ray -> "
        f"{1e3 * per_ray * beams:.0f} ms for the same sweep"
    )


if __name__ == "__main__":
    main()
