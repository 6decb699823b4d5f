"""Publishing transforms: ``TransformBroadcaster`` on ``/tf``, ``StaticTransformBroadcaster``
on the latched ``/tf_static`` (tf2_ros's classes)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from fleetsim.errors import TransformError
from fleetsim.tf._msgs import TFMessage, TransformStamped

__all__ = ["StaticTransformBroadcaster", "TransformBroadcaster"]

#: tf2_ros's publisher queue sizes for /tf and /tf_static.
TF_QUEUE_SIZE = 100


def _as_list(transforms: TransformStamped | Iterable[TransformStamped]) -> list[TransformStamped]:
    items = [transforms] if isinstance(transforms, TransformStamped) else list(transforms)
    for t in items:
        if not isinstance(t, TransformStamped):
            raise TransformError(
                f"send_transform expects geometry_msgs/TransformStamped messages, got "
                f"{type(t).__name__}: {t!r}"
            )
    return items


class TransformBroadcaster:
    """Sends transforms on ``/tf`` for a node.

    Parameters
    ----------
    node : fleetsim.runtime.Node
        The node that owns the publisher.
    """

    def __init__(self, node: Any) -> None:
        self.node = node
        self._pub = node.create_publisher(TFMessage, "/tf", queue_size=TF_QUEUE_SIZE)

    def send_transform(self, transforms: TransformStamped | Iterable[TransformStamped]) -> None:
        """Publish one ``TransformStamped`` or several in one ``TFMessage``."""
        items = _as_list(transforms)
        if items:
            self._pub.publish(TFMessage(transforms=items))

    #: ROS 1 spelling.
    sendTransform = send_transform


class StaticTransformBroadcaster:
    """Sends transforms on the latched ``/tf_static``.

    As tf2_ros does, the broadcaster remembers every static transform it has sent (one per
    child frame, the newest wins) and republishes all of them in each message, so that the
    latched message always holds this broadcaster's complete set.
    """

    def __init__(self, node: Any) -> None:
        self.node = node
        self._pub = node.create_publisher(
            TFMessage, "/tf_static", queue_size=TF_QUEUE_SIZE, latch=True
        )
        self._by_child: dict[str, TransformStamped] = {}

    def send_transform(self, transforms: TransformStamped | Iterable[TransformStamped]) -> None:
        """Add (or replace, by child frame) static transforms and publish the whole set."""
        items = _as_list(transforms)
        for t in items:
            self._by_child[t.child_frame_id.lstrip("/")] = t
        if items:
            self._pub.publish(TFMessage(transforms=list(self._by_child.values())))

    #: ROS 1 spelling.
    sendTransform = send_transform

    @property
    def transforms(self) -> list[TransformStamped]:
        """Every static transform sent so far, one per child frame."""
        return list(self._by_child.values())
