"""TransformListener fills its own Buffer from /tf and /tf_static."""

from __future__ import annotations

import pytest

from fleetsim.errors import TransformError
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import Buffer, StaticTransformBroadcaster, TransformBroadcaster, TransformListener
from fleetsim.tf._msgs import make_transform_stamped


def test_listener_receives_dynamic_and_latched_static_transforms():
    rt = Runtime()
    talker = Node(rt, "talker")
    static = StaticTransformBroadcaster(talker)
    static.send_transform(make_transform_stamped("base_link", "laser", 0.0, (0.2, 0, 0)))
    rt.spin_once()  # the static transform was sent before the listener existed
    buf = Buffer(cache_time=30.0)
    listener = TransformListener(Node(rt, "listener"), buf)
    dyn = TransformBroadcaster(talker)
    for k in range(3):
        dyn.send_transform(make_transform_stamped("odom", "base_link", float(k), (k, 0, 0)))
    rt.spin_once()
    assert buf.frame_info("laser").is_static
    assert buf.lookup_tuple("odom", "laser", 1.5)[0] == pytest.approx(1.7)
    listener.unregister()
    dyn.send_transform(make_transform_stamped("odom", "base_link", 3.0, (3, 0, 0)))
    rt.spin_once()
    assert buf.frame_info("base_link").most_recent == 2.0


def test_listener_needs_a_buffer():
    with pytest.raises(TransformError, match=r"buffer must be a fleetsim.tf.Buffer, got dict"):
        TransformListener(Node(Runtime(), "n"), {})
