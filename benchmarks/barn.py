"""BARN benchmark: the jackal with move_base on the BARN worlds, under the data's protocol.

Each run is the shipped scenario ``fleetsim_launch/barn.launch`` (args ``world:=N``,
``barn_dir:=...``) in process, headless, no bridge: the jackal spawned at the start pose
(-2.25, 3.0, yaw 1.57), move_base on laser-only costmaps, send_goals sending the goal
(-2.25, 13.0). The protocol of ../shared/data/barn/README.md:

- success: the ground-truth position (``/jackal/ground_truth/state``, the simulator's p3d) within
  1.0 m of the goal;
- collision: any contact of the jackal with an obstacle (the run's `RunMonitor`, which counts
  the simulator's contacts) ends the run as a failure;
- timeout: 100 s of simulated time pass. A goal that move_base aborts ends the run early and is
  counted as a timeout (the robot would stand still until the 100 s pass), reported as
  ``aborted``;
- metric: success * optimal_time / clip(actual_time, 2 * optimal_time, 8 * optimal_time), with
  optimal_time = length of the reference path (``path_N.npy`` in metres, start and goal
  added) / 2 m/s.

The clock starts when the robot has moved 0.1 m from its start, as the BARN challenge's run
script does (the startup of the stack is not navigation time).

    PYTHONPATH=src .venv/bin/python benchmarks/barn.py               # a handful of worlds
    PYTHONPATH=src .venv/bin/python benchmarks/barn.py --worlds 3,9,15
    PYTHONPATH=src .venv/bin/python benchmarks/barn.py --all
    PYTHONPATH=src .venv/bin/python benchmarks/barn.py --controller mppi --worlds 3,9

``--controller mppi`` loads ``params/jackal/mppi_params.yaml`` into move_base's namespace on top
of the launch file's (base_local_planner ``nav2_mppi_controller::MPPIController``).

``--batch OUTDIR`` runs BARN's own protocol, every world ``--runs`` times (seeds 0..runs-1), as a
`fleetsim batch` on Ray: each run in its own process, ``--workers`` at once on this machine or
on a cluster (``--address``); results in OUTDIR/results.parquet, plots with
``fleetsim batch report OUTDIR``:

    PYTHONPATH=src .venv/bin/python benchmarks/barn.py --all --batch barn_out           # 50 x 10
    PYTHONPATH=src .venv/bin/python benchmarks/barn.py --worlds 3,9 --runs 2 --batch out --workers 2
    PYTHONPATH=src .venv/bin/python benchmarks/barn.py --half heldout --batch out --runs 3

``--half tuning|held-out`` (also ``heldout``) picks one half of the tuning split, with or
without ``--batch``; a run over both halves (``--all``) prints each half's figures as well,
named by the split.
"""

from __future__ import annotations

import argparse
import logging
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# BARN's protocol (goal, radius, limits, reference path, metric, ground truth) is fleetsim's
# own scenario metrics, so that `fleetsim batch` scores runs the same way as this script
from fleetsim.batch.barn import (  # noqa: F401 (re-exported for the tests)
    GOAL,
    GOAL_RADIUS,
    MOVED,
    START,
    TIME_LIMIT,
    BarnProtocol,
    GroundTruth,
    metric_of,
    optimal_time_of,
    path_from_grid,
)
from fleetsim.launch.model import ParamOp
from fleetsim.launch.monitor import RobotResult
from fleetsim.launch.packages import ASSETS
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.runtime.params import load_yaml_file

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[1].parent / "shared"

BARN_DIR = Path(SHARED, "data/barn")
LAUNCH = ASSETS / "launch" / "barn.launch"
CHECK_PERIOD = 0.1  # s of sim time between checks of the run's state
DEFAULT_WORLDS = (3, 51, 99, 153, 201, 249)
#: local planner -> a params file loaded into /jackal/move_base after the launch file's (or None)
CONTROLLERS = {"dwa": None, "mppi": ASSETS / "launch" / "params" / "jackal" / "mppi_params.yaml"}


@dataclass
class RunResult:
    world: int
    outcome: str  # success | collision | timeout | aborted
    time: float  # s of sim time from the first 0.1 m of motion to the end of the run
    optimal_time: float
    metric: float
    final_gap: float  # m from the goal at the end
    wall: float  # s of wall time for the run

    @property
    def success(self) -> bool:
        return self.outcome == "success"


def with_controller(plan, controller: str):
    """``plan`` with the local planner ``controller`` (a `CONTROLLERS` key) for the jackal."""
    extra = CONTROLLERS[controller]
    if extra is not None:
        plan.params.append(ParamOp("load", "/jackal/move_base", load_yaml_file(extra), str(extra)))
    return plan


