"""`fleetsim bag`: inspect and replay MCAP recordings (``ros2 bag info`` / ``ros2 bag play``).

fleetsim bag info run.mcap
fleetsim bag play run.mcap --rate 2 [--topics /map --topics /tf] [--no-bridge]
fleetsim bag record -o run.mcap [/map /tf ...] [--duration 60]   (a running simulation)

``play`` republishes on sim time into a fresh runtime; with the Zenoh bridge (the default when
``fleetsim.transport`` is installed) other processes, ``fleetsim topic echo`` and nodes started
with ``fleetsim node run`` see the messages and the ``/clock`` as if a simulation were running.
"""

from __future__ import annotations

import logging
from pathlib import Path

import typer

from fleetsim.errors import FleetsimError

app = typer.Typer(no_args_is_help=True, add_completion=False, pretty_exceptions_enable=False)
_log = logging.getLogger("fleetsim.record")

FILE_ARG = typer.Argument(..., help="An .mcap recording.", show_default=False)
RATE = typer.Option(1.0, "--rate", "-r", help="Sim seconds per wall second.")
TOPICS = typer.Option(
    None, "--topics", help="Play only these topics (repeatable).", show_default=False
)
BRIDGE = typer.Option(True, "--bridge/--no-bridge", help="Serve the replay over the Zenoh bridge.")
LISTEN = typer.Option(
    None, "--listen", help="Bridge endpoint to listen on (default tcp/127.0.0.1:7447)."
)


def _fail(exc: FleetsimError) -> typer.Exit:
    typer.echo(f"error: {exc}", err=True)
    return typer.Exit(1)


@app.command()
def info(file: Path = FILE_ARG) -> None:
    """Print duration, start/end (sim time) and message counts per topic with their types."""
    from fleetsim.record import BagReader, format_info

    try:
        typer.echo(format_info(BagReader(file).info()))
    except FleetsimError as exc:
        raise _fail(exc) from None


def _open_bridge(runtime, listen: list[str] | None):
    """The Zenoh bridge as a simulation peer, or None when fleetsim.transport is absent."""
    try:
        from fleetsim.transport import ZenohBridge
    except ImportError:  # the transport is optional
        _log.warning("fleetsim.transport is not available: playing inside this process only")
        return None
    return ZenohBridge(runtime, mode="peer", listen=listen or None)


@app.command()
def play(
    file: Path = FILE_ARG,
    rate: float = RATE,
    topics: list[str] = TOPICS,
    bridge: bool = BRIDGE,
    listen: list[str] = LISTEN,
) -> None:
    """Republish FILE on sim time (paced at RATE times real time)."""
    from fleetsim.record import Player
    from fleetsim.runtime import Runtime

    if not rate > 0:
        raise _fail(FleetsimError(f"--rate must be > 0 (1.0 is real time), got {rate}"))
    runtime = Runtime()
    try:
        player = Player(runtime, file, topics=topics or None)
        if bridge:
            _open_bridge(runtime, listen)
        total = player.info.message_count
        typer.echo(
            f"playing {total} messages ({player.info.duration_s:.3f} s of sim time) from "
            f"{file} at rate {rate:g}",
            err=True,
        )
        runtime.run(until=lambda: player.done, rate=rate)
        typer.echo(f"played {player.published} messages", err=True)
    except FleetsimError as exc:
        raise _fail(exc) from None
    finally:
        runtime.shutdown()


OUT = typer.Option(..., "--output", "-o", help="The .mcap file to write.")
RECORD_TOPICS = typer.Argument(None, help="Topics to record (default: all).", show_default=False)
DURATION = typer.Option(
    None, "--duration", "-d", help="Sim seconds to record (default: until Ctrl-C)."
)
CONNECT = typer.Option(None, "--connect", help="Simulation endpoint (default tcp/127.0.0.1:7447).")
COMPRESSION = typer.Option("zstd", "--compression", help="zstd, lz4 or none.")


@app.command()
def record(
    topics: list[str] = RECORD_TOPICS,
    output: Path = OUT,
    duration: float = DURATION,
    connect: str = CONNECT,
    compression: str = COMPRESSION,
) -> None:
    """Record a running simulation's topics (all, or TOPICS) to an MCAP file."""
    from fleetsim.record.remote import record_remote

    try:
        rec = record_remote(output, topics or None, connect, duration, compression)
    except FleetsimError as exc:
        raise _fail(exc) from None
    typer.echo(
        f"recorded {rec.message_count} messages on {len(rec.recorded_topics)} topics to {output}",
        err=True,
    )
