"""``TransformListener``: fills a `Buffer` from ``/tf`` and ``/tf_static``.

The runtime already keeps one buffer fed this way (``node.tf_buffer``); a listener is for a node
that wants its own buffer, e.g. with a longer ``cache_time``.
"""

from __future__ import annotations

from typing import Any

from fleetsim.errors import TransformError
from fleetsim.tf._msgs import TFMessage
from fleetsim.tf.buffer import Buffer

__all__ = ["TransformListener"]


class TransformListener:
    """Subscribes a node to ``/tf`` and ``/tf_static`` and feeds ``buffer``.

    Subscriptions are unbounded (``queue_size=0``): in a deterministic simulation no transform
    is dropped. Transforms are recorded with the default authority, as the in-process graph does
    not say which node published a message.

    Parameters
    ----------
    node : fleetsim.runtime.Node
        The node that owns the subscriptions.
    buffer : Buffer
        The buffer to fill.
    """

    def __init__(self, node: Any, buffer: Buffer) -> None:
        if not isinstance(buffer, Buffer):
            raise TransformError(
                f"TransformListener(node, buffer): buffer must be a fleetsim.tf.Buffer, "
                f"got {type(buffer).__name__}"
            )
        self.node = node
        self.buffer = buffer
        self._subs = [
            node.create_subscription(TFMessage, "/tf", self._on_tf, queue_size=0),
            node.create_subscription(TFMessage, "/tf_static", self._on_tf_static, queue_size=0),
        ]

    def _on_tf(self, msg: TFMessage) -> None:
        self.buffer.add_message(msg, is_static=False)

    def _on_tf_static(self, msg: TFMessage) -> None:
        self.buffer.add_message(msg, is_static=True)

    def unregister(self) -> None:
        """Stop listening."""
        for sub in self._subs:
            sub.destroy()
        self._subs = []
