"""Running a runtime on another process's ``/clock`` (``fleetsim node run``).

A following runtime never runs ahead of the simulation: `run_following` advances its scheduler
only up to the newest ``/clock`` received, then waits for the next one. Its sim time starts at
the first clock received, so a node joining a simulation at t = 120 s does not replay two
minutes of timers.
"""

from __future__ import annotations

import threading
import time as _wall
from collections.abc import Callable
from typing import Any

from fleetsim.errors import TransportError
from fleetsim.transport.keys import parse_attachment


class ClockFollowing:
    """The ``/clock`` half of `ZenohBridge` (a mixin)."""

    def _init_clock(self, follow: bool, timeout: float) -> None:
        self._clock_ns = -1
        self._clock_origin: str | None = None
        self._clock_event = threading.Event()
        self._clock_sub = None
        self.follows_clock = follow
        if not follow:
            return
        from fleetsim.msgs import deserialize, rosgraph_msgs

        def on_clock(sample: Any) -> None:
            try:
                msg = deserialize(sample.payload.to_bytes(), rosgraph_msgs.Clock)
            except Exception:  # a foreign payload on /clock is ignored, like a bad message
                return
            ns = msg.clock.to_nsec()
            if ns > self._clock_ns:
                self._clock_ns = ns
                self._clock_origin = parse_attachment(sample.attachment)[0] or None
            self._clock_event.set()

        self._clock_sub = self.session.declare_subscriber(
            self.keys.topic("/clock"), on_clock, allowed_origin=self._zenoh.Locality.REMOTE
        )
        if not self._clock_event.wait(timeout):
            self.session.close()
            raise TransportError(
                f"no /clock from a simulation at {', '.join(self.endpoints)} within "
                f"{timeout:g} s (is it running, and does it publish /clock?)"
            )
        scheduler = self.runtime.scheduler
        if scheduler.next_time() is not None and scheduler.time_ns < self._clock_ns:
            self.session.close()
            raise TransportError(
                "create the bridge with follow_clock=True before any node or timer of its "
                "runtime, so that its time can start at the simulation's clock"
            )
        scheduler.time_ns = max(scheduler.time_ns, self._clock_ns)

    @property
    def clock_time(self) -> float:
        """The newest ``/clock`` received, seconds (-1e-9 before any)."""
        return self._clock_ns / 1e9

    def run_following(
        self,
        until: float | None = None,
        stop: threading.Event | None = None,
        idle: Callable[[], None] | None = None,
    ) -> None:
        """Advance the runtime with the remote clock until sim time ``until`` (or forever),
        ``stop`` is set, or the simulation goes away (`TransportError`)."""
        if not self.follows_clock:
            raise TransportError("run_following needs a bridge made with follow_clock=True")
        sched = self.runtime.scheduler
        end = None if until is None else round(until * 1e9)
        while not (stop is not None and stop.is_set()):
            if self._master_lost or self._closed:
                raise TransportError(
                    f"the simulation at {', '.join(self.endpoints)} went away at "
                    f"t = {self.runtime.now():.3f} s"
                )
            target = self._clock_ns if end is None else min(self._clock_ns, end)
            if target > sched.time_ns:
                sched.run(until_ns=target)
                continue
            if end is not None and sched.time_ns >= end:
                return
            self._clock_event.clear()
            if self._clock_ns <= sched.time_ns:
                self._clock_event.wait(0.05)
            self.spin_once()
            if idle is not None:
                idle()

    def wait_for(self, condition: Callable[[], bool], timeout: float) -> bool:
        """Spin (wall clock, without advancing sim time) until ``condition()`` or ``timeout``."""
        deadline = _wall.monotonic() + timeout
        while _wall.monotonic() < deadline:
            self.spin_once()
            if condition():
                return True
            _wall.sleep(0.005)
        return False
