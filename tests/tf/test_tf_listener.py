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


def test_a_bad_transform_is_logged_and_skipped_not_fatal(caplog):
    """tf2's listener logs a NaN or self-parent transform and keeps the rest of the message."""
    rt = Runtime()
    buf = Buffer()
    TransformListener(Node(rt, "listener"), buf)
    dyn = TransformBroadcaster(Node(rt, "talker"))
    nan = make_transform_stamped("odom", "base_link", 1.0)
    nan.transform.translation.x = float("nan")  # as a broken publisher would send it
    good = make_transform_stamped("map", "odom", 1.0, (1, 0, 0))
    loop = make_transform_stamped("map", "odom", 1.0)
    loop.header.frame_id = "odom"
    for _ in range(3):
        dyn.send_transform([nan, good, loop])
        rt.spin_once()
    assert buf.lookup_tuple("map", "odom", 1.0)[0] == pytest.approx(1.0)
    assert not buf.can_transform("map", "base_link", 1.0)
    errors = [r.getMessage() for r in caplog.records if r.levelname == "ERROR"]
    assert len(errors) == 2  # once per bad frame, not once per message
    assert "'base_link'" in errors[0] and "finite" in errors[0]
    assert "'odom'" in errors[1] and "own parent" in errors[1]
    # the run's own buffer does the same
    assert rt.tf_buffer.add_message(type("M", (), {"transforms": [nan, good]})()) == 1
