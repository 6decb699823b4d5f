"""Per-frame statistics of a tf buffer, as ``view_frames`` and ``tf_monitor`` report them."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import yaml

from fleetsim.errors import FrameNotFound
from fleetsim.tf.names import normalize_frame

__all__ = [
    "FrameInfo",
    "TreeIntrospection",
    "frame_info_of",
    "frames_as_dot",
    "frames_as_string",
    "frames_as_yaml",
]

#: Authority reported for transforms set without one (tf2's name for it).
DEFAULT_AUTHORITY = "default_authority"


@dataclass(frozen=True, slots=True)
class FrameInfo:
    """What the buffer knows about one child frame's edge to its parent.

    Attributes
    ----------
    frame, parent : str
        The child frame and its parent.
    authority : str
        Who sent the latest transform (the broadcasting node's name), or ``default_authority``.
    is_static : bool
        Whether the edge came from ``/tf_static`` (valid at all times).
    rate : float or None
        Average publishing rate over the cached window in Hz; ``None`` for a static edge or a
        single cached stamp.
    most_recent, oldest : float
        Newest and oldest cached stamps, seconds of sim time.
    buffer_length : float
        ``most_recent - oldest``, seconds.
    """

    frame: str
    parent: str
    authority: str
    is_static: bool
    rate: float | None
    most_recent: float
    oldest: float
    buffer_length: float


def frame_info_of(f: Any, cache_time: float) -> FrameInfo:
    """Summarise one buffer frame record (``name``, ``parent``, ``stamps``...) as `FrameInfo`."""
    newest = f.stamps[-1] * 1e-9 if f.stamps else 0.0
    oldest = f.stamps[0] * 1e-9 if f.stamps else 0.0
    span = newest - oldest
    rate = (len(f.stamps) - 1) / span if (not f.is_static and span > 0.0) else None
    return FrameInfo(
        frame=f.name,
        parent=f.parent,
        authority=f.authority or DEFAULT_AUTHORITY,
        is_static=f.is_static,
        rate=rate,
        most_recent=newest,
        oldest=oldest,
        buffer_length=span,
    )


def frames_as_yaml(infos: dict[str, FrameInfo]) -> str:
    """tf2's ``allFramesAsYAML`` layout: ``frame: {parent, broadcaster, rate, ...}`` blocks."""
    doc = {}
    for name, info in infos.items():
        d = asdict(info)
        doc[name] = {
            "parent": d["parent"],
            "broadcaster": d["authority"],
            "rate": 10000.0 if info.is_static else round(d["rate"] or 0.0, 3),
            "most_recent_transform": d["most_recent"],
            "oldest_transform": d["oldest"],
            "buffer_length": d["buffer_length"],
            "is_static": d["is_static"],
        }
    return yaml.safe_dump(doc, sort_keys=False) if doc else ""


def frames_as_string(parents: dict[str, str]) -> str:
    """tf2's ``allFramesAsString``: one ``Frame X exists with parent Y.`` line per child."""
    return "".join(
        f"Frame {child} exists with parent {parent}.\n" for child, parent in parents.items()
    )


def _dot_id(text: str) -> str:
    """A quoted Graphviz id; ``\\n`` escapes in ``text`` stay line breaks."""
    return '"' + text.replace('"', '\\"') + '"'


def frames_as_dot(infos: dict[str, FrameInfo], recorded_at: float | None = None) -> str:
    """A Graphviz digraph of the tree, labelled like tf2_tools' ``view_frames``.

    Each edge ``parent -> child`` carries the broadcaster, the average rate, the most recent
    and oldest stamps and the buffer length; static edges say so instead of a rate.
    """
    lines = ["digraph G {"]
    for name, info in infos.items():
        rate = (
            "static"
            if info.is_static
            else (f"{info.rate:.3f} Hz" if info.rate is not None else "n/a (one stamp)")
        )
        label = (
            f"Broadcaster: {info.authority}\\nAverage rate: {rate}\\n"
            f"Most recent transform: {info.most_recent:.3f}\\n"
            f"Oldest transform: {info.oldest:.3f}\\nBuffer length: {info.buffer_length:.3f} sec"
        )
        lines.append(f"{_dot_id(info.parent)} -> {_dot_id(name)} [label={_dot_id(label)}];")
    if recorded_at is not None:
        lines.append(f'label="Recorded at time: {recorded_at:.3f}"; labelloc=t;')
    lines.append("}")
    return "\n".join(lines) + "\n"


class TreeIntrospection:
    """What ``view_frames``, ``tf_monitor`` and ``tf_echo`` ask a `Buffer` about its tree
    (a base of `Buffer`, which holds ``_frames``, ``cache_time`` and ``_not_found``)."""

    _frames: dict[str, Any]
    cache_time: float

    def all_frames(self) -> list[str]:
        """Every frame id in the tree (children and roots), sorted."""
        return sorted(self._frames)

    def parents(self) -> dict[str, str]:
        """Map each child frame to its parent (the edges of ``tf tree`` / view_frames)."""
        return {n: f.parent for n, f in sorted(self._frames.items()) if f.parent is not None}

    def frame_info(self, frame: str) -> FrameInfo:
        """Parent, authority, average rate and time window of one child frame's transform."""
        name = normalize_frame(frame)
        f = self._frames.get(name)
        if f is None:
            raise self._not_found(name, "frame")
        if f.parent is None:
            raise FrameNotFound(f"frame {name!r} is a root of the tf tree and has no parent edge")
        return frame_info_of(f, self.cache_time)

    def frames_info(self) -> dict[str, FrameInfo]:
        """:meth:`frame_info` for every child frame, by frame id."""
        return {
            n: frame_info_of(f, self.cache_time)
            for n, f in sorted(self._frames.items())
            if f.parent is not None
        }

    def all_frames_as_yaml(self) -> str:
        """tf2's ``allFramesAsYAML``: one block per child frame, as view_frames reads it."""
        return frames_as_yaml(self.frames_info())

    def all_frames_as_dot(self, recorded_at: float | None = None) -> str:
        """The tree as a Graphviz digraph labelled like ``view_frames`` (render with ``dot``)."""
        return frames_as_dot(self.frames_info(), recorded_at)

    def all_frames_as_string(self) -> str:
        """tf2's ``allFramesAsString``: ``Frame X exists with parent Y.`` lines."""
        return frames_as_string(self.parents())
