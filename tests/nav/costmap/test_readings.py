"""Sensor messages as points: a scan read by two costmaps is projected once, read only."""

import math

import numpy as np
import pytest

from fleetsim.msgs import sensor_msgs
from fleetsim.nav.costmap.obstacle_layer import laser_scan_points
from fleetsim.nav.costmap.readings import points_from_scan


def scan(ranges):
    return sensor_msgs.LaserScan(
        angle_min=-math.pi / 2,
        angle_max=math.pi / 2,
        angle_increment=math.pi / 2,
        range_min=0.1,
        range_max=5.0,
        ranges=np.array(ranges, dtype=np.float32),
    )


def test_the_same_scan_is_projected_once_and_equals_the_projection():
    msg = scan([1.0, np.inf, 2.0])
    first = points_from_scan(msg)
    assert points_from_scan(msg) is first  # the second costmap gets the same points
    expected = laser_scan_points(msg.ranges, msg.angle_min, msg.angle_increment, 0.1, 5.0)
    np.testing.assert_array_equal(first, expected)
    with pytest.raises(ValueError, match="read-only"):
        first[0, 0] = 9.0  # shared: nobody may change them


def test_another_scan_or_inf_rule_is_projected_anew():
    msg = scan([1.0, np.inf, 2.0])
    plain = points_from_scan(msg)
    with_inf = points_from_scan(msg, inf_is_valid=True)
    assert len(plain) == 2 and len(with_inf) == 3
    other = scan([1.0, np.inf, 2.0])  # equal content, another message
    assert points_from_scan(other) is not plain
    np.testing.assert_array_equal(points_from_scan(other), plain)
