"""Sim clock and the deterministic scheduler.

Time is kept in integer nanoseconds so that periods add up exactly. Events are timers; at equal
times they run by ``(priority, creation order)``: the simulator's physics step (priority -100)
before sensor plugins (-50) before nodes (0). After each callback the graph's pending deliveries
are drained, so a run depends only on its inputs and its seed.

The scheduler never reads the wall clock unless asked to pace a run (``rate``), and then only to
sleep: sim time still advances by exact periods.
"""

from __future__ import annotations

import heapq
import itertools
import time as _wall
from collections.abc import Callable

from fleetsim.errors import FleetsimError

NS = 1_000_000_000


def to_ns(seconds: float) -> int:
    return round(seconds * NS)


class Timer:
    """A periodic (or one-shot) callback in sim time."""

    __slots__ = ("active", "callback", "next_ns", "oneshot", "period_ns", "priority", "seq")

    def __init__(self, period_ns, callback, priority, seq, start_ns, oneshot=False):
        self.period_ns = period_ns
        self.callback = callback
        self.priority = priority
        self.seq = seq
        self.next_ns = start_ns
        self.active = True
        self.oneshot = oneshot

    @property
    def period(self) -> float:
        return self.period_ns / NS

    def cancel(self) -> None:
        self.active = False


class Scheduler:
    """Runs timers in sim-time order and drains message deliveries after each."""

    def __init__(self, drain: Callable[[], int]) -> None:
        self._heap: list[tuple[int, int, int, Timer]] = []
        self._seq = itertools.count()
        self._drain = drain
        self.time_ns = 0
        self._stop = False

    def now(self) -> float:
        return self.time_ns / NS

    def create_timer(
        self,
        period: float,
        callback: Callable[[], None],
        priority: int = 0,
        oneshot: bool = False,
        start: float | None = None,
    ) -> Timer:
        """A timer firing every ``period`` seconds of sim time, first at now + period.

        ``start`` sets the first firing time instead (absolute sim time).
        """
        if not period > 0 and not oneshot:
            raise FleetsimError(f"timer period must be > 0 s, got {period!r}")
        period_ns = max(1, to_ns(period)) if period > 0 else 0
        first = self.time_ns + period_ns if start is None else to_ns(start)
        timer = Timer(period_ns, callback, priority, next(self._seq), first, oneshot)
        heapq.heappush(self._heap, (first, priority, timer.seq, timer))
        return timer

    def stop(self) -> None:
        """Ask a running `run` to return after the current callback."""
        self._stop = True

    def next_time(self) -> float | None:
        while self._heap and not self._heap[0][3].active:
            heapq.heappop(self._heap)
        return self._heap[0][0] / NS if self._heap else None

    def run(
        self,
        until_ns: int | None = None,
        condition: Callable[[], bool] | None = None,
        rate: float | None = None,
    ) -> None:
        """Run events up to and including ``until_ns`` (or forever), or until ``condition()``.

        ``condition`` is checked after each distinct sim time. ``rate`` paces sim time to
        ``rate`` times the wall clock (1.0 = real time).
        """
        heap = self._heap
        drain = self._drain
        self._stop = False
        drain()
        wall0 = _wall.monotonic()
        sim0 = self.time_ns
        last_time = self.time_ns
        while heap and not self._stop:
            t, _prio, _seq, timer = heap[0]
            if until_ns is not None and t > until_ns:
                break
            if t != last_time and condition is not None and condition():
                return
            heapq.heappop(heap)
            if not timer.active:
                continue
            if rate is not None and t != last_time:
                ahead = (t - sim0) / NS / rate - (_wall.monotonic() - wall0)
                if ahead > 0:
                    _wall.sleep(ahead)
            self.time_ns = last_time = t
            if timer.oneshot:
                timer.active = False
            else:
                timer.next_ns = t + timer.period_ns
                heapq.heappush(heap, (timer.next_ns, timer.priority, timer.seq, timer))
            timer.callback()
            drain()
        reached_end = until_ns is not None and not self._stop and self.time_ns < until_ns
        if reached_end and (condition is None or not condition()):
            self.time_ns = until_ns
