"""``fleetsim map save|show``: map_saver, and a picture of a map with its metadata.

``save`` writes ``NAME.pgm`` + ``NAME.yaml`` as ``rosrun map_server map_saver -f NAME`` does,
from the latched ``/map`` of a running simulation (over the Zenoh transport) or, with
``--bag``, from the last ``/map`` in an MCAP recording. ``show`` prints a map YAML's metadata
and, with ``-o``, draws it to a PNG in map coordinates.

The root app adds this one as ``("fleetsim.cli.map", "app", "map", ...)`` in its SUBAPPS.
"""

from __future__ import annotations

import math
import threading
from pathlib import Path
from typing import Any

import numpy as np
import typer

from fleetsim.errors import FleetsimError
from fleetsim.nav.errors import MapError

app = typer.Typer(no_args_is_help=True, add_completion=False, pretty_exceptions_enable=False)

NAME = typer.Option("map", "-f", "--file", help="Output base name: NAME.pgm and NAME.yaml.")
TOPIC = typer.Option("/map", "--topic", help="The nav_msgs/OccupancyGrid topic to save.")
BAG = typer.Option(None, "--bag", help="Read the map from this MCAP file instead.")
CONNECT = typer.Option(None, "--connect", help="The simulation's Zenoh endpoint.")
TIMEOUT = typer.Option(5.0, "--timeout", help="Seconds to wait for the map.")
OCC = typer.Option(65, "--occ", help="Occupied threshold (map_saver's --occ), 1..100.")
FREE = typer.Option(25, "--free", help="Free threshold (map_saver's --free), 0..99.")


def occupancy_from_grid(msg: Any, where: str) -> Any:
    """An `OccupancyMap` from a nav_msgs/OccupancyGrid message (``where`` names its source)."""
    from fleetsim.nav.map_io import OccupancyMap

    info = msg.info
    w, h = int(info.width), int(info.height)
    data = np.asarray(msg.data, dtype=np.int8)
    if w <= 0 or h <= 0 or data.size != w * h:
        raise MapError(
            f"{where}: the OccupancyGrid is {w} x {h} cells but carries {data.size} values"
        )
    q = info.origin.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    origin = (float(info.origin.position.x), float(info.origin.position.y), yaw)
    return OccupancyMap(data.reshape(h, w).copy(), float(info.resolution), origin)


def grid_from_bag(path: Path, topic: str) -> Any:
    """The last OccupancyGrid on ``topic`` in the MCAP file ``path``."""
    from fleetsim.record import BagReader

    reader = BagReader(path)
    last = None
    for m in reader.messages(topics=[topic], allow_truncated=True):
        last = m.msg
    if last is None:
        topics = sorted(t.name for t in reader.info().topics)
        grids = [t.name for t in reader.info().topics if t.typename.endswith("OccupancyGrid")]
        hint = f"; OccupancyGrid topics there: {', '.join(grids)}" if grids else ""
        raise MapError(
            f"{path}: no messages on {topic} (recorded topics: {', '.join(topics) or 'none'})"
            f"{hint}; choose one with --topic"
        )
    return last


def grid_from_simulation(topic: str, connect: str | None, timeout: float) -> Any:
    """The latched OccupancyGrid on ``topic`` of the running simulation."""
    from fleetsim.transport import SimulationClient

    got: list[Any] = []
    arrived = threading.Event()

    def on_msg(received: Any) -> None:
        if not isinstance(received.msg, Exception) and not got:
            got.append(received.msg)
            arrived.set()

    with SimulationClient(connect, timeout=min(timeout, 5.0)) as client:
        have = client.topic_type(topic)
        if have is None:
            # a SLAM robot's map is in its namespace (/lizi1/map): name the grids there are
            grids = sorted(
                name
                for name, info in client.graph()["topics"].items()
                if "OccupancyGrid" in info["type"]
            )
            there = f"; OccupancyGrids are on {', '.join(grids[:6])}" if grids else ""
            raise MapError(
                f"the simulation at {client.endpoint} has no topic {topic}{there}; is map_server "
                "running? (choose another topic with --topic)"
            )
        if "OccupancyGrid" not in have:
            raise MapError(f"{topic} carries {have}, not nav_msgs/msg/OccupancyGrid")
        client.subscribe(topic, on_msg, latched=True)
        if not arrived.wait(timeout):
            raise MapError(f"no map arrived on {topic} within {timeout:g} s")
    return got[0]


