"""Building TransformStamped messages from plain values."""

from __future__ import annotations

import pytest

from fleetsim.errors import TransformError
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.tf import make_transform_stamped
from fleetsim.tf._msgs import transform_stamped, value_of


def test_make_transform_stamped_from_seconds_or_time():
    m = make_transform_stamped("lizi1/odom", "lizi1/base_link", 0.1 + 0.2, (1, 2, 3))
    assert m.__msgtype__ == "geometry_msgs/msg/TransformStamped"
    assert m.header.stamp == Time(0, 300_000_000) and m.header.frame_id == "lizi1/odom"
    assert m.child_frame_id == "lizi1/base_link"
    assert value_of(m) == (1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0)
    m2 = make_transform_stamped("a", "b", Time(5, 7), rotation=(0, 0, 1, 0))
    assert m2.header.stamp == Time(5, 7) and m2.transform.rotation.z == 1.0
    with pytest.raises(TransformError, match=r"'a' -> 'b': translation must be 3 numbers"):
        make_transform_stamped("a", "b", 0.0, (1, 2))


def test_transform_stamped_round_trips_a_value():
    v = (1.0, -2.0, 0.5, 0.0, 0.0, 0.6, 0.8)
    m = transform_stamped("map", "odom", 1_500_000_000, v)
    assert value_of(m) == v and m.header.stamp == Time(1, 500_000_000)
