"""`fleetsim`: the command-line entry point.

Sub-commands live in their own modules (``cli/urdf.py``, ``cli/sim.py``, ...) as typer apps and
are added here. A `FleetsimError` is printed as one line on stderr, without a traceback, and the
exit status is 1.
"""

from __future__ import annotations

import importlib
import logging
import sys

import typer
from rich.console import Console
from rich.logging import RichHandler

from fleetsim import __version__
from fleetsim.errors import FleetsimError

app = typer.Typer(
    name="fleetsim",
    help="Many namespaced robots, a ROS-like runtime and the navigation stack, on MuJoCo.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

# (module, attribute, command name, help): sub-apps registered if their module is present.
SUBAPPS = [
    ("fleetsim.cli.urdf", "app", "urdf", "Robot descriptions: check, graph, export."),
    ("fleetsim.cli.sim", "app", "sim", "The simulator: world snapshots."),
    ("fleetsim.cli.bag", "app", "bag", "MCAP recordings: info, play, record."),
    ("fleetsim.cli.map", "app", "map", "Maps: save (map_saver), show."),
    ("fleetsim.cli.tools", "topic_app", "topic", "Topics of a running simulation."),
    ("fleetsim.cli.tools", "service_app", "service", "Services of a running simulation."),
    ("fleetsim.cli.tools", "param_app", "param", "Parameters of a running simulation."),
    ("fleetsim.cli.tools", "node_app", "node", "Nodes: list them, or run one in this process."),
    ("fleetsim.cli.tools", "tf_app", "tf", "tf of a running simulation: echo, tree."),
    ("fleetsim.cli.arm", "app", "arm", "Arms: planning groups, named poses, move_group goals."),
    ("fleetsim.cli.batch", "app", "batch", "Sweeps of scenarios, args and seeds on Ray; reports."),
]
# modules with a register(app) function that add single commands
COMMANDS = ["fleetsim.cli.render", "fleetsim.cli.launch", "fleetsim.cli.tools"]

err_console = Console(stderr=True)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"fleetsim {__version__}")
        raise typer.Exit()


#: loggers of libraries whose INFO lines are not the run's news (shown with --verbose)
QUIET_LIBRARIES = ("OpenGL", "numba", "matplotlib", "PIL")


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Print the version and exit."
    ),
    verbose: bool = typer.Option(False, "--verbose", "-v", help="Log debug messages."),
) -> None:
    logging.basicConfig(
        level=logging.DEBUG if verbose else logging.INFO,
        format="%(message)s",
        handlers=[RichHandler(console=err_console, show_path=False, show_time=False)],
        force=True,
    )
    # other libraries' notes at INFO ("No OpenGL_accelerate module loaded"), shown with -v
    for name in QUIET_LIBRARIES:
        logging.getLogger(name).setLevel(logging.NOTSET if verbose else logging.WARNING)


@app.command()
def demo(
    out: str = typer.Option("out", "--out", "-o", help="Folder for the demo's outputs."),
) -> None:
    """Run the main demo headless: three lizis with amcl across the office (navigation_multi),
    recorded to OUT/demo.mcap and rendered to OUT/demo.mp4 and OUT/demo.png."""
    from fleetsim.demo import run_demo

    if not run_demo(out):
        raise typer.Exit(1)


def _add_subapps() -> None:
    for module, attr, name, help_text in SUBAPPS:
        mod = importlib.import_module(module)
        app.add_typer(getattr(mod, attr), name=name, help=help_text)
    for module in COMMANDS:
        importlib.import_module(module).register(app)


_add_subapps()


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; returns the exit status."""
    try:
        # outside standalone mode click hands back a typer.Exit's code as the return value
        code = app(args=argv, standalone_mode=False)
    except FleetsimError as e:
        err_console.print(f"[bold red]error:[/] {e}", highlight=False, soft_wrap=True)
        return 1
    except typer.Exit as e:
        return e.exit_code
    except typer.Abort:
        err_console.print("aborted")
        return 130
    except KeyboardInterrupt:
        return 130
    except typer.TyperException as e:  # usage errors: typer prints them its own way
        e.show()
        return e.exit_code
    return code if isinstance(code, int) else 0


if __name__ == "__main__":
    sys.exit(main())
