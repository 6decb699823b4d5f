"""Batch throughput: runs per hour of the same batch on 1 and on 2 local Ray workers.

The batch is ``--runs`` runs (seeds) of the shipped BARN scenario on world 3 for ``--duration``
s of sim time each (BARN's protocol may end a run earlier, the same way on both), each run in
its own process as `fleetsim batch` runs them. Ray is started before the clock starts, so the
times are the batch's, not Ray's start-up. Prints runs/hour for each and their ratio (the issue
asks >= 1.7x on this 2-core machine); asserts nothing.

    PYTHONPATH=src .venv/bin/python benchmarks/batch_throughput.py
    PYTHONPATH=src .venv/bin/python benchmarks/batch_throughput.py --runs 8 --duration 20
"""

from __future__ import annotations

import argparse
import logging
import os
import tempfile
import time
from pathlib import Path

import ray

from fleetsim.batch import BatchSpec, run_batch

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
BARN_DIR = SHARED / "data" / "barn"


def runs_per_hour(workers: int, runs: int, duration: float) -> tuple[float, int]:
    """(runs/hour, failed runs) of the batch on ``workers`` local Ray CPUs."""
    spec = BatchSpec(
        scenarios=["barn"],
        args={"world": ["3"], "barn_dir": [str(BARN_DIR)], "gui": ["false"]},
        seeds=list(range(runs)),
        duration=duration,
        until_goals=False,
        timeout=600.0,
    )
    os.environ["FLEETSIM_BARN_DIR"] = str(BARN_DIR)
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    ray.init(num_cpus=workers, include_dashboard=False, log_to_driver=False)
    try:
        with tempfile.TemporaryDirectory() as out:
            t0 = time.perf_counter()
            table = run_batch(spec, out, workers=workers, progress=False)
            wall = time.perf_counter() - t0
    finally:
        ray.shutdown()
    failed = len({r["run_id"] for r in table.rows if r["error"]})
    return runs / wall * 3600.0, failed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=6, help="runs in the batch (seeds)")
    ap.add_argument("--duration", type=float, default=15.0, help="sim s per run at most")
    a = ap.parse_args()
    logging.basicConfig(level=logging.ERROR)
    print(
        f"batch: {a.runs} runs of barn world 3, {a.duration:g} sim s each; cores {os.cpu_count()}"
    )
    rates = {}
    for workers in (1, 2):
        rate, failed = runs_per_hour(workers, a.runs, a.duration)
        rates[workers] = rate
        print(f"{workers} worker(s): {rate:7.1f} runs/hour ({failed} failed)", flush=True)
    print(f"2 workers / 1 worker: {rates[2] / rates[1]:.2f}x (target >= 1.7x)")


if __name__ == "__main__":
    main()