def run_world(
    world: int,
    barn_dir: Path = BARN_DIR,
    seed: int = 0,
    time_limit: float = TIME_LIMIT,
    controller: str = "dwa",
) -> RunResult:
    """One run of the protocol on world ``world``."""
    t_wall = time.perf_counter()
    args = {"world": str(world), "barn_dir": str(barn_dir), "gui": "false"}
    # barn.launch's barn_dir default is $(env FLEETSIM_BARN_DIR), which roslaunch resolves even
    # when the arg is given: set it too
    os.environ["FLEETSIM_BARN_DIR"] = str(barn_dir)
    plan = with_controller(load_plan(LAUNCH, args, seed=seed), controller)
    session = LaunchSession(plan, seed=seed, listen=None)
    try:
        # the protocol's end conditions and scores: the same code scores `--batch` runs
        protocol = BarnProtocol(session, args, time_limit=time_limit)
        while not protocol.done():
            session.runtime.run(duration=CHECK_PERIOD)
        robot = session.monitor.robots.get(protocol.robot) or RobotResult(protocol.robot)
        m = protocol.robot_metrics(robot)
        return RunResult(
            world=world,
            outcome=m["barn_outcome"],
            time=m["barn_time"],
            optimal_time=m["barn_optimal_time"],
            metric=m["barn_metric"],
            final_gap=m["barn_final_gap"],
            wall=time.perf_counter() - t_wall,
        )
    finally:
        session.close()


def summary(results: list[RunResult]) -> dict[str, float]:
    """Rates (fractions) of each outcome and the mean metric over ``results``."""
    n = len(results)
    count = {k: sum(r.outcome == k for r in results) for k in ("success", "collision")}
    timeouts = sum(r.outcome in ("timeout", "aborted") for r in results)
    return {
        "runs": n,
        "success": count["success"] / n,
        "collision": count["collision"] / n,
        "timeout": timeouts / n,
        "metric": float(np.mean([r.metric for r in results])),
    }


#: a launch file (written into the batch's folder) with the jackal's local planner swapped:
#: barn.launch, then the controller's params over move_base's (what `with_controller` does)
CONTROLLER_LAUNCH = """<launch>
  <arg name="world"/>
  <arg name="barn_dir"/>
  <arg name="gui" default="false"/>
  <include file="$(find fleetsim_launch)/barn.launch">
    <arg name="world" value="$(arg world)"/>
    <arg name="barn_dir" value="$(arg barn_dir)"/>
    <arg name="gui" value="$(arg gui)"/>
  </include>
  <rosparam file="{params}" command="load" ns="/jackal/move_base"/>
</launch>
"""


def run_as_batch(worlds, barn_dir: Path, runs: int, controller: str, out: Path, **ray_kw):
    """BARN's protocol as a batch: every world ``runs`` times; returns the results table."""
    from fleetsim.batch import BatchSpec, run_batch

    scenario, workdir = "barn", Path.cwd()
    if CONTROLLERS[controller] is not None:
        out.mkdir(parents=True, exist_ok=True)
        workdir = out.resolve()
        scenario = f"barn_{controller}.launch"
        (out / scenario).write_text(CONTROLLER_LAUNCH.format(params=CONTROLLERS[controller]))
    spec = BatchSpec(
        scenarios=[scenario],
        args={"world": [str(w) for w in worlds], "barn_dir": [str(barn_dir.resolve())]},
        seeds=list(range(runs)),
        duration=TIME_LIMIT + 60.0,  # the protocol ends each run; this only bounds a stuck one
        until_goals=False,
        timeout=900.0,
        metrics="barn",
        workdir=workdir,
    )
    os.environ["FLEETSIM_BARN_DIR"] = str(barn_dir.resolve())  # see run_world
    return run_batch(spec, out, **ray_kw).table()


def batch_main(a, worlds: list[int]) -> None:
    table = run_as_batch(
        worlds, a.barn_dir, a.runs, a.controller, a.batch,
        workers=a.workers, address=a.address, resume=a.resume,
    )  # fmt: skip
    rows = table.to_pylist()
    results = [
        RunResult(
            world=int(r["arg_world"]),
            outcome=r["barn_outcome"] or "failed",  # a run that crashed or timed out (wall)
            time=r["barn_time"] or float("nan"),
            optimal_time=r["barn_optimal_time"] or float("nan"),
            metric=r["barn_metric"] or 0.0,
            final_gap=r["barn_final_gap"] or float("nan"),
            wall=r["wall_time"] or float("nan"),
        )
        for r in rows
    ]
    errors = [r for r in rows if r["error"]]
    print(f"{len(rows)} runs ({len(errors)} failed to run) in {a.batch}")
    for r in errors[:5]:
        print(f"  world {r['arg_world']} seed {r['seed']}: {r['error']}")
    print_by_half(results, a.barn_dir)
    print(f"plots: fleetsim batch report {a.batch}")


def print_rates(results: list[RunResult]) -> None:
    s = summary(results)
    print(
        f"runs {s['runs']}: success {100 * s['success']:.1f} %, collision "
        f"{100 * s['collision']:.1f} %, timeout {100 * s['timeout']:.1f} %, "
        f"mean metric {s['metric']:.3f}"
    )


