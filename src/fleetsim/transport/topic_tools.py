"""The loops behind ``fleetsim topic echo|hz|pub``: what rostopic does, against a
`SimulationClient`, writing lines through a ``write(text, err=False)`` callback."""

from __future__ import annotations

import time as _wall
from collections.abc import Callable
from typing import Any

from fleetsim.errors import MessageError, TransportError
from fleetsim.transport.client import Received, SimulationClient

Write = Callable[..., Any]


def echo(
    client: SimulationClient,
    name: str,
    write: Write,
    limit: int | None = None,
    timeout: float | None = None,
    no_arrays: bool = False,
) -> int:
    """Write each message on ``name`` as a YAML document ending in ``---``; returns how many.

    Stops after ``limit`` messages; after ``timeout`` wall seconds it returns, or raises
    `TransportError` when fewer than ``limit`` arrived.
    """
    from fleetsim.transport.textout import message_yaml

    got: list[Received] = []
    if name not in client.graph()["topics"]:
        write(f"WARNING: topic [{name}] does not appear to be published yet", err=True)
    client.subscribe(name, got.append)
    printed = 0
    deadline = None if timeout is None else _wall.monotonic() + timeout
    while limit is None or printed < limit:
        if printed < len(got):
            r = got[printed]
            printed += 1
            if isinstance(r.msg, Exception):
                raise r.msg
            write(message_yaml(r.msg, no_arrays=no_arrays) + "---")
            continue
        if deadline is not None and _wall.monotonic() > deadline:
            if limit is not None:
                raise TransportError(f"{name}: {printed} of {limit} messages in {timeout:g} s")
            return printed
        _wall.sleep(0.01)
    return printed


def hz(
    client: SimulationClient,
    name: str,
    write: Write,
    window: int = 1000,
    duration: float | None = None,
) -> dict | None:
    """Report ``name``'s rate every wall second (in sim time when ``/clock`` is published,
    else wall time) for ``duration`` s (or until interrupted); returns the last report."""
    from fleetsim.transport.textout import RateStats

    stats = RateStats(window)
    clock: list[float] = []

    def on_clock(r: Received) -> None:
        if not isinstance(r.msg, Exception):
            clock.append(r.msg.clock.to_sec())

    has_clock = "/clock" in client.graph()["topics"]
    if has_clock:
        client.subscribe("/clock", on_clock, latched=False)

    def on_msg(r: Received) -> None:
        if not has_clock:
            stats.add(r.wall)
        elif clock:  # sim time of arrival, to the clock's resolution (the bridge's pump period)
            stats.add(clock[-1])

    client.subscribe(name, on_msg, latched=False)
    write(f"subscribed to [{name}]")
    end = None if duration is None else _wall.monotonic() + duration
    report = None
    while end is None or _wall.monotonic() < end:
        _wall.sleep(1.0 if end is None else max(0.0, min(1.0, end - _wall.monotonic())))
        del clock[:-1]
        report = stats.report()
        write(stats.format(report) if report else "no new messages")
    return report


def publish(
    client: SimulationClient,
    name: str,
    msg_type: str,
    values: Any,
    write: Write,
    rate: float | None = None,
    count: int | None = None,
    wait: float = 2.0,
) -> int:
    """Publish ``values`` (parsed YAML) as ``msg_type`` on ``name`` once, or at ``rate`` Hz
    (wall) ``count`` times (forever when None); ``stamp: now`` becomes the sim time."""
    from fleetsim.msgs import from_dict, get_type
    from fleetsim.transport.textout import fill_now

    if rate is not None and not rate > 0:
        raise MessageError(f"topic pub: rate must be > 0 Hz, got {rate}")
    cls = get_type(msg_type)
    msg = from_dict(cls, fill_now(values, client.sim_time()), where=f"topic pub {name}")
    pub = client.publisher(name, cls)
    if not pub.wait_for_subscribers(wait):
        write(f"WARNING: no subscriber on {name} yet; publishing anyway", err=True)
    sent = 0
    if rate is None:
        pub.publish(msg)
        write(f"published one message on {name}")
        sent = 1
    else:
        period = 1.0 / rate
        next_t = _wall.monotonic()
        while count is None or sent < count:
            pub.publish(msg)
            sent += 1
            next_t += period
            _wall.sleep(max(0.0, next_t - _wall.monotonic()))
    _wall.sleep(0.1)  # let the last sample leave before the session closes
    return sent
