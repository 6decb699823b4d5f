"""TransformBroadcaster on /tf and StaticTransformBroadcaster on latched /tf_static."""

from __future__ import annotations

import pytest

from fleetsim.errors import TransformError
from fleetsim.msgs import tf2_msgs
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster
from fleetsim.tf._msgs import make_transform_stamped


def test_broadcaster_publishes_tf_messages_that_reach_the_runtime_buffer():
    rt = Runtime()
    node = Node(rt, "odom_publisher", "/lizi1")
    got = []
    rt.graph.subscribe("/tf", tf2_msgs.TFMessage, got.append)
    buf = rt.tf_buffer
    br = TransformBroadcaster(node)
    br.send_transform(make_transform_stamped("lizi1/odom", "lizi1/base_link", 1.0, (1, 2, 0)))
    br.sendTransform(
        [
            make_transform_stamped("lizi1/odom", "lizi1/base_link", 2.0, (3, 2, 0)),
            make_transform_stamped("map", "lizi1/odom", 2.0),
        ]
    )
    br.send_transform([])  # nothing to send: nothing published
    rt.spin_once()
    assert [len(m.transforms) for m in got] == [1, 2]
    assert "/tf" in rt.graph.topics and "/lizi1/tf" not in rt.graph.topics
    assert buf.lookup_tuple("lizi1/odom", "lizi1/base_link", 1.5)[:2] == (2.0, 2.0)
    assert buf.lookup_tuple("map", "lizi1/base_link")[:2] == (3.0, 2.0)


def test_broadcaster_rejects_other_message_types():
    br = TransformBroadcaster(Node(Runtime(), "n"))
    with pytest.raises(TransformError, match=r"expects geometry_msgs/TransformStamped.*got str"):
        br.send_transform(["map"])


def test_static_broadcaster_accumulates_and_latches():
    rt = Runtime()
    node = Node(rt, "robot_state_publisher", "/lizi1")
    br = StaticTransformBroadcaster(node)
    br.send_transform(make_transform_stamped("base_link", "laser_link", 0.0, (0, 0, 1)))
    br.send_transform(make_transform_stamped("base_link", "camera_link", 0.0, (0.1, 0, 0.5)))
    br.send_transform(make_transform_stamped("base_link", "laser_link", 0.0, (0, 0, 2)))
    assert [t.child_frame_id for t in br.transforms] == ["laser_link", "camera_link"]
    late = []  # a subscriber that arrives after all three sends gets the complete set
    rt.graph.subscribe("/tf_static", tf2_msgs.TFMessage, late.append)
    rt.spin_once()
    assert len(late) == 1
    children = {t.child_frame_id: t.transform.translation.z for t in late[0].transforms}
    assert children == {"laser_link": 2.0, "camera_link": 0.5}
    buf = rt.tf_buffer  # subscribes now, also late
    rt.spin_once()
    assert buf.lookup_tuple("base_link", "laser_link", 123.0)[2] == 2.0
