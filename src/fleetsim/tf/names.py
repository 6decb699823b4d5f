"""Frame names and ROS 1's ``tf_prefix``.

fleetsim keeps the seeds' convention: one ``/tf`` topic, each robot's frames prefixed by its
``tf_prefix`` parameter (``lizi1/odom``, ``lizi1/base_link``) and one shared ``map`` frame. Frame
ids are stored without a leading slash, as tf2 stores them.
"""

from __future__ import annotations

import re

from fleetsim.errors import InvalidName

__all__ = ["normalize_frame", "resolve_frame", "resolve_frame_once"]

_SEGMENT = re.compile(r"[A-Za-z0-9_]+")
_INVALID_CHAR = re.compile(r"[^A-Za-z0-9_/]")


def _check_segments(value: str, what: str, original: str) -> None:
    bad = _INVALID_CHAR.search(value)
    if bad is not None:
        raise InvalidName(
            f"{what} {original!r} contains the invalid character {bad.group()!r}; frame names use "
            "letters, digits, '_' and '/' between segments"
        )
    for segment in value.split("/"):
        if not _SEGMENT.fullmatch(segment):
            raise InvalidName(
                f"{what} {original!r} has an empty segment (a doubled or trailing '/'); "
                "write segments separated by single slashes, e.g. 'lizi1/base_link'"
            )


def normalize_frame(frame: str) -> str:
    """Return a frame id as the tf buffer keys it: one leading ``/`` removed, never empty.

    Raises
    ------
    InvalidName
        If ``frame`` is not a string, or empty (or just ``"/"``).
    """
    if not isinstance(frame, str):
        raise InvalidName(f"frame id must be a string, got {frame!r} ({type(frame).__name__})")
    key = frame[1:] if frame.startswith("/") else frame
    if not key:
        raise InvalidName(
            f"frame id {frame!r} is empty; give a frame name such as 'map' or 'lizi1/base_link'"
        )
    return key


def resolve_frame(tf_prefix: str, frame: str) -> str:
    """Apply ``tf_prefix`` to a frame id, as ROS 1's ``tf::resolve`` does, without a leading slash.

    - ``resolve_frame("lizi1", "odom") == "lizi1/odom"``
    - ``resolve_frame("lizi1", "/map") == "map"`` (a leading slash marks a global frame)
    - ``resolve_frame("", "odom") == "odom"``
    - ``resolve_frame("/lizi1/", "odom") == "lizi1/odom"`` (slashes around the prefix are dropped)

    Parameters
    ----------
    tf_prefix : str
        The robot's ``tf_prefix`` parameter; empty or ``"/"`` for none.
    frame : str
        A frame id, relative (prefixed) or global (leading ``/``).

    Raises
    ------
    InvalidName
        For an empty frame, or a frame or prefix with characters other than letters, digits,
        ``_`` and single ``/`` separators; the message names the value.
    """
    if not isinstance(tf_prefix, str):
        raise InvalidName(f"tf_prefix must be a string, got {tf_prefix!r}")
    if not isinstance(frame, str):
        raise InvalidName(f"frame id must be a string, got {frame!r} ({type(frame).__name__})")
    if not frame or frame == "/":
        raise InvalidName(
            f"frame id {frame!r} is empty; give a frame name such as 'odom' or '/map'"
        )
    prefix = tf_prefix.strip("/")
    if prefix:
        _check_segments(prefix, "tf_prefix", tf_prefix)
    if frame.startswith("/"):
        key = frame[1:]
        _check_segments(key, "frame id", frame)
        return key
    _check_segments(frame, "frame id", frame)
    return f"{prefix}/{frame}" if prefix else frame


def resolve_frame_once(tf_prefix: str, frame: str) -> str:
    """Like :func:`resolve_frame`, but a frame already under ``tf_prefix`` is left as it is.

    ROS 1 launch files for tf_prefix robots often spell frames out in full
    (``$(arg robot_name)/base_link``) for nodes that, since ROS Hydro, no longer apply the
    prefix themselves. Resolving those once more would give ``lizi1/lizi1/base_link``; this
    function accepts both spellings: ``resolve_frame_once("lizi1", "lizi1/base_link")`` and
    ``resolve_frame_once("lizi1", "base_link")`` are both ``"lizi1/base_link"``.
    """
    resolved = resolve_frame(tf_prefix, frame)
    prefix = tf_prefix.strip("/")
    if prefix and not frame.startswith("/") and frame.startswith(prefix + "/"):
        return frame
    return resolved
