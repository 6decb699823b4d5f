"""`fleetsim launch`: run a launch file (or a shipped scenario by name) headless.

Shows a progress bar (sim time, real-time factor) and, at the end, a results table per robot.
With ``--until-goals`` the run ends when every robot's goals are done, and the exit status is 0
only if all were reached without a collision. A goal counts as reached only when the
simulator's ground truth agrees (`fleetsim.launch.monitor`); the table shows each robot's
ground-truth distance to its last goal and, where a localizer publishes ``map``, its error.
"""

from __future__ import annotations

import time
from pathlib import Path

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from fleetsim.errors import LaunchError
from fleetsim.launch.scenarios import (
    LAUNCH_SUFFIXES,
    package_launch_file,
    resolve_launch_file,
    scenarios,
)

console = Console(stderr=True)
PIPED_WIDTH = 200  # columns of a table written to a pipe or a file


def table_console(c: Console) -> Console:
    """``c``, or when it writes to a pipe or a file (``| tee``, CI logs), a console of
    `PIPED_WIDTH` columns on the same stream: rich takes 80 there, and a wide results table
    lost its last columns to wrapping."""
    return c if c.is_terminal else Console(file=c.file, width=PIPED_WIDTH)


def parse_launch_args(items: list[str]) -> dict[str, str]:
    out = {}
    for item in items:
        key, sep, value = item.partition(":=")
        if not sep or not key:
            raise LaunchError(f"launch argument '{item}' is not of the form name:=value")
        out[key] = value
    return out


UNTIL_GOALS_HELP = (
    "Stop when every robot's goals are done. Goals are the move_base action goals "
    "(<ns>/move_base/goal) of every robot, from any sender: send_goals nodes in the launch file, "
    "'fleetsim goal', user nodes, other processes over the bridge; the run also waits for "
    "send_goals nodes to send all theirs. Exit status 0 only if each goal was reached by "
    "ground truth (within the local planner's xy_goal_tolerance plus the margin the results "
    "table states) without a collision."
)


def _metres(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}"


def results_table(monitor) -> Table:
    from fleetsim.launch.monitor import GOAL_MARGIN

    t = Table(
        title="results",
        caption=f"goal reached: move_base SUCCEEDED and ground truth within the local planner's "
        f"xy_goal_tolerance + {GOAL_MARGIN:g} m of the goal",
    )
    columns = (
        "robot",
        "goals reached",
        "last result at [sim s]",
        "path [m]",
        "collisions",
        "to goal [m] (truth)",
        "loc. error [m]",
        "last status",
    )
    for col in columns:
        t.add_column(escape(col))  # "[m]" is rich markup otherwise, and the units vanished
    for r in monitor.results():
        # a robot spawned in the root namespace (the manual's hunter) is told by its model
        name = f"/ ({r.model})" if r.namespace == "/" and r.model else r.namespace
        t.add_row(
            escape(name),
            f"{r.goals_reached}/{r.goals_sent}",
            "-" if r.time_of_last_result is None else f"{r.time_of_last_result:.1f}",
            f"{r.path_length:.1f}",
            str(r.collisions),
            _metres(r.distance_to_goal),
            _metres(r.localization_error),
            escape(_short(r.last_text)) or "-",
        )
    return t


#: characters of a last status shown in the table; a longer one is given whole below it
STATUS_WIDTH = 48


def _short(text: str) -> str:
    return text if len(text) <= STATUS_WIDTH else text[: STATUS_WIDTH - 1] + "\u2026"


def results_notes(monitor) -> list[str]:
    """Lines printed under the results table: each collision's onset (sim time, the robots,
    where), once per pair, and the whole of each last status the table shortened."""
    out, seen = [], set()
    results = monitor.results()
    names = {r.model: r.namespace for r in results if r.model}
    for r in results:
        for t, other, x, y in r.collision_events:
            pair = (round(t, 3), frozenset((r.model, other)))
            if pair in seen:
                continue
            seen.add(pair)
            what = f"robot {names[other]}" if other in names else f"'{other}'"
            out.append(
                f"collision at {t:.2f} s: {r.namespace} touched {what}, {r.namespace} at "
                f"({x:.2f}, {y:.2f})"
            )
    for r in results:
        if len(r.last_text) > STATUS_WIDTH:
            out.append(f"{r.namespace} last status: {r.last_text}")
    return out


def print_results(monitor, to: Console | None = None) -> None:
    """The results table and its notes (`results_notes`), on ``to`` (default: stderr, wide
    when piped)."""
    to = to or table_console(console)
    to.print(results_table(monitor))
    for line in results_notes(monitor):
        to.print(line, markup=False, highlight=False)


