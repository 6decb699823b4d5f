"""Running a batch on Ray: one task per run, each run in a process of its own.

Each Ray task starts the run as a child process (`fleetsim.batch.worker`), so that one run's
state (module globals, MuJoCo, threads) cannot reach the next and a hung run can be killed
without killing the Ray worker: after ``timeout`` s of wall time the child's process group is
killed and the run recorded as failed. A run that raises, a child killed by a signal and a Ray
worker that dies (``ray.exceptions.WorkerCrashedError``; tasks are not retried, so a run is
never counted twice) are each a failed row with the reason; the batch goes on.

Embedded by default: a local Ray started for the batch with ``workers`` CPUs, one run per CPU.
With ``address`` (or ``RAY_ADDRESS``) the batch runs on an existing cluster: the spec's folder
is shipped as the runs' working directory (a Ray runtime environment), so the user's launch
files, parameter files, node modules and robot packages reach every node and the cluster needs
only ``pip install fleetsim``. A run's files come back to the driver as bytes, so its folder
(``OUTDIR/runs/<run_id>``) is written on this machine whichever node ran it.
"""

from __future__ import annotations

import ctypes
import json
import logging
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from fleetsim.batch.metrics import metrics_class, metrics_name_for
from fleetsim.batch.results import ARG_PREFIX, ResultsTable, columns_for
from fleetsim.batch.spec import BatchSpec, RunSpec, validate
from fleetsim.batch.worker import RESULT
from fleetsim.errors import BatchError

_log = logging.getLogger("fleetsim.batch")
RUNS = "runs"
LOG = "log.txt"
#: the tail of a failed run's log that goes into its error, characters
ERROR_TAIL = 300
#: MB of Ray's object store for an embedded batch: run results and files are small
OBJECT_STORE_MB = 150


#: prctl(2), looked up here in the parent: between fork and exec the child must not load
#: libraries (a lock another of the Ray worker's threads held at the fork would never be freed)
_PRCTL = ctypes.CDLL(None, use_errno=True).prctl if sys.platform.startswith("linux") else None
PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """In the child before exec: be killed when the Ray worker that started it dies (Linux's
    PR_SET_PDEATHSIG; the standard library has no call for it), so that a crashed worker or
    a batch stopped with Ctrl-C leaves no run behind."""
    if _PRCTL is not None:
        _PRCTL(PR_SET_PDEATHSIG, signal.SIGKILL)


def execute_run(run_json: dict, timeout: float, record: bool, workdir: str | None) -> dict:
    """Body of a Ray task: ``run_json`` run in a child process; its rows or error and files.

    ``workdir`` is where the user's files are (None: the task's current directory, which is
    the shipped working directory on a cluster).
    """
    cwd = workdir or os.getcwd()
    with tempfile.TemporaryDirectory(prefix="fleetsim-run-") as tmp:
        out = Path(tmp)
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (cwd, env.get("PYTHONPATH")) if p)
        # str hashes (set order) are then the same in every run's process
        env["PYTHONHASHSEED"] = "0"
        env.setdefault("MUJOCO_GL", "egl")
        cmd = [sys.executable, "-m", "fleetsim.batch", json.dumps(run_json), tmp]
        cmd.append("1" if record else "0")
        error = ""
        with (out / LOG).open("wb") as log:
            proc = subprocess.Popen(
                cmd, cwd=cwd, env=env, stdout=log, stderr=subprocess.STDOUT,
                start_new_session=True,  # its own process group, killed whole on a timeout
                preexec_fn=_die_with_parent,
            )  # fmt: skip
            try:
                code = proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                code = None
                error = f"timed out: still running after {timeout:g} s of wall time (killed)"
        result = {"rows": [], "error": ""}
        if (out / RESULT).exists():
            result = json.loads((out / RESULT).read_text())
        if not error:
            error = result["error"]
        if not error and code is not None and code < 0:
            error = f"the run's process was killed by {signal.Signals(-code).name}"
        elif not error and code:
            tail = (out / LOG).read_text(errors="replace")[-ERROR_TAIL:].strip()
            error = f"the run's process exited with status {code}: ...{tail}"
        files = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
        return {"rows": [] if error else result["rows"], "error": error, "files": files}