def print_summary(results: list[RunResult]) -> None:
    print_rates(results)
    print(
        "reference (ROS move_base + DWA, 50 test worlds): success 85.0 %, collision 5.6 %, "
        "timeout 9.4 %; target >= 90 % success"
    )


def available_worlds(barn_dir: Path) -> list[int]:
    return sorted(int(p.stem.split("_")[1]) for p in barn_dir.glob("world_*.world"))


#: the held-out discipline: parameters and planner changes are tuned on the first half of the
#: shared worlds by number (3-147), the second half (153-297) only measured
HALVES = ("tuning", "held-out")
#: other spellings of a half accepted by --half
HALF_ALIASES = {"heldout": "held-out", "held_out": "held-out", "tune": "tuning"}


def half_name(text: str) -> str:
    """The half ``text`` names (`HALVES` or an alias); argparse's type for --half."""
    name = HALF_ALIASES.get(text.strip().lower(), text.strip().lower())
    if name not in HALVES:
        raise argparse.ArgumentTypeError(
            f"--half {text!r} is not a half of the split; use one of {', '.join(HALVES)}"
        )
    return name


def half_of(barn_dir: Path, world: int) -> str | None:
    """The half world ``world`` belongs to (None if it is not in ``barn_dir``)."""
    for half in HALVES:
        if world in half_worlds(barn_dir, half):
            return half
    return None


def print_by_half(results: list[RunResult], barn_dir: Path) -> None:
    """The summary of ``results``, then of each half of the split they cover, named."""
    print_summary(results)
    by_half = {h: [r for r in results if half_of(barn_dir, r.world) == h] for h in HALVES}
    if sum(bool(v) for v in by_half.values()) < 2:
        return
    for half, rs in by_half.items():
        print(f"{split_name(barn_dir, half)}:", end=" ")
        print_rates(rs)


def half_worlds(barn_dir: Path, half: str) -> list[int]:
    """The worlds of one half of the split (``tuning``: the first half by number)."""
    worlds = available_worlds(barn_dir)
    k = len(worlds) // 2
    return worlds[:k] if half == "tuning" else worlds[k:]


def split_name(barn_dir: Path, half: str) -> str:
    worlds = half_worlds(barn_dir, half)
    return f"{half} half of the split, worlds {worlds[0]}-{worlds[-1]} ({len(worlds)})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--worlds", help="comma-separated world numbers, e.g. 3,9,15")
    ap.add_argument("--all", action="store_true", help="every world in --barn-dir")
    ap.add_argument(
        "--half",
        type=half_name,
        metavar="{tuning,held-out}",
        help="one half of the tuning split (tuning: first by number; also heldout)",
    )
    ap.add_argument("--barn-dir", type=Path, default=BARN_DIR)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--controller", choices=sorted(CONTROLLERS), default="dwa")
    ap.add_argument("-v", "--verbose", action="store_true", help="show the nodes' log")
    ap.add_argument("--batch", type=Path, metavar="OUTDIR", help="run as a batch on Ray")
    ap.add_argument("--runs", type=int, default=10, help="--batch: runs per world (seeds)")
    ap.add_argument("--workers", type=int, help="--batch: local Ray CPUs (default: cores)")
    ap.add_argument("--address", help="--batch: an existing Ray cluster")
    ap.add_argument("--resume", action="store_true", help="--batch: keep finished runs")
    a = ap.parse_args()
    logging.basicConfig(level=logging.INFO if a.verbose else logging.ERROR)
    if a.half:
        worlds = half_worlds(a.barn_dir, a.half)
    elif a.all:
        worlds = available_worlds(a.barn_dir)
    elif a.worlds:
        parts = [w.strip() for w in a.worlds.split(",") if w.strip()]
        if not all(w.isdigit() for w in parts):
            ap.error(f"--worlds: BARN world numbers, comma separated; got {a.worlds!r}")
        worlds = [int(w) for w in parts]
    else:
        worlds = list(DEFAULT_WORLDS)
    print(f"BARN: jackal + move_base ({a.controller}), {len(worlds)} worlds from {a.barn_dir}")
    tuned = half_worlds(a.barn_dir, "tuning")
    print(f"split: tuned on worlds {tuned[0]}-{tuned[-1]}; held out: the rest")
    if a.half:
        print(f"measuring the {split_name(a.barn_dir, a.half)}")
    if a.batch is not None:
        batch_main(a, worlds)
        return
    print(
        f"{'world':>5} {'outcome':>9} {'time s':>7} {'opt s':>6} {'metric':>6} {'gap m':>6} "
        f"{'wall s':>6}"
    )
    results = []
    for w in worlds:
        r = run_world(w, a.barn_dir, seed=a.seed, controller=a.controller)
        results.append(r)
        print(
            f"{r.world:>5} {r.outcome:>9} {r.time:7.1f} {r.optimal_time:6.2f} {r.metric:6.3f} "
            f"{r.final_gap:6.2f} {r.wall:6.1f}",
            flush=True,
        )
    print_by_half(results, a.barn_dir)


if __name__ == "__main__":
    main()
