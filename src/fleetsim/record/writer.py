"""`Recorder`: writes every topic (or a chosen few) of a runtime to an MCAP file, as it runs.

The file is a ROS 2 bag: profile ``ros2``, one schema per message type with encoding
``ros2msg`` (the type's definition with its dependencies), messages as CDR, chunked and
compressed. ``log_time`` and ``publish_time`` are the sim time in nanoseconds at which the
message was delivered, so a recording of a deterministic run is itself deterministic.

Messages are written as they arrive (one chunk of at most ``chunk_size`` bytes is held in
memory), and the file is finalised (indexes and summary written) by `Recorder.close`, which runs
on `Runtime.shutdown`, at interpreter exit, and from the caller's ``try/finally`` after Ctrl-C or
an error in a node. `close` may be called any number of times.

Topics are found through the graph's listeners: the recorder subscribes to each topic the
moment it is advertised or subscribed to, so topics that appear in the middle of a run (a robot
spawned later) are recorded from their first message. Latched messages (``/map``,
``/tf_static``) published before the recorder started are recorded too.

At close the runtime's parameter tree is stored as MCAP metadata named ``fleetsim/params``
(one key ``yaml``), so renders can find robot footprints, and the topics that had a latched
publisher as ``fleetsim/latched``, so a replay can latch them again.
"""

from __future__ import annotations

import atexit
import logging
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType, Writer

from fleetsim import __version__
from fleetsim.errors import RecordingError

_log = logging.getLogger("fleetsim.record")

COMPRESSIONS = {
    "zstd": CompressionType.ZSTD,
    "lz4": CompressionType.LZ4,
    "none": CompressionType.NONE,
}
#: metadata record holding the parameter tree as YAML
PARAMS_METADATA = "fleetsim/params"
#: metadata record listing the topics that had a latched publisher (key ``topics``, one a line)
LATCHED_METADATA = "fleetsim/latched"


def _global_topic(name: str) -> str:
    name = name.strip()
    if not name or name == "/":
        raise RecordingError(f"topic name {name!r} is empty; give global names such as /scan")
    return name if name.startswith("/") else "/" + name


