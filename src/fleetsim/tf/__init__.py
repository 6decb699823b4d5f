"""tf: transform math, the time-stamped transform buffer, tf_prefix names, broadcasters.

Import the math from :mod:`fleetsim.tf.transforms`, and these from here::

    from fleetsim.tf import Buffer, MessageFilter, make_transform_stamped, resolve_frame
    from fleetsim.tf import TransformBroadcaster, StaticTransformBroadcaster, TransformListener

The node-facing classes (broadcasters, listener, static_transform_publisher) are imported on
first use, so that the runtime can import the buffer without importing itself back.
"""

from __future__ import annotations

import importlib
from typing import Any

from fleetsim.tf._msgs import make_transform_stamped
from fleetsim.tf.buffer import Buffer
from fleetsim.tf.frame_info import FrameInfo
from fleetsim.tf.message_filter import MessageFilter
from fleetsim.tf.names import normalize_frame, resolve_frame, resolve_frame_once

_LAZY = {
    "TransformBroadcaster": "fleetsim.tf.broadcaster",
    "StaticTransformBroadcaster": "fleetsim.tf.broadcaster",
    "TransformListener": "fleetsim.tf.listener",
    "StaticTransformPublisher": "fleetsim.tf.static_transform_publisher",
}

__all__ = [
    "Buffer",
    "FrameInfo",
    "MessageFilter",
    "make_transform_stamped",
    "normalize_frame",
    "resolve_frame",
    "resolve_frame_once",
    *_LAZY,
]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'fleetsim.tf' has no attribute {name!r}")
    return getattr(importlib.import_module(module), name)
