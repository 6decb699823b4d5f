"""`fleetsim urdf`: check, graph and export robot descriptions (xacro or URDF), without ROS.

fleetsim urdf check hunter.urdf.xacro [name:=value ...]
fleetsim urdf graph lizi.urdf.xacro -o out/
fleetsim urdf export jackal.urdf.xacro -o jackal.urdf
"""

from __future__ import annotations

from pathlib import Path

import typer

from fleetsim.errors import FleetsimError

app = typer.Typer(no_args_is_help=True, add_completion=False, pretty_exceptions_enable=False)

FILE_ARG = typer.Argument(..., help="A .urdf or .xacro robot description.")
XACRO_ARGS = typer.Argument(None, help="xacro arguments, name:=value.", show_default=False)
PKG_PATH = typer.Option(
    None,
    "--package-path",
    "-p",
    help="Folder searched for packages ($(find pkg), package://); repeatable.",
)
GRAPH_OUT = typer.Option(Path("."), "--out", "-o", help="Folder for NAME.gv and NAME.pdf.")
EXPORT_OUT = typer.Option(None, "--out", "-o", help="URDF file to write (stdout if absent).")


def _load(file: Path, xacro_args: list[str] | None, package_path: list[Path] | None):
    from fleetsim.description.urdf import load_robot
    from fleetsim.description.xacro import parse_cli_args

    return load_robot(file, parse_cli_args(xacro_args or []), package_path)


def _fail(exc: FleetsimError) -> typer.Exit:
    typer.echo(f"Error: {exc}", err=True)
    return typer.Exit(1)


@app.command()
def check(
    file: Path = FILE_ARG,
    xacro_args: list[str] = XACRO_ARGS,
    package_path: list[Path] = PKG_PATH,
) -> None:
    """Parse FILE and print its link tree, as ROS's check_urdf does."""
    from fleetsim.description.tree import check_report

    try:
        robot = _load(file, xacro_args, package_path)
        typer.echo(check_report(robot), nl=False)
    except FleetsimError as exc:
        raise _fail(exc) from None


@app.command()
def graph(
    file: Path = FILE_ARG,
    xacro_args: list[str] = XACRO_ARGS,
    out: Path = GRAPH_OUT,
    package_path: list[Path] = PKG_PATH,
) -> None:
    """Write NAME.gv and NAME.pdf (links as boxes, joints as ellipses), as urdf_to_graphiz."""
    from fleetsim.description.tree import write_graph

    try:
        robot = _load(file, xacro_args, package_path)
        gv, pdf = write_graph(robot, out)
    except FleetsimError as exc:
        raise _fail(exc) from None
    typer.echo(f"Created file {gv}")
    typer.echo(f"Created file {pdf}")


@app.command()
def export(
    file: Path = FILE_ARG,
    xacro_args: list[str] = XACRO_ARGS,
    out: Path = EXPORT_OUT,
    package_path: list[Path] = PKG_PATH,
) -> None:
    """Expand and validate FILE, then write plain URDF (what `xacro FILE > X.urdf` gives)."""
    try:
        robot = _load(file, xacro_args, package_path)
        text = robot.to_urdf()
        if out is None:
            typer.echo(text, nl=False)
            return
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text)
    except FleetsimError as exc:
        raise _fail(exc) from None
    except OSError as exc:
        raise _fail(FleetsimError(f"{out}: cannot write ({exc.strerror})")) from None
    typer.echo(f"Created file {out}")