def run_launch(
    file: str,
    args: dict[str, str],
    duration: float | None = None,
    until_goals: bool = False,
    record: str | None = None,
    viz: bool = False,
    realtime: bool = False,
    seed: int = 0,
    progress: bool = True,
    listen: str | None = None,
    connect: str | None = None,
):
    """Run a launch file; returns the finished session's monitor.

    With ``connect`` the file's nodes join the simulation at that endpoint (see
    `fleetsim.launch.runner`) and run with its clock: for ``duration`` s of sim time from
    joining, until their goals are done, or (neither given) until SIGTERM/Ctrl-C or the
    simulation goes away.
    """
    from fleetsim.launch.runner import LaunchSession, load_plan

    if connect is not None:
        if realtime:
            raise LaunchError("--realtime has no effect with --connect: time is the simulation's")
        plan = load_plan(resolve_launch_file(file), args, seed=seed)
        with LaunchSession(plan, seed=seed, viz=viz, record=record, connect=connect) as session:
            follow_until_stopped(session, duration, until_goals)
            print_results(session.monitor)
            return session.monitor
    if duration is None and not until_goals:
        raise LaunchError("give --duration S, --until-goals, or both")
    plan = load_plan(resolve_launch_file(file), args, seed=seed)
    rate = 1.0 if realtime else None
    with LaunchSession(plan, seed=seed, viz=viz, record=record, listen=listen) as session:
        rt = session.runtime
        followers = [s for s in session.monitor.senders if getattr(s, "follows", False)]
        if until_goals and duration is None and followers:
            raise LaunchError(
                f"--until-goals without --duration: {followers[0].full_name} is a follower, "
                "which never finishes; give --duration S"
            )
        total = duration if duration is not None else 3600.0
        until = session.monitor.all_goals_done if until_goals else None
        wall0 = time.monotonic()
        with Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            TextColumn("sim {task.completed:.1f}/{task.total:.0f} s"),
            TextColumn("{task.fields[rtf]}"),
            TimeElapsedColumn(),
            console=console,
            disable=not progress,
            transient=False,
        ) as bar:
            task = bar.add_task(Path(file).name, total=total, rtf="")
            step = 1.0
            while rt.now() < total - 1e-9:
                end = min(total, rt.now() + step)
                rt.run(duration=end - rt.now(), until=until, rate=rate)
                wall = time.monotonic() - wall0
                bar.update(task, completed=rt.now(), rtf=f"{rt.now() / max(wall, 1e-9):.1f}x RT")
                if until is not None and until():
                    break
        print_results(session.monitor)
        if record:
            console.print(f"recorded to {record}")
        return session.monitor


def follow_until_stopped(session, duration: float | None, until_goals: bool) -> None:
    """Run a joined session until ``duration`` s of sim time have passed, its goals are done,
    or SIGTERM arrives (a clean stop, as roslaunch's)."""
    import signal
    import threading

    stop = threading.Event()
    previous = signal.signal(signal.SIGTERM, lambda *_: stop.set())
    console.print(f"joined at t = {session.runtime.now():.1f} s; following the simulation's clock")
    try:
        session.run(duration, until_goals, stop=stop)
    finally:
        signal.signal(signal.SIGTERM, previous)


def register(app: typer.Typer) -> None:
    @app.command("launch")
    def launch(
        file: str = typer.Argument(
            None,
            help="A launch file (.launch XML or .yaml), a scenario, or a package followed by "
            "one of its launch files (roslaunch PACKAGE FILE).",
        ),
        args: list[str] = typer.Argument(None, help="Launch arguments name:=value."),
        duration: float = typer.Option(None, "--duration", help="Sim seconds to run."),
        until_goals: bool = typer.Option(False, "--until-goals", help=UNTIL_GOALS_HELP),
        record: str = typer.Option(None, "--record", help="Record every topic to this MCAP file."),
        viz: bool = typer.Option(False, "--viz", help="Serve the live view to Foxglove."),
        realtime: bool = typer.Option(False, "--realtime", help="Pace the run to the wall clock."),
        seed: int = typer.Option(0, "--seed", help="The run's random seed."),
        list_: bool = typer.Option(False, "--list", help="List the shipped scenarios."),
        listen: str = typer.Option(
            None,
            "--listen",
            help="Zenoh endpoint for tools (default $FLEETSIM_ZENOH or tcp/127.0.0.1:7447).",
        ),
        no_bridge: bool = typer.Option(False, "--no-bridge", help="Do not listen for tools."),
        connect: str = typer.Option(
            None,
            "--connect",
            help="Join the simulation at this Zenoh endpoint instead of hosting one: the file's "
            "nodes run here, on its clock (as roslaunch on a second machine).",
        ),
    ) -> None:
        """Run a launch file headless, then print a results table per robot."""
        if list_:
            for name, path in scenarios().items():
                typer.echo(f"{name}\t{path}")
            return
        if not file:
            raise LaunchError("name a launch file or a scenario (fleetsim launch --list)")
        args = list(args or [])
        if args and ":=" not in args[0] and args[0].endswith(LAUNCH_SUFFIXES):
            # roslaunch PACKAGE FILE: `fleetsim launch robocluedo_robot_hunter run2.launch`
            file = str(package_launch_file(file, args.pop(0)))
        from fleetsim.transport.keys import default_endpoint

        endpoint = None if no_bridge else (listen or default_endpoint())
        monitor = run_launch(
            file,
            parse_launch_args(args),
            duration,
            until_goals,
            record,
            viz,
            realtime,
            seed,
            listen=None if connect else endpoint,
            connect=connect,
        )
        if until_goals and not monitor.success():
            # the exit status alone had not said which goal, sender or robot failed
            console.print("--until-goals: exit status 1:", markup=False, highlight=False)
            for line in monitor.failures() or ["the run did not succeed"]:
                console.print(f"  {line}", markup=False, highlight=False)
            raise typer.Exit(1)
