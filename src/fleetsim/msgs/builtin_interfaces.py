"""builtin_interfaces: Time and Duration (ROS 1's ``time`` and ``duration`` primitives)."""

from __future__ import annotations

import math
from typing import NoReturn

from fleetsim.errors import MessageError
from fleetsim.msgs.fields import int32, uint32
from fleetsim.msgs.registry import message

_NS = 1_000_000_000


class _SecNanosec:
    """What Time and Duration share: ``sec`` + ``nanosec`` (0 <= nanosec < 1e9) conversions."""

    __slots__ = ()

    @classmethod
    def from_sec(cls, t: float):
        """``t`` seconds (a Duration may be negative), rounded to the nearest nanosecond."""
        return cls.from_nsec(round(t * _NS)) if math.isfinite(t) else _not_finite(cls, t)

    @classmethod
    def from_nsec(cls, ns: int):
        """``ns`` nanoseconds (an int); nanosec is always in [0, 1e9)."""
        sec, nanosec = divmod(int(ns), _NS)
        return cls(sec, nanosec)

    def to_sec(self) -> float:
        """Seconds as a float."""
        return self.sec + self.nanosec * 1e-9

    def to_nsec(self) -> int:
        """Nanoseconds as an int (exact)."""
        return self.sec * _NS + self.nanosec


@message("builtin_interfaces/msg/Time")
class Time(_SecNanosec):
    """A point in time: ``sec`` seconds plus ``nanosec`` (0 <= nanosec < 1e9) nanoseconds."""

    sec: int32
    nanosec: uint32


@message("builtin_interfaces/msg/Duration")
class Duration(_SecNanosec):
    """A span of time: ``sec`` seconds plus ``nanosec`` (0 <= nanosec < 1e9) nanoseconds."""

    sec: int32
    nanosec: uint32


def _not_finite(cls: type, t: float) -> NoReturn:
    raise MessageError(f"{cls.__msgtype__}.from_sec: {t!r} seconds is not a finite number")
