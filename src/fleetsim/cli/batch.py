"""`fleetsim batch`: sweeps of scenarios, launch arguments and seeds on Ray, and their reports.

    fleetsim batch SPEC.yaml -o OUTDIR
    fleetsim batch SCENARIO --arg NAME=V1,V2 --arg NAME=A..B --seeds 0..9 -o OUTDIR
    fleetsim batch report OUTDIR [--by NAME]

``fleetsim batch X`` is ``fleetsim batch run X`` unless X is a sub-command's name.
"""

from __future__ import annotations

from pathlib import Path

import typer
import yaml
from rich.console import Console
from rich.markup import escape
from rich.table import Table
from typer.core import TyperGroup

from fleetsim.cli.launch import table_console
from fleetsim.errors import BatchError

console = Console(stderr=True)


class _RunByDefault(TyperGroup):
    """``fleetsim batch SPEC`` runs SPEC: a first word that names no sub-command goes to run."""

    def parse_args(self, ctx, args):
        if args and args[0] not in self.commands and args[0] not in ("--help", "-h"):
            args = ["run", *args]
        return super().parse_args(ctx, args)


app = typer.Typer(cls=_RunByDefault, no_args_is_help=True, pretty_exceptions_enable=False)


def _is_spec(target: str) -> bool:
    """A batch spec: a .yaml/.yml file that is not a launch file (no top-level 'launch')."""
    p = Path(target)
    if p.suffix not in (".yaml", ".yml") or not p.is_file() or ".launch." in p.name:
        return False
    try:
        data = yaml.safe_load(p.read_text())
    except yaml.YAMLError:
        return True  # load_spec reports it
    return not (isinstance(data, dict) and "launch" in data)


@app.command("run")
def run(
    target: str = typer.Argument(..., help="A batch spec (.yaml), a scenario or a launch file."),
    arg: list[str] = typer.Option(
        None, "--arg", help="A swept launch argument: NAME=V1,V2 or NAME=A..B (repeatable)."
    ),
    seeds: str = typer.Option(None, "--seeds", help="Seeds: 0..9, 1,2,3 or one integer."),
    out: Path = typer.Option(Path("batch_out"), "--out", "-o", help="Output folder."),
    duration: float = typer.Option(None, "--duration", help="Sim seconds a run lasts at most."),
    until_goals: bool = typer.Option(
        None, "--until-goals/--full-duration", help="End a run once its goals are done."
    ),
    timeout: float = typer.Option(None, "--timeout", help="Wall seconds before a run is killed."),
    metrics: str = typer.Option(None, "--metrics", help="Scenario metrics (e.g. barn)."),
    workers: int = typer.Option(None, "--workers", "-j", help="Local Ray CPUs (default: cores)."),
    address: str = typer.Option(
        None, "--address", help="An existing Ray cluster (default $RAY_ADDRESS; else local)."
    ),
    resume: bool = typer.Option(False, "--resume", help="Skip the runs OUTDIR already holds."),
    record: bool = typer.Option(False, "--record", help="Record each run to runs/<id>/run.mcap."),
    no_progress: bool = typer.Option(False, "--no-progress", help="No progress bar."),
) -> None:
    """Run a sweep: every scenario x argument value x seed, each run headless in its own
    process, as Ray tasks; results in OUTDIR/results.csv and results.parquet. Exit status 1
    when a run ended in an error (its row says which)."""
    from fleetsim.batch import load_spec, parse_cli_args, parse_seeds, run_batch
    from fleetsim.batch.spec import BatchSpec

    if _is_spec(target):
        if arg or seeds:
            raise BatchError(f"{target} is a batch spec: put --arg and --seeds in it")
        spec = load_spec(target)
    else:
        spec = BatchSpec(scenarios=[target], args=parse_cli_args(arg or []))
        if seeds is not None:
            spec.seeds = parse_seeds(seeds, "--seeds")
    for name, value in (("duration", duration), ("until_goals", until_goals)):
        if value is not None:
            setattr(spec, name, value)
    if timeout is not None:
        spec.timeout = timeout
    if metrics is not None:
        spec.metrics = metrics
    table = run_batch(
        spec, out, workers=workers, address=address, resume=resume, record=record,
        progress=not no_progress, console=console,
    )  # fmt: skip
    console.print(closing_line(table.rows, out))
    errored = sorted({r["run_id"] for r in table.rows if r["error"]})
    if errored:  # results are what they are; a run that could not run is a failure
        console.print(f"{len(errored)} run(s) ended in an error (see their 'error' column)")
        raise typer.Exit(1)


def closing_line(rows: list[dict], out) -> str:
    """The batch's last line: its runs (a run has a row per robot), those that ended in an
    error, and of the others with goals those where every robot reached every goal without a
    collision (``success`` true; null for a robot without goals), then the results files."""
    failed = len({r["run_id"] for r in rows if r["error"]})
    runs = len({r["run_id"] for r in rows})
    judged = {r["run_id"] for r in rows if not r["error"] and r["success"] is not None}
    missed = {r["run_id"] for r in rows if r["success"] is False}
    return (
        f"{runs} runs ({failed} ended in an error; of the {len(judged)} with goals, "
        f"{len(judged - missed)} reached every goal without a collision): {out}/results.csv, "
        f"{out}/results.parquet"
    )


@app.command("report")
def report_cmd(
    results: Path = typer.Argument(..., help="A batch's output folder or its results file."),
    by: list[str] = typer.Option(
        None, "--by", help="Group by this argument (repeatable; default: the swept ones)."
    ),
    out: Path = typer.Option(None, "--out", "-o", help="Folder for the summary and plots."),
) -> None:
    """Summaries grouped by argument (success rate with Wilson intervals, medians) and plots."""
    from fleetsim.batch import read_results
    from fleetsim.batch.report import report

    table = read_results(results)
    outdir = out or (results if results.is_dir() else results.parent)
    groups, cols, files = report(table, by, outdir)
    t = Table(title=f"{len(table)} rows")
    for c in cols:
        t.add_column(c.removeprefix("arg_"))
    for c in ("rows", "errors", "success", "95% CI", "median time [s]", "median path [m]"):
        t.add_column(escape(c))  # "[s]" is rich markup otherwise
    metric_names = list(groups[0].metrics) if groups else []
    for m in metric_names:
        t.add_column(f"mean {m}")
    for g in groups:
        rate = "-" if not g.judged else f"{g.successes}/{g.judged} ({g.success_rate:.0%})"
        ci = "-" if not g.judged else f"{g.ci[0]:.2f}-{g.ci[1]:.2f}"
        t.add_row(
            *g.key, str(g.rows), str(g.errors), rate, ci, f"{g.median_time:.1f}",
            f"{g.median_path:.2f}", *(f"{g.metrics[m]:.3f}" for m in metric_names),
        )  # fmt: skip
    table_console(Console()).print(t)
    for f in files:
        console.print(f"wrote {f}")