def _ray_init(workers: int, address: str | None, workdir: Path, outdir: Path) -> bool:
    """Start or join Ray; True if this batch started it (and must shut it down)."""
    import ray

    if ray.is_initialized():
        return False
    address = address or os.environ.get("RAY_ADDRESS")
    if address:
        excludes = [".git", "__pycache__", "*.mcap"]
        if outdir.resolve().is_relative_to(workdir.resolve()):
            excludes.append(str(outdir.resolve().relative_to(workdir.resolve())))
        ray.init(
            address=address,
            runtime_env={"working_dir": str(workdir), "excludes": excludes},
            log_to_driver=False,
            logging_level=logging.WARNING,
        )
    else:
        # a Ray started for one batch reports no usage statistics unless the user asks it to
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        ray.init(
            num_cpus=workers,
            include_dashboard=False,
            log_to_driver=False,
            logging_level=logging.WARNING,
            object_store_memory=OBJECT_STORE_MB * 1024 * 1024,
        )
    return True


def default_workers() -> int:
    return os.cpu_count() or 1


def run_batch(
    spec: BatchSpec,
    outdir: str | Path,
    workers: int | None = None,
    address: str | None = None,
    resume: bool = False,
    record: bool = False,
    progress: bool = True,
    console: Console | None = None,
) -> ResultsTable:
    """Validate ``spec``, run every run not yet finished, and return the results table."""
    import ray

    workers = default_workers() if workers is None else workers
    if workers < 1:
        raise BatchError(f"--workers must be >= 1, got {workers}")
    runs = validate(spec)
    outdir = Path(outdir)
    metric_cols: dict[str, str] = {}
    for run in runs:
        name = metrics_name_for(run.scenario, run.metrics)
        if name is not None:
            metric_cols.update(metrics_class(name).columns)
    table = ResultsTable(outdir, columns_for(list(spec.args), metric_cols), resume=resume)
    if resume:
        outside = table.reindex({r.run_id: r.index for r in runs})
        if outside:
            _log.warning(f"{outdir}: kept {outside} rows of runs that are not in this sweep")
    done = table.finished()
    todo = [r for r in runs if r.run_id not in done]
    if not todo:
        return table
    started = _ray_init(workers, address, spec.workdir, outdir)
    # on a cluster the runs find the user's files in the shipped working dir, here in place
    local = not (address or os.environ.get("RAY_ADDRESS"))
    try:
        task = ray.remote(num_cpus=1, max_retries=0)(execute_run)
        workdir = str(spec.workdir.resolve()) if local else None
        pending = {
            task.remote(r.to_json(), spec.timeout, record, workdir): r for r in todo
        }  # fmt: skip
        slots = int(ray.cluster_resources().get("CPU", workers))
        _collect(pending, table, outdir, slots, len(runs) - len(todo), len(runs), progress, console)
    finally:
        if started:
            ray.shutdown()
    return table


def _collect(pending, table, outdir, slots, already, total, progress, console) -> None:
    import ray

    failed = 0
    columns = [
        TextColumn("[bold]batch"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("failed {task.fields[failed]}  running {task.fields[running]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
    ]
    with Progress(*columns, console=console or Console(stderr=True), disable=not progress) as bar:
        task = bar.add_task("runs", total=total, completed=already, failed=0, running=0)
        while pending:
            bar.update(task, running=min(slots, len(pending)))
            ready, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
            for ref in ready:
                run = pending.pop(ref)
                t0 = time.perf_counter()
                try:
                    result = ray.get(ref)
                except ray.exceptions.RayError as e:
                    first = str(e).strip().splitlines()[0] if str(e).strip() else ""
                    result = {"rows": [], "files": {}, "error": f"{type(e).__name__}: {first}"}
                _log.debug(f"run {run.run_id} collected in {time.perf_counter() - t0:.2f} s")
                rows = _rows_of(run, result, outdir)
                failed += bool(result["error"])
                table.append(rows)
                bar.update(task, advance=1, failed=failed, running=min(slots, len(pending)))


def _rows_of(run: RunSpec, result: dict[str, Any], outdir: Path) -> list[dict[str, Any]]:
    """The run's rows with its own columns, its files written to ``OUTDIR/runs/<run_id>``."""
    run_dir = Path(RUNS, run.run_id)
    folder = outdir / run_dir
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in result.get("files", {}).items():
        (folder / name).write_bytes(data)
    own = {"run": run.index, "run_id": run.run_id, "scenario": run.scenario, "seed": run.seed}
    own.update({ARG_PREFIX + k: v for k, v in run.args})
    own.update(error=result["error"], run_dir=str(run_dir))
    if result["error"]:
        return [{**own, "robot": "", "success": False}]
    return [{**own, **row} for row in result["rows"]]
