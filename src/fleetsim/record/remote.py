"""Recording a simulation that runs in another process (``fleetsim bag record``).

The recorder gets its own `Runtime`, joined to the simulation through the Zenoh bridge as a
client that follows the simulation's ``/clock``, so log times are the simulation's sim time.
The simulation's graph is polled (once a wall second) and every selected topic is subscribed
to as it appears; each message crosses the process boundary once, as CDR.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Iterable
from pathlib import Path

from fleetsim.errors import FleetsimError
from fleetsim.record.writer import Recorder

_log = logging.getLogger("fleetsim.record")


def record_remote(
    path: str | Path,
    topics: Iterable[str] | None = None,
    connect: str | None = None,
    duration: float | None = None,
    compression: str = "zstd",
    stop: threading.Event | None = None,
    poll_period: float = 1.0,
) -> Recorder:
    """Record the simulation at ``connect`` to ``path`` for ``duration`` sim seconds (or until
    ``stop`` is set, or Ctrl-C); returns the closed `Recorder`.

    Raises
    ------
    TransportError
        When no simulation answers at ``connect`` (default ``tcp/127.0.0.1:7447``), or it goes
        away while recording (the file is finalised first).
    """
    from fleetsim.msgs import get_type
    from fleetsim.runtime import Runtime
    from fleetsim.transport import SimulationClient, ZenohBridge

    client = SimulationClient(connect)
    runtime = Runtime()
    bridge = rec = None
    try:
        bridge = ZenohBridge(
            runtime, mode="client", connect=[client.endpoint], follow_clock=True, role="recorder"
        )
        rec = Recorder(
            runtime, path, topics=None if topics is None else list(topics), compression=compression
        )
        last_poll = [0.0]
        skipped: set[str] = set()

        def poll() -> None:
            now = time.monotonic()
            if now - last_poll[0] < poll_period:
                return
            last_poll[0] = now
            for name, info in sorted(client.graph().get("topics", {}).items()):
                typename = str(info.get("type", "")).split(" | ")[0]
                if name in skipped or not typename:
                    continue
                try:
                    rec.record_topic(name, get_type(typename))
                except FleetsimError as e:
                    skipped.add(name)
                    _log.warning("not recording %s: %s", name, e)

        poll()
        until = None if duration is None else runtime.now() + duration
        bridge.run_following(until=until, stop=stop, idle=poll)
    finally:
        if rec is not None:
            rec.close()
        if bridge is not None:
            bridge.close()
        client.close()
        runtime.shutdown()
    return rec
