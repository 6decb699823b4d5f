"""Reading MCAP recordings back: messages (decoded to fleetsim dataclasses), summary, metadata.

`BagReader` opens a file and checks it is MCAP. A complete file (written to the end, with its
summary) is read through its index in log-time order; a file cut short (a killed process, a
copy in progress) is read record by record, and after the last whole chunk a `RecordingError`
says so: ``x.mcap is truncated after N messages: ...``. ``allow_truncated=True`` keeps the
messages that survived and stops there quietly.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from mcap.exceptions import EndOfFile, McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Footer, Message, Metadata, Schema
from mcap.stream_reader import StreamReader

from fleetsim.errors import FleetsimError, RecordingError
from fleetsim.record.writer import LATCHED_METADATA, PARAMS_METADATA

_log = logging.getLogger("fleetsim.record")

MAGIC = b"\x89MCAP0\r\n"


def _read_errors() -> tuple[type[BaseException], ...]:
    errors: list[type[BaseException]] = [
        McapError,
        EndOfFile,
        struct.error,
        ValueError,
        KeyError,
        OSError,
        EOFError,
    ]
    import zstandard

    errors.append(zstandard.ZstdError)
    return tuple(errors)


#: what the mcap library raises on bytes that are cut short or damaged
READ_ERRORS = _read_errors()


@dataclass(frozen=True, slots=True)
class BagMessage:
    """One recorded message: its topic, ROS 2 type name, log time (ns) and content.

    ``msg`` is the decoded fleetsim message (``None`` when read with ``decode=False``);
    ``data`` is the CDR bytes as stored.
    """

    topic: str
    typename: str
    log_time_ns: int
    data: bytes
    msg: Any = None


@dataclass(frozen=True, slots=True)
class TopicInfo:
    name: str
    typename: str
    count: int
    encoding: str
    latched: bool


@dataclass(frozen=True, slots=True)
class BagInfo:
    """What ``fleetsim bag info`` prints: size, time span and per-topic counts."""

    path: Path
    size_bytes: int
    profile: str
    library: str
    start_ns: int
    end_ns: int
    message_count: int
    topics: tuple[TopicInfo, ...]
    compression: str

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.start_ns) / 1e9 if self.message_count else 0.0


def _size_text(n: int) -> str:
    size = float(n)
    for unit in ("B", "KiB", "MiB", "GiB"):
        if size < 1024 or unit == "GiB":
            return f"{size:.1f} {unit}" if unit != "B" else f"{n} B"
        size /= 1024
    return f"{n} B"  # pragma: no cover


def format_info(info: BagInfo) -> str:
    """``ros2 bag info``'s layout: files, size, duration, start/end (sim seconds), topics."""
    lines = [
        f"Files:             {info.path.name}",
        f"Bag size:          {_size_text(info.size_bytes)}",
        "Storage id:        mcap",
        f"Profile:           {info.profile or '-'} (compression: {info.compression or 'none'})",
        f"Duration:          {info.duration_s:.9f}s",
        f"Start:             {info.start_ns / 1e9:.9f} (sim time)",
        f"End:               {info.end_ns / 1e9:.9f} (sim time)",
        f"Messages:          {info.message_count}",
    ]
    width = max((len(t.name) for t in info.topics), default=0)
    twidth = max((len(t.typename) for t in info.topics), default=0)
    for i, t in enumerate(info.topics):
        head = "Topic information: " if i == 0 else " " * 19
        lines.append(
            f"{head}Topic: {t.name:<{width}} | Type: {t.typename:<{twidth}} | "
            f"Count: {t.count} | Serialization Format: {t.encoding}"
            + (" | latched" if t.latched else "")
        )
    if not info.topics:
        lines.append("Topic information: (no topics)")
    return "\n".join(lines)


