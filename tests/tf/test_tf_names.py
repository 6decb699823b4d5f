"""tf_prefix resolution (ROS 1 tf::resolve, without the leading slash) and frame id keys."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from tf_strategies import tf_settings

from fleetsim.errors import InvalidName
from fleetsim.tf.names import normalize_frame, resolve_frame, resolve_frame_once

segments = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,8}", fullmatch=True)
names = st.lists(segments, min_size=1, max_size=3).map("/".join)


@pytest.mark.parametrize(
    ("prefix", "frame", "expected"),
    [
        ("lizi1", "odom", "lizi1/odom"),
        ("lizi1", "base_link", "lizi1/base_link"),
        ("lizi1", "/map", "map"),
        ("", "odom", "odom"),
        ("/", "odom", "odom"),
        ("/lizi1/", "odom", "lizi1/odom"),
        ("/lizi1", "/lizi2/odom", "lizi2/odom"),
        ("fleet/lizi1", "laser_link", "fleet/lizi1/laser_link"),
        ("", "/map", "map"),
    ],
)
def test_resolve_frame_table(prefix, frame, expected):
    assert resolve_frame(prefix, frame) == expected


@tf_settings
@given(names, names)
def test_resolve_frame_properties(prefix, frame):
    resolved = resolve_frame(prefix, frame)
    assert resolved == f"{prefix}/{frame}"
    assert not resolved.startswith("/")
    assert resolve_frame(prefix, "/" + frame) == frame  # global frames are never prefixed
    assert resolve_frame("/" + prefix + "/", frame) == resolved
    assert resolve_frame("", frame) == frame
    assert resolve_frame("", "/" + resolved) == resolved


@pytest.mark.parametrize(
    ("prefix", "frame", "message"),
    [
        ("lizi1", "", r"frame id '' is empty"),
        ("lizi1", "/", r"frame id '/' is empty"),
        ("lizi 1", "odom", r"tf_prefix 'lizi 1' contains the invalid character ' '"),
        ("lizi1", "base link", r"frame id 'base link' contains the invalid character ' '"),
        ("lizi1", "/map$", r"frame id '/map\$' contains the invalid character '\$'"),
        ("lizi1", "a//b", r"frame id 'a//b' has an empty segment"),
        ("lizi1", "odom/", r"frame id 'odom/' has an empty segment"),
        ("a//b", "odom", r"tf_prefix 'a//b' has an empty segment"),
    ],
)
def test_resolve_frame_rejects_invalid_names(prefix, frame, message):
    with pytest.raises(InvalidName, match=message):
        resolve_frame(prefix, frame)


def test_resolve_frame_rejects_non_strings():
    with pytest.raises(InvalidName, match=r"frame id must be a string, got 3"):
        resolve_frame("lizi1", 3)
    with pytest.raises(InvalidName, match=r"tf_prefix must be a string, got None"):
        resolve_frame(None, "odom")


def test_normalize_frame_strips_one_leading_slash_and_rejects_empty():
    assert normalize_frame("/map") == "map"
    assert normalize_frame("lizi1/odom") == "lizi1/odom"
    with pytest.raises(InvalidName, match=r"frame id '' is empty"):
        normalize_frame("")
    with pytest.raises(InvalidName, match=r"frame id '/' is empty"):
        normalize_frame("/")
    with pytest.raises(InvalidName, match=r"frame id must be a string"):
        normalize_frame(None)


@pytest.mark.parametrize(
    ("prefix", "frame", "expected"),
    [
        ("lizi1", "lizi1/base_link", "lizi1/base_link"),
        ("lizi1", "base_link", "lizi1/base_link"),
        ("/lizi1/", "lizi1/laser_link", "lizi1/laser_link"),
        ("lizi1", "lizi2/base_link", "lizi1/lizi2/base_link"),
        ("lizi1", "lizi10/base_link", "lizi1/lizi10/base_link"),
        ("lizi1", "/map", "map"),
        ("", "base_link", "base_link"),
    ],
)
def test_resolve_frame_once_accepts_already_prefixed_frames(prefix, frame, expected):
    assert resolve_frame_once(prefix, frame) == expected
