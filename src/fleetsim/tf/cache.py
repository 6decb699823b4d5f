"""One frame's time-sorted transform cache (tf2's ``TimeCache`` and ``StaticCache``).

Stamps are integer nanoseconds, so a stamp written as ``builtin_interfaces/Time`` and a lookup
at the same sim time given as float seconds meet exactly.
"""

from __future__ import annotations

import math
from bisect import bisect_left
from typing import Any

from fleetsim.errors import ExtrapolationError, TransformError
from fleetsim.tf.fastmath import Transform7, interpolate

__all__ = ["FrameCache", "checked_value", "ns_from_time"]

#: A quaternion whose squared norm is further than this from 1 is rejected, not normalised.
QUATERNION_NORM2_TOLERANCE = 1e-3


def ns_from_time(time: Any) -> int:
    """Return a stamp as integer nanoseconds; ``None`` and ``0`` mean "latest" and give ``0``.

    Accepts float or int seconds, or a ``builtin_interfaces/Time``-like object (``sec`` and
    ``nanosec`` fields).
    """
    if time is None:
        return 0
    if time.__class__ is float or time.__class__ is int:
        seconds = time
    elif hasattr(time, "sec") and hasattr(time, "nanosec"):
        return int(time.sec) * 1_000_000_000 + int(time.nanosec)
    else:
        try:
            seconds = float(time)  # NumPy scalars and other real numbers
        except (TypeError, ValueError):
            raise TransformError(
                f"tf time {time!r} is neither seconds nor a builtin_interfaces/Time (sec, nanosec)"
            ) from None
    if not math.isfinite(seconds):
        raise TransformError(f"tf time {time!r} is not finite; give seconds of sim time")
    return round(seconds * 1e9)


def checked_value(parent: str, child: str, translation: Any, rotation: Any) -> Transform7:
    """Return ``(tx, ty, tz, qx, qy, qz, qw)`` with the quaternion normalised.

    Raises
    ------
    TransformError
        For values that are not numbers or not finite, or a quaternion whose squared norm is
        more than ``QUATERNION_NORM2_TOLERANCE`` away from 1.
    """
    # every transform of every robot passes here (odometry at 100 Hz each): plain unpacking
    # and one sum for the finiteness check (``all`` over a generator only when it fails)
    try:
        x, y, z = map(float, translation)
        qx, qy, qz, qw = map(float, rotation)
    except (TypeError, ValueError):
        raise TransformError(
            f"transform {parent!r} -> {child!r}: translation must be 3 numbers and rotation 4 "
            f"numbers (x, y, z, w), got {translation!r} and {rotation!r}"
        ) from None
    value = (x, y, z, qx, qy, qz, qw)
    if not math.isfinite(x + y + z + qx + qy + qz + qw) and not all(map(math.isfinite, value)):
        raise TransformError(
            f"transform {parent!r} -> {child!r} has a non-finite value: translation "
            f"{(x, y, z)}, rotation {(qx, qy, qz, qw)}"
        )
    n2 = qx * qx + qy * qy + qz * qz + qw * qw
    if abs(n2 - 1.0) > QUATERNION_NORM2_TOLERANCE:
        raise TransformError(
            f"transform {parent!r} -> {child!r} has a rotation quaternion of norm "
            f"{math.sqrt(n2):.6g}, not 1: {(qx, qy, qz, qw)}; normalise it (identity is "
            "x=0, y=0, z=0, w=1)"
        )
    if n2 != 1.0:
        n = 1.0 / math.sqrt(n2)
        value = (x, y, z, qx * n, qy * n, qz * n, qw * n)
    return value


class FrameCache:
    """One child frame: its parent and the time-sorted transforms to it.

    A root frame has ``parent is None`` and no data. A static frame holds one value, valid at
    all times.
    """

    __slots__ = ("authority", "is_static", "name", "parent", "stamps", "values")

    def __init__(self, name: str) -> None:
        self.name = name
        self.parent: str | None = None
        self.is_static = False
        self.authority = ""
        self.stamps: list[int] = []  # ns, ascending
        self.values: list[Transform7] = []  # T_parent_child at each stamp

    def reset(self, parent: str | None, is_static: bool) -> None:
        """Attach to ``parent`` (or detach, ``None``), dropping all cached data."""
        self.parent = parent
        self.is_static = is_static
        self.stamps = []
        self.values = []

    def insert(self, stamp_ns: int, value: Transform7, cache_ns: int) -> bool:
        """Insert one value; keep ``cache_ns`` of history behind the newest stamp.

        A stamp already cached is replaced. Returns ``False`` (and stores nothing) for a stamp
        older than the window.
        """
        if self.is_static:
            self.stamps = [stamp_ns]
            self.values = [value]
            return True
        stamps = self.stamps
        if not stamps or stamp_ns > stamps[-1]:
            stamps.append(stamp_ns)
            self.values.append(value)
        else:
            if stamp_ns < stamps[-1] - cache_ns:
                return False
            i = bisect_left(stamps, stamp_ns)
            if stamps[i] == stamp_ns:
                self.values[i] = value
            else:
                stamps.insert(i, stamp_ns)
                self.values.insert(i, value)
        cutoff = stamps[-1] - cache_ns
        if stamps[0] < cutoff:
            k = bisect_left(stamps, cutoff)
            del stamps[:k]
            del self.values[:k]
        return True

    def value_at(self, t_ns: int, target: str, source: str) -> Transform7:
        """The transform to the parent at ``t_ns``, interpolated between bracketing stamps.

        ``target`` and ``source`` name the lookup in the error message.

        Raises
        ------
        ExtrapolationError
            When ``t_ns`` lies outside the cached window.
        """
        if self.is_static:
            return self.values[0]
        stamps = self.stamps
        last = stamps[-1]
        if t_ns == last:
            return self.values[-1]
        if t_ns > last or t_ns < stamps[0]:
            raise self.extrapolation_error(t_ns, target, source)
        i = bisect_left(stamps, t_ns)
        t1 = stamps[i]
        if t1 == t_ns:
            return self.values[i]
        t0 = stamps[i - 1]
        return interpolate(self.values[i - 1], self.values[i], (t_ns - t0) / (t1 - t0))

    def extrapolation_error(self, t_ns: int, target: str, source: str) -> ExtrapolationError:
        """The error for a lookup of ``source`` in ``target`` at ``t_ns`` outside the window."""
        first, last = self.stamps[0] * 1e-9, self.stamps[-1] * 1e-9
        edge = f"edge {self.parent!r} -> {self.name!r}"
        if len(self.stamps) == 1:
            window = f"only time {first:.9f} s is in the buffer for the {edge}"
        else:
            window = f"the {edge} has data from {first:.9f} to {last:.9f} s"
        direction = "into the future" if t_ns > self.stamps[-1] else "into the past"
        return ExtrapolationError(
            f"lookup of {source!r} in {target!r} at time {t_ns * 1e-9:.9f} s would require "
            f"extrapolation {direction}: {window}; look up at time 0 for the latest common "
            "time, or wait for newer data"
        )
