"""Building tf messages: the one place fleetsim.tf touches ``fleetsim.msgs`` types.

Kept in one small module so that the buffer's math has no dependency on the message package
and the message classes are built the same way everywhere in tf.
"""

from __future__ import annotations

from typing import Any

from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.geometry_msgs import (
    Quaternion,
    Transform,
    TransformStamped,
    Vector3,
)
from fleetsim.msgs.std_msgs import Header
from fleetsim.msgs.tf2_msgs import TFMessage
from fleetsim.tf.cache import checked_value, ns_from_time

__all__ = [
    "TFMessage",
    "TransformStamped",
    "make_transform_stamped",
    "transform_stamped",
    "value_of",
]


def transform_stamped(
    parent: str, child: str, stamp_ns: int, value: tuple[float, ...]
) -> TransformStamped:
    """A ``TransformStamped`` of ``child`` in ``parent`` from a 7-tuple ``(t, q)`` value."""
    x, y, z, qx, qy, qz, qw = value
    # positional: every robot's state publisher and localisation build these at their rates,
    # and keywords cost ~3x as much in a dataclass ``__init__`` (fields in message order)
    return TransformStamped(
        Header(Time.from_nsec(stamp_ns), parent),
        child,
        Transform(Vector3(x, y, z), Quaternion(qx, qy, qz, qw)),
    )


def value_of(msg: TransformStamped) -> tuple[float, ...]:
    """The 7-tuple ``(tx, ty, tz, qx, qy, qz, qw)`` of a ``TransformStamped``."""
    t = msg.transform.translation
    q = msg.transform.rotation
    return (t.x, t.y, t.z, q.x, q.y, q.z, q.w)


def make_transform_stamped(
    parent_frame: str,
    child_frame: str,
    stamp: Any,
    translation: Any = (0.0, 0.0, 0.0),
    rotation: Any = (0.0, 0.0, 0.0, 1.0),
) -> TransformStamped:
    """A ``TransformStamped`` of ``child_frame`` in ``parent_frame`` from plain values.

    Parameters
    ----------
    parent_frame, child_frame : str
        ``header.frame_id`` and ``child_frame_id``, used as given (apply tf_prefix first).
    stamp : float or builtin_interfaces/Time
        Sim time in seconds, or a ``Time``.
    translation : sequence of 3 floats
        Child origin in the parent frame, metres.
    rotation : sequence of 4 floats
        Child orientation in the parent frame, quaternion ``(x, y, z, w)``; normalised when
        nearly unit.

    Raises
    ------
    TransformError
        For values that are not numbers, not finite, or a quaternion far from unit length.
    """
    value = checked_value(parent_frame, child_frame, translation, rotation)
    return transform_stamped(parent_frame, child_frame, ns_from_time(stamp), value)
