"""Building tf messages: the one place fleetsim.tf touches ``fleetsim.msgs`` types.

Kept in one small module so that the buffer's math has no dependency on the message package
and the message classes are built the same way everywhere in tf.
"""

from __future__ import annotations

from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.geometry_msgs import (
    Quaternion,
    Transform,
    TransformStamped,
    Vector3,
)
from fleetsim.msgs.std_msgs import Header
from fleetsim.msgs.tf2_msgs import TFMessage

__all__ = ["TFMessage", "TransformStamped", "transform_stamped", "value_of"]


def transform_stamped(
    parent: str, child: str, stamp_ns: int, value: tuple[float, ...]
) -> TransformStamped:
    """A ``TransformStamped`` of ``child`` in ``parent`` from a 7-tuple ``(t, q)`` value."""
    x, y, z, qx, qy, qz, qw = value
    return TransformStamped(
        header=Header(stamp=Time.from_nsec(stamp_ns), frame_id=parent),
        child_frame_id=child,
        transform=Transform(
            translation=Vector3(x=x, y=y, z=z), rotation=Quaternion(x=qx, y=qy, z=qz, w=qw)
        ),
    )


def value_of(msg: TransformStamped) -> tuple[float, ...]:
    """The 7-tuple ``(tx, ty, tz, qx, qy, qz, qw)`` of a ``TransformStamped``."""
    t = msg.transform.translation
    q = msg.transform.rotation
    return (t.x, t.y, t.z, q.x, q.y, q.z, q.w)
