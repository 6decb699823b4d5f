"""rostopic-style YAML, command-line YAML, rate statistics."""

import math

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from fleetsim.errors import MessageError
from fleetsim.msgs import geometry_msgs, sensor_msgs
from fleetsim.transport.textout import (
    RateStats,
    fill_now,
    message_yaml,
    parse_yaml_arg,
    yaml_text,
)


def test_message_yaml_is_block_yaml_with_inline_number_lists():
    scan = sensor_msgs.LaserScan(ranges=np.array([1.0, np.inf, 2.0], np.float32))
    text = message_yaml(scan)
    assert "ranges: [1.0, .inf, 2.0]\n" in text
    assert "header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: ''\n" in text
    assert yaml.safe_load(text)["ranges"][1] == math.inf
    assert "ranges: '<array type: float, length: 3>'" in message_yaml(scan, no_arrays=True)
    assert yaml_text({"a": [{"b": 1}]}) == "a:\n- b: 1\n"


def test_parse_yaml_arg():
    assert parse_yaml_arg("{x: 1, y: [1, 2]}", "w") == {"x": 1, "y": [1, 2]}
    assert parse_yaml_arg("  ", "w") is None and parse_yaml_arg(None, "w") is None
    with pytest.raises(MessageError, match=r"^topic pub /a: the YAML does not parse at line 1, "):
        parse_yaml_arg("{x: [", "topic pub /a")


def test_fill_now_replaces_only_stamps():
    data = {"header": {"stamp": "now", "frame_id": "now"}, "list": [{"stamp": "now"}]}
    assert fill_now(data, 2.5) == {
        "header": {"stamp": 2.5, "frame_id": "now"},
        "list": [{"stamp": 2.5}],
    }
    msg = __import__("fleetsim.msgs", fromlist=["from_dict"]).from_dict(
        geometry_msgs.PoseStamped, fill_now({"header": {"stamp": "now"}}, 2.5)
    )
    assert msg.header.stamp.to_sec() == 2.5


@given(st.floats(0.001, 10.0), st.integers(3, 50))
def test_rate_of_regular_arrivals(period, n):
    stats = RateStats(window=100)
    for i in range(n):
        stats.add(i * period)
    r = stats.report()
    assert r["rate"] == pytest.approx(1.0 / period, rel=1e-6)
    assert r["std"] == pytest.approx(0.0, abs=1e-9 * period + 1e-12)
    assert r["window"] == n


def test_rate_window_and_errors():
    stats = RateStats(window=3)
    assert stats.report() is None
    for t in (0.0, 10.0, 10.5, 11.0):
        stats.add(t)
    r = stats.report()
    assert r["rate"] == pytest.approx(2.0) and r["max"] == pytest.approx(0.5)
    assert RateStats.format(r).startswith("average rate: 2.000\n\tmin: 0.500s")
    with pytest.raises(MessageError, match="hz window must be at least 2 messages, got 1"):
        RateStats(window=1)
