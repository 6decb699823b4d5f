"""`fleetsim sim`: simulator commands (``snapshot``: a picture of a world)."""

from __future__ import annotations

from pathlib import Path

import typer

from fleetsim.errors import SimulationError

app = typer.Typer(no_args_is_help=True, help="The simulator: world snapshots.")


@app.callback()
def _sim() -> None:
    """The simulator: world snapshots."""


def _robot_option(text: str) -> tuple[str, str, tuple[float, ...]]:
    """``FILE[:NAME[:X,Y[,YAW]]]`` -> (file, name, pose)."""
    parts = text.split(":")
    file = parts[0]
    name = parts[1] if len(parts) > 1 and parts[1] else Path(file).stem.split(".")[0]
    pose = [0.0] * 6
    if len(parts) > 2:
        try:
            vals = [float(v) for v in parts[2].split(",")]
        except ValueError:
            raise SimulationError(f"--robot '{text}': pose must be X,Y[,YAW] numbers") from None
        pose[0], pose[1] = vals[0], vals[1] if len(vals) > 1 else 0.0
        if len(vals) > 2:
            pose[5] = vals[2]
    return file, name, tuple(pose)


@app.command()
def snapshot(
    world: Path = typer.Argument(..., help="SDF .world or map_server .yaml"),
    output: Path = typer.Option(Path("world.png"), "-o", "--output", help="PNG file to write"),
    width: int = typer.Option(1280, help="image width, pixels"),
    height: int = typer.Option(960, help="image height, pixels"),
    view: str = typer.Option("top", help="top | perspective"),
    robot: list[str] = typer.Option(
        [], "--robot", "-r", help="robot to place: URDF/xacro[:NAME[:X,Y[,YAW]]] (repeatable)"
    ),
    settle: float = typer.Option(0.0, help="seconds of physics to run before the picture"),
) -> None:
    """Render an overview of WORLD (and optional robots) to a PNG."""
    from PIL import Image

    from fleetsim.sim import Engine
    from fleetsim.sim.snapshot import overview_image

    if view not in ("top", "perspective"):
        raise SimulationError(f"--view must be 'top' or 'perspective', got '{view}'")
    engine = Engine(world)
    for item in robot:
        file, name, pose = _robot_option(item)
        engine.spawn_robot(name, file, pose)
    if settle > 0:
        engine.advance(settle)
    img = overview_image(engine, width, height, view)
    Image.fromarray(img).save(output)
    typer.echo(f"wrote {output} ({width}x{height}, {len(engine.models)} models)")
