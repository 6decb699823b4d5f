"""Real-time factor of the simulator: N diff-drive robots with a 360-beam laser at 10 Hz each,
driving in the Willow Garage map (physics, drives, odometry, p3d, lasers; no runtime).

Targets (issue 4): 10 robots >= 10x real time, 100 robots >= 1x, on one core. Each row also
splits the wall time into physics (drive servos + mj_step), sensors (odometry, p3d, joint
states), lasers and other (commands, the stepping loop), and gives MuJoCo's own speed on the same
world (bare ``mj_step``, no plugins) as the baseline: the share of it fleetsim keeps does not
depend on how fast this shared machine happens to be (its speed swings by up to 2x from one
minute to the next, so each size runs ``--repeats`` times; the best and median are printed).
Usage: python benchmarks/sim_rtf.py [--robots 1 10 50 100] [--seconds 5] [--repeats 3]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import mujoco
import numpy as np
from scipy import ndimage

from fleetsim.description import load_robot
from fleetsim.sim import Engine

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[1].parent / "shared"

ROOT = Path(__file__).resolve().parent.parent
WILLOW = Path(SHARED, "data/maps/willow-full.yaml")
ROBOT = ROOT / "tests" / "sim" / "fixtures" / "diffbot.urdf"


def free_poses(engine: Engine, n: int, rng: np.random.Generator, clearance: float = 0.6):
    """``n`` start poses in free space at least ``clearance`` m from walls and each other."""
    grid = engine.world.occupancy
    dist = ndimage.distance_transform_edt(~grid.occupied) * grid.resolution
    rows, cols = np.nonzero(dist > clearance)
    poses: list[tuple] = []
    order = rng.permutation(len(rows))
    for k in order:
        x = grid.origin[0] + (cols[k] + 0.5) * grid.resolution
        y = grid.origin[1] + (rows[k] + 0.5) * grid.resolution
        if all((x - p[0]) ** 2 + (y - p[1]) ** 2 > 1.0 for p in poses):
            poses.append((x, y, 0.0, 0.0, 0.0, float(rng.uniform(-np.pi, np.pi))))
        if len(poses) == n:
            break
    return poses


class PartTimer:
    """Wall time spent inside wrapped callables, by part name (instance attributes wrap the
    engine's own methods, so the engine's work is unchanged)."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    def wrap(self, part: str, fn):
        self.seconds.setdefault(part, 0.0)

        def timed(*args, **kw):
            t0 = time.perf_counter()
            try:
                return fn(*args, **kw)
            finally:
                self.seconds[part] += time.perf_counter() - t0

        return timed


def run(n: int, seconds: float, seed: int = 0) -> dict:
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    engine = Engine(WILLOW, rng=np.random.default_rng(seed))
    robot = load_robot(ROBOT)
    entries = engine.spawn_robots(
        [(f"r{i}", robot, pose) for i, pose in enumerate(free_poses(engine, n, rng))]
    )
    build = time.perf_counter() - t0
    engine.advance(0.2)  # warm-up (numba compile, contacts settle)
    parts = PartTimer()
    engine.step = parts.wrap("physics", engine.step)  # drive servos + mj_step
    engine.due_readings = parts.wrap("sensors", engine.due_readings)  # incl. lasers
    engine.lasers.measure = parts.wrap("lasers", engine.lasers.measure)
    cmds = np.c_[rng.uniform(0.1, 0.5, n), rng.uniform(-0.5, 0.5, n)]
    t0 = time.perf_counter()
    scans = 0
    sim0 = engine.time
    while engine.time - sim0 < seconds - 1e-9:
        if round((engine.time - sim0) / 0.1) % 20 == 0:
            cmds = np.c_[rng.uniform(0.1, 0.5, n), rng.uniform(-0.5, 0.5, n)]
        for e, (vx, wz) in zip(entries, cmds):
            e.plugins[0].command(vx, wz, engine.time)
        readings = engine.advance(0.1)
        scans += sum(1 for r in readings if type(r).__name__ == "ScanReading")
    wall = time.perf_counter() - t0
    sec = parts.seconds
    steps = round(seconds / engine.model.opt.timestep)
    t0 = time.perf_counter()
    for _ in range(steps):  # the baseline: MuJoCo alone on the same world and robots
        mujoco.mj_step(engine.model, engine.data)
    bare = time.perf_counter() - t0
    return {
        "physics_s": sec["physics"],
        "sensors_s": sec["sensors"] - sec["lasers"],
        "lasers_s": sec["lasers"],
        "other_s": wall - sec["physics"] - sec["sensors"],
        "robots": n,
        "build_s": build,
        "sim_s": seconds,
        "wall_s": wall,
        "rtf": seconds / wall,
        "bare_rtf": seconds / bare,
        "scans": scans,
        "contacts": len(engine.contacts()),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--robots", type=int, nargs="+", default=[1, 10, 50, 100])
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    print(
        f"{'robots':>6} {'build s':>8} {'sim s':>6} {'wall s':>7} {'RTF':>7} {'median':>7} "
        f"{'mj_step':>8} {'share':>6} {'scans':>6}   wall s by part: physics (drives + mj_step), "
        "sensors (odometry, p3d, joint states), lasers, other"
    )
    for n in args.robots:
        runs = [run(n, args.seconds) for _ in range(max(1, args.repeats))]
        r = max(runs, key=lambda x: x["rtf"])
        median = float(np.median([x["rtf"] for x in runs]))
        print(
            f"{r['robots']:>6} {r['build_s']:>8.2f} {r['sim_s']:>6.1f} {r['wall_s']:>7.2f} "
            f"{r['rtf']:>7.2f} {median:>7.2f} {r['bare_rtf']:>8.2f} "
            f"{r['rtf'] / r['bare_rtf']:>6.0%} {r['scans']:>6}   {r['physics_s']:.3f} "
            f"{r['sensors_s']:.3f} {r['lasers_s']:.3f} {r['other_s']:.3f}"
        )
    print(
        "RTF: best run; median: of the runs; mj_step: MuJoCo alone on the same world right after "
        "the best run; share: RTF / mj_step."
    )


if __name__ == "__main__":
    main()
