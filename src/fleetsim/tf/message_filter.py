"""Messages held until tf can answer for them: tf2_ros's ``MessageFilter``.

A node whose data needs a transform at the data's stamp (amcl's and gmapping's scans need
``odom -> base`` at the scan's stamp) queues it here. The queue is processed in arrival order;
when the head cannot be processed yet, the filter waits for the next tf message that adds a
transform (`Buffer.call_after_next_message`, tf2's transformable callback) and tries again, so
that the node need not receive every ``/tf`` message itself.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any


class MessageFilter:
    """A bounded queue of messages, each handed to ``process`` once tf can answer for it.

    ``process(msg)`` returns False when tf cannot answer for ``msg`` yet (the message stays at
    the head and is retried after the next tf message; with ``frames(msg)`` giving the
    (target, source) frames it needs, after the next one that moves an edge between them),
    True when it is done with it (used or dropped). ``queue_size`` bounds the queue; the
    oldest message goes first, as in tf2.
    """

    __slots__ = ("_buffer", "_frames", "_process", "queue")

    def __init__(
        self,
        buffer: Any,
        process: Callable[[Any], bool],
        queue_size: int,
        frames: Callable[[Any], tuple[str, str]] | None = None,
    ) -> None:
        self._buffer = buffer
        self._process = process
        self._frames = frames  # (target, source) a message needs: wait only on their edges
        self.queue: deque = deque(maxlen=queue_size)

    def __len__(self) -> int:
        return len(self.queue)

    def add(self, msg: Any) -> None:
        """Queue ``msg`` and process every queued message that tf can answer for."""
        self.queue.append(msg)
        self.drain()

    def drain(self) -> None:
        """Process queued messages in order until one must wait for tf."""
        queue = self.queue
        while queue:
            if not self._process(queue[0]):
                buf = self._buffer
                edges = buf.edges_between(*self._frames(queue[0])) if self._frames else None
                buf.call_after_next_message(self.drain, edges)
                return
            queue.popleft()