class Recorder:
    """Record topics of ``runtime`` to the MCAP file ``path`` until `close`.

    Parameters
    ----------
    runtime : the `Runtime` whose graph is recorded.
    path : the ``.mcap`` file to write (its folder is created; an existing file is replaced).
    topics : global topic names to record; ``None`` records every topic, present and future.
    compression : ``"zstd"`` (default), ``"lz4"`` or ``"none"``; applied per chunk.
    chunk_size : bytes of messages gathered before a chunk is compressed and written.
    """

    def __init__(
        self,
        runtime: Any,
        path: str | Path,
        topics: list[str] | None = None,
        compression: str = "zstd",
        chunk_size: int = 1024 * 1024,
    ) -> None:
        if compression not in COMPRESSIONS:
            raise RecordingError(
                f"compression {compression!r} is not supported; use one of "
                f"{', '.join(COMPRESSIONS)}"
            )
        if chunk_size <= 0:
            raise RecordingError(f"chunk_size must be > 0 bytes, got {chunk_size}")
        self.runtime = runtime
        self.path = Path(path)
        self.topics = None if topics is None else {_global_topic(t) for t in topics}
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = open(self.path, "wb")  # noqa: SIM115 - closed in close()
        except OSError as e:
            raise RecordingError(f"{self.path}: cannot write the recording ({e.strerror})") from e
        self._writer = Writer(
            self._file, chunk_size=chunk_size, compression=COMPRESSIONS[compression]
        )
        self._writer.start(profile="ros2", library=f"fleetsim {__version__}")
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._subs: list[Any] = []
        self._latched: set[str] = set()
        self.message_count = 0
        self.closed = False
        graph = runtime.graph
        graph.listeners.append(self._on_graph_event)
        for name, topic in sorted(graph.topics.items()):
            self._maybe_record(name, topic)
        runtime.on_shutdown(self.close)
        atexit.register(self.close)

    # -- topics -----------------------------------------------------------------------------
    def _on_graph_event(self, event: str, name: str, obj: Any) -> None:
        if event in ("advertise", "subscribe") and not self.closed:
            self._maybe_record(name, obj.topic)
            if event == "advertise" and obj.latch and name in self._channels:
                self._latched.add(name)

    def _maybe_record(self, name: str, topic: Any) -> None:
        if any(p.latch for p in topic.publishers) and self._wanted(name):
            self._latched.add(name)
        self.record_topic(name, topic.type)

    def _wanted(self, name: str) -> bool:
        return self.topics is None or name in self.topics

    def record_topic(self, name: str, msg_type: Any) -> None:
        """Record ``name`` (a global topic of ``msg_type``) from now on, if it is selected.

        Topics of the runtime's graph are found by themselves; this is for topics that exist
        elsewhere (another process, through the Zenoh bridge) and have no local end yet.
        """
        if name in self._channels or not self._wanted(name) or self.closed:
            return
        from fleetsim.msgs import msgdef, type_name

        typename = type_name(msg_type)
        schema_id = self._schemas.get(typename)
        if schema_id is None:
            schema_id = self._writer.register_schema(
                name=typename, encoding="ros2msg", data=msgdef(msg_type).encode()
            )
            self._schemas[typename] = schema_id
        channel_id = self._writer.register_channel(
            topic=name, message_encoding="cdr", schema_id=schema_id
        )
        self._channels[name] = channel_id
        callback = self._make_callback(channel_id)
        # registered before subscribing: the subscribe event comes back to _on_graph_event
        self._subs.append(self.runtime.graph.subscribe(name, msg_type, callback, queue_size=0))

    def _make_callback(self, channel_id: int):
        from fleetsim.msgs import serialize

        writer = self._writer
        runtime = self.runtime

        def on_message(msg: Any) -> None:
            if self.closed:
                return
            t = runtime.time_ns
            self.message_count += 1
            writer.add_message(
                channel_id=channel_id,
                log_time=t,
                data=serialize(msg),
                publish_time=t,
                sequence=self.message_count,
            )

        return on_message

    @property
    def recorded_topics(self) -> list[str]:
        """The topics being recorded so far, sorted."""
        return sorted(self._channels)

    # -- finishing --------------------------------------------------------------------------
    def flush(self) -> None:
        """Write the chunk in progress to disk now (a crash after this loses nothing before)."""
        if not self.closed:
            self._writer.flush()

    def close(self) -> None:
        """Stop recording and finalise the file (indexes, statistics, summary). Idempotent."""
        if self.closed:
            return
        self.closed = True
        atexit.unregister(self.close)
        graph = self.runtime.graph
        if self._on_graph_event in graph.listeners:
            graph.listeners.remove(self._on_graph_event)
        # deliver what is still queued for us before unsubscribing, then stop
        self.closed = False
        for sub in self._subs:
            while sub.queue:
                sub.callback(sub.queue.popleft())
        self.closed = True
        for sub in self._subs:
            sub.destroy()
        self._subs.clear()
        try:
            self._write_params()
            self._writer.add_metadata(
                LATCHED_METADATA, {"topics": "\n".join(sorted(self._latched))}
            )
            self._writer.finish()
        finally:
            self._file.close()
        _log.info("recorded %d messages to %s", self.message_count, self.path)

    def _write_params(self) -> None:
        import yaml

        params = getattr(self.runtime, "params", None)
        if params is None:
            return
        try:
            tree = params.get("/", {})
            text = yaml.safe_dump(tree, sort_keys=True)
        except Exception as e:  # a parameter YAML cannot represent: keep the recording
            _log.warning("recording %s: parameters not stored (%s)", self.path, e)
            return
        self._writer.add_metadata(PARAMS_METADATA, {"yaml": text})

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self.closed else "recording"
        return f"<Recorder {self.path} {state}, {self.message_count} messages>"
