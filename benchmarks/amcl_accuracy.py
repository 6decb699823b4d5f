"""amcl tracking accuracy on the Willow route, at two odometry noise levels (issue 6).

lizi drives the 62.7 m route of ``tests/scenarios/amcl_harness.py`` in the MuJoCo simulator;
amcl (the scenario tests' parameters) localizes it. Errors are taken at every ``amcl_pose``
after the first 5 m of travel, against ``base_pose_ground_truth``. Levels:

- ``sim``: the simulator's wheel-encoder odometry as it is (skid steer: rotation over-reported
  several times when turning);
- ``sim+noise``: the same, re-broadcast with extra noise (translation scale 1 + 0.2 n and
  rotation + 0.5 |dtheta| n per 100 Hz message, plus a heading drift of 0.02 rad/m).

Usage: python benchmarks/amcl_accuracy.py [--seed 1]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "scenarios"))

from amcl_harness import willow_amcl_run
from test_amcl_willow import TRACKING

LEVELS = {"sim": None, "sim+noise": (0.2, 0.5, 0.02)}


def run(level: str, seed: int) -> dict:
    t0 = time.perf_counter()
    r = willow_amcl_run(seed=seed, amcl_params=TRACKING, odom_noise=LEVELS[level])
    r.drive(max_sim_time=300.0)
    err = r.log.errors()
    after = err["dist"] > 5.0
    pos, yaw = err["pos"][after], err["yaw"][after]
    return {
        "level": level,
        "travelled": r.follower.travelled,
        "poses": int(after.sum()),
        "pos_mean": pos.mean(),
        "pos_p95": np.percentile(pos, 95),
        "yaw_mean": yaw.mean(),
        "yaw_p95": np.percentile(yaw, 95),
        "wall": time.perf_counter() - t0,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    print("odometry    route(m) poses  pos mean  pos p95  yaw mean  yaw p95  wall(s)")
    for level in LEVELS:
        s = run(level, args.seed)
        print(
            f"{s['level']:<11} {s['travelled']:8.1f} {s['poses']:5d} {s['pos_mean']:8.3f} m"
            f" {s['pos_p95']:6.3f} m {s['yaw_mean']:7.4f} r {s['yaw_p95']:6.4f} r {s['wall']:7.1f}"
        )


if __name__ == "__main__":
    main()