class BagReader:
    """An MCAP recording on disk.

    Raises
    ------
    RecordingError
        If the file is missing, unreadable or not MCAP.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        try:
            with open(self.path, "rb") as f:
                head = f.read(len(MAGIC))
                f.seek(0, 2)
                self.size_bytes = f.tell()
                f.seek(max(0, self.size_bytes - len(MAGIC)))
                tail = f.read(len(MAGIC))
        except FileNotFoundError:
            raise RecordingError(f"{self.path}: no such file") from None
        except IsADirectoryError:
            raise RecordingError(
                f"{self.path} is a folder; give the .mcap file inside a ROS 2 bag folder"
            ) from None
        except OSError as e:
            raise RecordingError(f"{self.path}: cannot read ({e.strerror})") from e
        if head != MAGIC:
            raise RecordingError(
                f"{self.path} is not an MCAP file (it starts with {head[:8]!r}, not the MCAP "
                "magic); record one with `--record FILE.mcap` or `fleetsim bag record`"
            )
        self.complete = self.size_bytes >= 2 * len(MAGIC) and tail == MAGIC
        self._decoders: dict[str, type] = {}

    # -- messages ---------------------------------------------------------------------------
    def messages(
        self,
        topics: Iterable[str] | None = None,
        decode: bool = True,
        allow_truncated: bool = False,
    ) -> Iterator[BagMessage]:
        """Yield the recorded messages in log-time order (file order for a truncated file).

        Parameters
        ----------
        topics : only these topics (global names); ``None`` for all.
        decode : decode each message to its fleetsim class (``BagMessage.msg``).
        allow_truncated : for a file cut short, stop after the last whole chunk instead of
            raising.
        """
        wanted = None if topics is None else set(topics)
        if self.complete:
            yield from self._indexed(wanted, decode)
        else:
            yield from self._streamed(wanted, decode, allow_truncated)

    def _indexed(self, wanted: set[str] | None, decode: bool) -> Iterator[BagMessage]:
        n = 0
        with open(self.path, "rb") as f:
            try:
                reader = SeekingReader(f)
                for schema, channel, message in reader.iter_messages(
                    topics=wanted, log_time_order=True
                ):
                    yield self._message(schema, channel, message, decode)
                    n += 1
            except READ_ERRORS as e:
                raise self._corrupt(n, e) from e

    def _streamed(
        self, wanted: set[str] | None, decode: bool, allow_truncated: bool
    ) -> Iterator[BagMessage]:
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        n = 0
        with open(self.path, "rb") as f:
            records = StreamReader(f).records
            while True:
                try:
                    record = next(records)
                except StopIteration:
                    return
                except READ_ERRORS as e:
                    if allow_truncated:
                        _log.warning("%s", self._truncated(n, e))
                        return
                    raise self._truncated(n, e) from e
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    channels[record.id] = record
                elif isinstance(record, Message):
                    channel = channels.get(record.channel_id)
                    if channel is None:
                        raise self._corrupt(n, f"message on unknown channel {record.channel_id}")
                    if wanted is not None and channel.topic not in wanted:
                        continue
                    yield self._message(schemas.get(channel.schema_id), channel, record, decode)
                    n += 1
                elif isinstance(record, Footer):
                    return

    def _truncated(self, n: int, cause: Any) -> RecordingError:
        if isinstance(cause, EndOfFile | struct.error | EOFError):
            why = "the file ends inside a record"
        else:
            why = f"{type(cause).__name__}: {cause}"
        return RecordingError(
            f"{self.path} is truncated after {n} messages: {why} (the recording was not "
            "finalised, e.g. its process was killed; the messages before this point can be "
            "read with allow_truncated=True)"
        )

    def _corrupt(self, n: int, cause: Any) -> RecordingError:
        why = cause if isinstance(cause, str) else f"{type(cause).__name__}: {cause}"
        return RecordingError(f"{self.path} is corrupt after {n} messages: {why}")

    def _message(
        self, schema: Schema | None, channel: Channel, message: Message, decode: bool
    ) -> BagMessage:
        typename = schema.name if schema is not None else ""
        data = bytes(message.data)
        msg = None
        if decode:
            if channel.message_encoding != "cdr":
                raise RecordingError(
                    f"{self.path}: topic {channel.topic} is encoded as "
                    f"{channel.message_encoding!r}; fleetsim decodes ROS 2 'cdr' messages only"
                )
            msg = self._decode(data, typename, channel.topic)
        return BagMessage(channel.topic, typename, message.log_time, data, msg)

    def _decode(self, data: bytes, typename: str, topic: str) -> Any:
        from fleetsim.msgs import deserialize, get_type

        cls = self._decoders.get(typename)
        if cls is None:
            try:
                cls = self._decoders[typename] = get_type(typename)
            except FleetsimError as e:
                raise RecordingError(f"{self.path}: topic {topic}: {e}") from e
        try:
            return deserialize(data, cls)
        except FleetsimError as e:
            raise RecordingError(f"{self.path}: topic {topic}: {e}") from e

    # -- summary ----------------------------------------------------------------------------
    def info(self) -> BagInfo:
        """Time span and per-topic message counts (from the summary, or by reading the file)."""
        if self.complete:
            with open(self.path, "rb") as f:
                try:
                    reader = SeekingReader(f)
                    header = reader.get_header()
                    summary = reader.get_summary()
                except READ_ERRORS as e:
                    raise self._corrupt(0, e) from e
            if summary is not None and summary.statistics is not None:
                return self._info_from_summary(header, summary)
        return self._info_by_reading()

    def _info_from_summary(self, header: Any, summary: Any) -> BagInfo:
        stats = summary.statistics
        counts = stats.channel_message_counts
        latched = self.latched_topics()
        topics = []
        for cid, ch in sorted(summary.channels.items(), key=lambda kv: kv[1].topic):
            schema = summary.schemas.get(ch.schema_id)
            topics.append(
                TopicInfo(
                    ch.topic,
                    schema.name if schema is not None else "",
                    counts.get(cid, 0),
                    ch.message_encoding,
                    ch.topic in latched,
                )
            )
        comps = {c.compression for c in summary.chunk_indexes}
        return BagInfo(
            self.path,
            self.size_bytes,
            header.profile,
            header.library,
            stats.message_start_time,
            stats.message_end_time,
            stats.message_count,
            tuple(topics),
            ",".join(sorted(c or "none" for c in comps)),
        )

    def _info_by_reading(self) -> BagInfo:
        counts: dict[str, int] = {}
        types: dict[str, str] = {}
        start = end = None
        n = 0
        for m in self.messages(decode=False):  # raises for a truncated file
            counts[m.topic] = counts.get(m.topic, 0) + 1
            types[m.topic] = m.typename
            start = m.log_time_ns if start is None else min(start, m.log_time_ns)
            end = m.log_time_ns if end is None else max(end, m.log_time_ns)
            n += 1
        latched = self.latched_topics()
        topics = tuple(
            TopicInfo(t, types[t], counts[t], "cdr", t in latched) for t in sorted(counts)
        )
        return BagInfo(self.path, self.size_bytes, "", "", start or 0, end or 0, n, topics, "")

    def metadata(self, name: str) -> dict[str, str] | None:
        """The metadata record ``name`` (a dict of strings), or None."""
        found = None
        with open(self.path, "rb") as f:
            try:
                if self.complete:  # through the metadata index
                    for record in SeekingReader(f).iter_metadata():
                        if record.name == name:
                            found = dict(record.metadata)
                    return found
                for record in StreamReader(f).records:
                    if isinstance(record, Metadata) and record.name == name:
                        found = dict(record.metadata)
            except READ_ERRORS:
                pass  # a truncated file has no metadata (it is written at close)
        return found

    def params(self) -> dict:
        """The parameter tree the run had when recording ended ({} when not stored)."""
        meta = self.metadata(PARAMS_METADATA)
        if not meta or "yaml" not in meta:
            return {}
        try:
            tree = yaml.safe_load(meta["yaml"])
        except yaml.YAMLError as e:
            raise RecordingError(f"{self.path}: metadata {PARAMS_METADATA} is not YAML: {e}") from e
        return tree if isinstance(tree, dict) else {}

    def latched_topics(self) -> set[str]:
        """Topics whose publisher was latched when recorded (``/map``, ``/tf_static``)."""
        meta = self.metadata(LATCHED_METADATA) or {}
        return {t for t in meta.get("topics", "").split("\n") if t}


def read_messages(
    path: str | Path, topics: Iterable[str] | None = None, allow_truncated: bool = False
) -> Iterator[BagMessage]:
    """Shorthand for ``BagReader(path).messages(topics, allow_truncated=...)``."""
    return BagReader(path).messages(topics, allow_truncated=allow_truncated)
