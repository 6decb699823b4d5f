"""FrameInfo summaries and tf2's allFramesAsYAML / allFramesAsString layouts."""

from __future__ import annotations

import pytest
import yaml

from fleetsim.tf.cache import FrameCache
from fleetsim.tf.frame_info import frame_info_of, frames_as_dot, frames_as_string, frames_as_yaml

S = 1_000_000_000


def cache(name, parent, stamps, static=False, authority=""):
    c = FrameCache(name)
    c.reset(parent, static)
    c.authority = authority
    for s in stamps:
        c.insert(s, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0), 100 * S)
    return c


def test_frame_info_rates_and_windows():
    info = frame_info_of(
        cache("odom", "map", [0, S // 2, S, 3 * S // 2, 2 * S], authority="/amcl"), 10.0
    )
    assert info.rate == pytest.approx(2.0)
    assert (info.oldest, info.most_recent, info.buffer_length) == (0.0, 2.0, 2.0)
    assert info.authority == "/amcl" and info.parent == "map" and not info.is_static
    single = frame_info_of(cache("odom", "map", [S]), 10.0)
    assert single.rate is None and single.authority == "default_authority"
    static = frame_info_of(cache("laser", "base", [0], static=True), 10.0)
    assert static.is_static and static.rate is None


def test_yaml_and_string_layouts():
    infos = {
        "odom": frame_info_of(cache("odom", "map", [0, S]), 10.0),
        "laser": frame_info_of(cache("laser", "odom", [0], static=True), 10.0),
    }
    doc = yaml.safe_load(frames_as_yaml(infos))
    assert doc["odom"]["parent"] == "map" and doc["odom"]["rate"] == 1.0
    assert doc["odom"]["broadcaster"] == "default_authority"
    assert doc["laser"]["rate"] == 10000.0 and doc["laser"]["is_static"] is True
    assert frames_as_yaml({}) == ""
    assert frames_as_string({"odom": "map", "laser": "odom"}) == (
        "Frame odom exists with parent map.\nFrame laser exists with parent odom.\n"
    )


def test_dot_graph_has_one_labelled_edge_per_child():
    infos = {
        "lizi1/odom": frame_info_of(cache("lizi1/odom", "map", [0, S], authority="/amcl"), 10.0),
        "lizi1/laser": frame_info_of(cache("lizi1/laser", "lizi1/odom", [0], static=True), 10.0),
    }
    dot = frames_as_dot(infos, recorded_at=12.5)
    assert dot.startswith("digraph G {\n") and dot.endswith("}\n")
    assert '"map" -> "lizi1/odom" [label="Broadcaster: /amcl\\nAverage rate: 1.000 Hz\\n' in dot
    assert '"lizi1/odom" -> "lizi1/laser" [label="Broadcaster: default_authority\\n' in dot
    assert "Average rate: static" in dot and 'label="Recorded at time: 12.500"' in dot
