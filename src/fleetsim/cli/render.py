"""`fleetsim render FILE.mcap -o out.mp4|out.png`: a top-down render of a recording.

The lead adds it to the root app with ``register(app)``.
"""

from __future__ import annotations

from pathlib import Path

import typer

from fleetsim.errors import FleetsimError

FILE_ARG = typer.Argument(..., help="An .mcap recording.", show_default=False)
OUT = typer.Option(..., "--out", "-o", help="out.png (last frame) or out.mp4 (the run).")
FPS = typer.Option(10.0, "--fps", help="Video frames per second (MP4).")
SPEED = typer.Option(1.0, "--speed", help="Sim seconds per video second (MP4).")
WIDTH = typer.Option(800, "--width", help="Image width in pixels.")
FIXED_FRAME = typer.Option("map", "--fixed-frame", help="The tf frame the view is drawn in.")
MAP_TOPIC = typer.Option("/map", "--map-topic", help="OccupancyGrid drawn as the background.")
PROGRESS = typer.Option(True, "--progress/--no-progress", help="Show a progress bar (MP4).")


def render(
    file: Path = FILE_ARG,
    out: Path = OUT,
    fps: float = FPS,
    speed: float = SPEED,
    width: int = WIDTH,
    fixed_frame: str = FIXED_FRAME,
    map_topic: str = MAP_TOPIC,
    progress: bool = PROGRESS,
) -> None:
    """Draw FILE from above: map, robots with footprints and names, laser points, plans,
    particle clouds and goals. PNG: the last instant with trails; MP4: the whole run."""
    from fleetsim.viz.render import render as render_file

    try:
        res = render_file(
            file, out, fps=fps, speed=speed, width=width, fixed_frame=fixed_frame,
            map_topic=map_topic, progress=progress,
        )  # fmt: skip
    except FleetsimError as exc:
        typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(1) from None
    what = f"{res.frames} frames" if res.frames > 1 else "1 frame"
    typer.echo(f"Created file {res.path} ({what}, {res.width}x{res.height})")


def register(app: typer.Typer) -> None:
    """Add the ``render`` command to ``app`` (the root ``fleetsim`` app)."""
    app.command(name="render")(render)
