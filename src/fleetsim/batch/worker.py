"""One run of a batch, in a process of its own: ``python -m fleetsim.batch RUN OUT``.

``RUN`` is the run's JSON (`RunSpec.to_json`), ``OUT`` the folder its files go to:
``result.json`` (one row per robot, or the error that ended the run), ``run.mcap`` with
``--record``. The run is headless and has no Zenoh listener; user files (launch files, node
modules, robot packages) are read relative to the current directory, which is the batch's
working directory (shipped by Ray to a cluster's nodes). The process ends with the run, so
nothing of one run (module state, MuJoCo, threads) reaches the next.
"""

from __future__ import annotations

import json
import logging
import math
import sys
import time
import traceback
from pathlib import Path
from typing import Any

from fleetsim.batch.metrics import metrics_class, metrics_name_for
from fleetsim.batch.spec import RunSpec, resolve_scenario

#: s of sim time between checks of the run's end conditions (goals done, the protocol's)
CHECK_PERIOD = 0.1
RESULT = "result.json"
RECORDING = "run.mcap"


class _Count(logging.Handler):
    """Counts MuJoCo's warnings (fleetsim routes them to the ``fleetsim.mujoco`` logger)."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.count = 0

    def emit(self, record: logging.LogRecord) -> None:
        self.count += 1


def run_here(run: RunSpec, out: Path, record: bool = False) -> list[dict[str, Any]]:
    """Run ``run`` in this process; one row per robot (without the run's own columns)."""
    from fleetsim.launch.runner import LaunchSession, load_plan

    warnings = _Count()
    logging.getLogger("fleetsim.mujoco").addHandler(warnings)
    wall0 = time.perf_counter()
    plan = load_plan(resolve_scenario(run.scenario, Path.cwd()), dict(run.args), seed=run.seed)
    name = metrics_name_for(run.scenario, run.metrics)
    cls = metrics_class(name) if name is not None else None
    rec = out / RECORDING if record else None
    with LaunchSession(plan, seed=run.seed, record=rec, listen=None) as session:
        metrics = cls(session, dict(run.args)) if cls is not None else None
        rt, monitor = session.runtime, session.monitor
        loop0 = time.perf_counter()
        while rt.now() < run.duration - 1e-9:
            rt.run(duration=min(CHECK_PERIOD, run.duration - rt.now()))
            if run.until_goals and monitor.all_goals_done():
                break
            if metrics is not None and metrics.done():
                break
        loop_wall = time.perf_counter() - loop0
        sim_time = rt.now()
        robots = monitor.results()
        rows = []
        for r in robots or [None]:
            row: dict[str, Any] = {"robot": "", "success": None}
            if r is not None:
                row.update(
                    robot=r.namespace,
                    # a robot without goals has no success to speak of (null, not false)
                    success=r.ok if r.goals_sent > 0 else None,
                    goals_sent=r.goals_sent,
                    goals_reached=r.goals_reached,
                    time=r.time_of_last_result,
                    path_length=r.path_length,
                    collisions=r.collisions,
                    collided_with=collision_text(r.collision_events),
                    last_status=r.last_text,
                )
                if metrics is not None:
                    row.update(metrics.robot_metrics(r))
            row.update(
                sim_time=sim_time,
                wall_time=time.perf_counter() - wall0,
                rtf=sim_time / loop_wall if loop_wall > 0 else math.nan,
                mujoco_warnings=warnings.count,
            )
            rows.append(row)
    return rows


def collision_text(events) -> str:
    """The ``collided_with`` column: each collision's onset (`RobotResult.collision_events`:
    sim time, the other model, this robot's x, y) as "14.70 s lizi5 at (7.82, 6.00)", joined by
    "; "."""
    return "; ".join(f"{t:.2f} s {other} at ({x:.2f}, {y:.2f})" for t, other, x, y in events)


def main(argv: list[str]) -> int:
    run = RunSpec.from_json(json.loads(argv[0]))
    out = Path(argv[1])
    record = len(argv) > 2 and argv[2] == "1"
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    try:
        rows = run_here(run, out, record)
    except Exception as e:
        traceback.print_exc()
        error = f"{type(e).__name__}: {e}"
        (out / RESULT).write_text(json.dumps({"rows": [], "error": error}))
        return 1
    (out / RESULT).write_text(json.dumps({"rows": rows, "error": ""}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
