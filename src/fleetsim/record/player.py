"""`Player`: republish a recording into a runtime on sim time (``rosbag play`` / ``ros2 bag play``).

Each message is published when the runtime's sim time reaches ``start + (log_time - t0)``,
where ``t0`` is the recording's first log time and ``start`` the sim time at which playing
began. How fast that is in wall time is the runtime's business (``Runtime.run(rate=R)``), which
is what ``fleetsim bag play --rate R`` passes on. Messages are read from the file lazily, one
time step ahead, so a long recording never sits in memory.

Topics that had a latched publisher when recorded (``/map``, ``/tf_static``) are republished
latched. A topic that already exists in the runtime with another type is an error naming both.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from fleetsim.errors import FleetsimError, RecordingError
from fleetsim.record.reader import BagMessage, BagReader

_log = logging.getLogger("fleetsim.record")

#: players publish after the nodes of the same instant (nodes default to priority 0)
PLAYER_PRIORITY = 10


class Player:
    """Publish the messages of ``path`` into ``runtime`` at their recorded times.

    Parameters
    ----------
    runtime : the `Runtime` to publish into.
    path : an MCAP recording (fleetsim's, or any ROS 2 bag in MCAP with known types).
    topics : global topic names to play; ``None`` plays all.
    start : sim time (s) at which the first message is published; ``None`` is now.
    remaps : ``{recorded topic: topic to publish on}``.
    """

    def __init__(
        self,
        runtime: Any,
        path: str | Path,
        topics: Iterable[str] | None = None,
        start: float | None = None,
        remaps: dict[str, str] | None = None,
    ) -> None:
        self.runtime = runtime
        self.reader = BagReader(path)
        self.topics = None if topics is None else set(topics)
        self.remaps = dict(remaps or {})
        info = self.reader.info()
        known = {t.name for t in info.topics}
        if self.topics is not None and (missing := sorted(self.topics - known)):
            raise RecordingError(
                f"{self.reader.path} has no topic {', '.join(missing)}; it records "
                f"{', '.join(sorted(known)) or 'nothing'}"
            )
        self.info = info
        self._latched = self.reader.latched_topics()
        self._publishers: dict[str, Any] = {}
        self._iter = self.reader.messages(self.topics)
        self._next: BagMessage | None = None
        self.published = 0
        self.done = False
        start_s = runtime.now() if start is None else float(start)
        self._offset_ns = round(start_s * 1e9) - info.start_ns
        self._timer = None
        self._due_ns = 0
        self._advance()

    @property
    def end_time(self) -> float:
        """Sim time (s) of the last message's publication."""
        return (self.info.end_ns + self._offset_ns) / 1e9

    def _publisher(self, m: BagMessage) -> Any:
        pub = self._publishers.get(m.topic)
        if pub is None:
            name = self.remaps.get(m.topic, m.topic)
            try:
                pub = self.runtime.graph.advertise(
                    name, type(m.msg), latch=m.topic in self._latched
                )
            except FleetsimError as e:
                raise RecordingError(f"cannot play {self.reader.path}: {e}") from e
            self._publishers[m.topic] = pub
        return pub

    def _advance(self) -> None:
        """Take the first message and schedule the timer that publishes it."""
        self._next = next(self._iter, None)
        self._schedule()

    def _schedule(self) -> None:
        if self._next is None:
            self.done = True
            _log.info("played %d messages from %s", self.published, self.reader.path)
            return
        self._due_ns = max(self._next.log_time_ns + self._offset_ns, self.runtime.time_ns)
        self._timer = self.runtime.scheduler.create_timer(
            0.0, self._fire, PLAYER_PRIORITY, oneshot=True, start=self._due_ns / 1e9
        )

    def _fire(self) -> None:
        # the timer's time went through float seconds; the exact due time decides
        limit = max(self.runtime.time_ns, self._due_ns)
        while self._next is not None and self._next.log_time_ns + self._offset_ns <= limit:
            m = self._next
            self._publisher(m).publish(m.msg)
            self.published += 1
            self._next = next(self._iter, None)
        self._schedule()

    def stop(self) -> None:
        """Stop playing and withdraw the publishers."""
        if self._timer is not None:
            self._timer.cancel()
        self.done = True
        for pub in self._publishers.values():
            pub.destroy()
        self._publishers.clear()

    def __repr__(self) -> str:
        return f"<Player {self.reader.path}: {self.published}/{self.info.message_count} played>"