@app.command()
def save(
    file: str = NAME,
    topic: str = TOPIC,
    bag: Path | None = BAG,
    connect: str | None = CONNECT,
    timeout: float = TIMEOUT,
    occ: int = OCC,
    free: int = FREE,
) -> None:
    """Save a map as NAME.pgm + NAME.yaml (map_saver), from a running simulation or --bag."""
    from fleetsim.nav.map_io import save_map

    try:
        if bag is not None:
            msg, where = grid_from_bag(bag, topic), f"{bag} {topic}"
        else:
            msg, where = grid_from_simulation(topic, connect, timeout), topic
        occupancy = occupancy_from_grid(msg, where)
        pgm, yml = save_map(occupancy, file, occupied_threshold=occ, free_threshold=free)
    except FleetsimError as exc:
        typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(1) from None
    typer.echo(
        f"Saved a {occupancy.width} x {occupancy.height} map at {occupancy.resolution:g} m/cell "
        f"from {where} to {pgm} and {yml}"
    )


def metadata_lines(path: Path, occupancy: Any) -> list[str]:
    """What `show` prints: size, resolution, extent, origin and the share of each cell kind."""
    d = occupancy.data
    ox, oy, oyaw = occupancy.origin
    res = occupancy.resolution
    n = d.size
    free = int(np.count_nonzero(d == 0))
    unknown = int(np.count_nonzero(d < 0))
    occupied = int(np.count_nonzero(d >= 65))
    return [
        f"map: {path}",
        f"size: {occupancy.width} x {occupancy.height} cells, resolution {res:g} m/cell",
        f"extent: x {ox:g} .. {ox + occupancy.width * res:g} m, "
        f"y {oy:g} .. {oy + occupancy.height * res:g} m "
        f"({occupancy.width * res:g} x {occupancy.height * res:g} m)",
        f"origin: ({ox:g}, {oy:g}, yaw {oyaw:g})",
        f"cells: {100 * free / n:.1f} % free, {100 * occupied / n:.1f} % occupied, "
        f"{100 * unknown / n:.1f} % unknown",
    ]


def render_map_png(occupancy: Any, out: Path, title: str, lines: list[str], width: int) -> None:
    """Draw the grid in map coordinates (free white, occupied black, unknown grey) with the
    metadata under it, to ``out`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d = occupancy.data
    img = np.full(d.shape, 0.8)  # unknown
    img[d >= 0] = 1.0 - np.clip(d[d >= 0], 0, 100) / 100.0
    ox, oy, _ = occupancy.origin
    res = occupancy.resolution
    extent = (ox, ox + occupancy.width * res, oy, oy + occupancy.height * res)
    aspect = occupancy.height / occupancy.width
    dpi = 100
    w_in = width / dpi
    img_h = 0.85 * w_in * aspect  # the axes are 85 % of the width; cells stay square
    h_in = 1.3 + img_h + 0.4  # metadata text below, title above
    fig = plt.figure(figsize=(w_in, h_in), dpi=dpi)
    ax = fig.add_axes((0.1, 1.3 / h_in, 0.85, img_h / h_in))
    ax.imshow(img, cmap="gray", vmin=0.0, vmax=1.0, origin="lower", extent=extent)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title, fontsize=10)
    fig.text(0.02, 0.02, "\n".join(lines[1:]), fontsize=8, family="monospace", va="bottom")
    try:
        fig.savefig(out, dpi=dpi)
    except OSError as e:
        raise MapError(f"cannot write {out}: {e.strerror}") from None
    finally:
        plt.close(fig)


@app.command()
def show(
    map_yaml: Path = typer.Argument(..., help="A map YAML (map_server's format)."),
    out: Path | None = typer.Option(None, "--out", "-o", help="Draw the map to this PNG."),
    width: int = typer.Option(800, "--width", help="Image width in pixels."),
) -> None:
    """Print a map's metadata; with -o, draw it (map coordinates, metadata below) to a PNG."""
    from fleetsim.nav.map_io import load_map

    try:
        if width < 100:
            raise MapError(f"--width must be at least 100 pixels, got {width}")
        occupancy = load_map(map_yaml)
        lines = metadata_lines(map_yaml, occupancy)
        if out is not None:
            if out.suffix.lower() != ".png":
                raise MapError(f"-o {out}: the picture is written as PNG; give a .png name")
            render_map_png(occupancy, out, map_yaml.name, lines, width)
    except FleetsimError as exc:
        typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(1) from None
    for line in lines:
        typer.echo(line)
    if out is not None:
        typer.echo(f"Created file {out}")
