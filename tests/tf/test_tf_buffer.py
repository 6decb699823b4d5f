"""tf Buffer: lookups across the tree, interpolation, time 0, static frames, errors."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from tf_strategies import tf_settings, translations, unit_quaternions

from fleetsim.errors import (
    ConnectivityError,
    ExtrapolationError,
    FrameNotFound,
    InvalidName,
    ParameterError,
    TransformError,
)
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.geometry_msgs import TransformStamped
from fleetsim.tf import transforms as tm
from fleetsim.tf.buffer import Buffer

IDENT_Q = (0.0, 0.0, 0.0, 1.0)


def msg(parent, child, stamp, t=(0.0, 0.0, 0.0), q=IDENT_Q) -> TransformStamped:
    m = TransformStamped()
    m.header.frame_id = parent
    m.header.stamp = Time.from_sec(stamp)
    m.child_frame_id = child
    tr, r = m.transform.translation, m.transform.rotation
    tr.x, tr.y, tr.z = map(float, t)
    r.x, r.y, r.z, r.w = map(float, q)
    return m


def yawq(yaw):
    return tuple(tm.quaternion_from_yaw(yaw))


def robot_buffer() -> Buffer:
    """map -> lizi1/odom (1 Hz, moving) -> lizi1/base_link (10 Hz, driving) -> laser (static)."""
    buf = Buffer()
    for k in range(6):
        buf.set_transform(msg("map", "lizi1/odom", k, (0.1 * k, 0.0, 0.0), yawq(0.01 * k)))
    for k in range(51):
        t = 0.1 * k
        buf.set_transform(msg("lizi1/odom", "lizi1/base_link", t, (t, 0.5 * t, 0.0), yawq(0.2 * t)))
    buf.set_transform(msg("lizi1/base_link", "lizi1/laser_link", 0.0, (0, 0, 1.0)), is_static=True)
    return buf


def reference(buf_edges, target, source):
    """Compose T_root_frame for each frame from the edges {child: (parent, t, q)}, brute force."""

    def to_root(frame):
        t, q = np.zeros(3), np.array(IDENT_Q)
        chain = []
        while frame in buf_edges:
            parent, et, eq = buf_edges[frame]
            chain.append((et, eq))
            frame = parent
        for et, eq in reversed(chain):
            t, q = tm.compose_transforms(t, q, et, eq)
        return t, q

    tt, qt = to_root(target)
    ts, qs = to_root(source)
    return tm.compose_transforms(*tm.inverse_transform(tt, qt), ts, qs)


@tf_settings
@given(
    st.lists(st.integers(0, 20), min_size=1, max_size=7),
    st.lists(st.tuples(translations, unit_quaternions()), min_size=7, max_size=7),
    st.integers(0, 7),
    st.integers(0, 7),
)
def test_lookup_across_a_random_tree_matches_brute_force(parents, values, a, b):
    # frame i+1's parent is one of the frames 0..i: a random tree rooted at f0
    buf = Buffer()
    edges = {}
    for i, p in enumerate(parents):
        child, parent = f"f{i + 1}", f"f{p % (i + 1)}"
        t, q = values[i]
        buf.set_transform(msg(parent, child, 1.0, t, q))
        edges[child] = (parent, t, q)
    a, b = f"f{a % (len(parents) + 1)}", f"f{b % (len(parents) + 1)}"
    got = buf.lookup_arrays(a, b)
    want = reference(edges, a, b)
    assert np.allclose(got[0], want[0], atol=1e-8)
    assert np.allclose(got[1], want[1], atol=1e-8) or np.allclose(got[1], -want[1], atol=1e-8)


def test_lookup_transform_message_maps_source_points_into_target():
    buf = robot_buffer()
    out = buf.lookup_transform("map", "lizi1/laser_link", 2.0)
    assert out.header.frame_id == "map" and out.child_frame_id == "lizi1/laser_link"
    assert out.header.stamp == Time(2, 0)
    t, q = buf.lookup_arrays("map", "lizi1/laser_link", 2.0)
    # laser origin: odom at (0.2, 0) yaw 0.02; base at (2, 1) yaw 0.4 in odom; laser 1 m above
    odom_t, odom_q = tm.transform_from_pose2d(0.2, 0.0, 0.02)
    want = tm.transform_points(odom_t, odom_q, [[2.0, 1.0, 1.0]])[0]
    assert np.allclose(t, want)
    assert tm.yaw_from_quaternion(q) == pytest.approx(0.42)
    tr = out.transform.translation
    assert np.allclose([tr.x, tr.y, tr.z], t)
    # the inverse lookup maps the other way
    ti, qi = buf.lookup_arrays("lizi1/laser_link", "map", 2.0)
    assert np.allclose(tm.transform_points(ti, qi, [want]), [[0.0, 0.0, 0.0]], atol=1e-12)


def test_interpolates_linearly_and_by_slerp_between_bracketing_stamps():
    buf = Buffer()
    buf.set_transform(msg("odom", "base", 1.0, (0.0, 0.0, 0.0), yawq(0.0)))
    buf.set_transform(msg("odom", "base", 2.0, (1.0, 2.0, 0.0), yawq(1.0)))
    x, y, yaw = buf.lookup_pose2d("odom", "base", 1.25)
    assert (x, y, yaw) == pytest.approx((0.25, 0.5, 0.25))
    assert buf.lookup_tuple("odom", "base", 2.0)[:3] == (1.0, 2.0, 0.0)


def test_latest_common_time_follows_the_tree_when_its_edges_change():
    """The frame path kept between asks is dropped when an edge moves or the buffer clears:
    the latest time is the new chain's."""
    buf = Buffer()
    buf.set_transform(msg("map", "odom", 3.0))
    buf.set_transform(msg("odom", "base", 5.0))
    buf.set_transform(msg("map", "other", 1.0))
    assert buf.latest_common_time("map", "base") == pytest.approx(3.0)
    assert buf.latest_common_time("map", "base") == pytest.approx(3.0)  # kept path
    buf.set_transform(msg("other", "odom", 2.0))  # odom moves under other (at 1.0)
    assert buf.latest_common_time("map", "base") == pytest.approx(1.0)
    buf.clear()
    with pytest.raises(ConnectivityError):
        buf.latest_common_time("map", "base")


def test_time_zero_uses_the_latest_common_time_and_static_edges_do_not_limit_it():
    buf = robot_buffer()
    assert buf.latest_common_time("map", "lizi1/laser_link") == pytest.approx(5.0)
    assert buf.latest_common_time("lizi1/base_link", "lizi1/laser_link") == 0.0
    buf.set_transform(msg("lizi1/odom", "lizi1/base_link", 5.05, (9.0, 0.0, 0.0)))
    out = buf.lookup_transform("map", "lizi1/laser_link")  # odom's newest is 5.0
    assert out.header.stamp == Time(5, 0)
    assert buf.lookup_transform("lizi1/odom", "lizi1/laser_link", None).header.stamp == Time(
        5, 50_000_000
    )
    assert buf.lookup_transform("lizi1/odom", "lizi1/laser_link", Time(0, 0)).header.stamp == Time(
        5, 50_000_000
    )
    # a purely static chain: any time works, latest is stamp 0
    assert buf.lookup_transform("lizi1/base_link", "lizi1/laser_link", 1234.5).header.stamp == Time(
        1234, 500_000_000
    )


def test_stamps_meet_exactly_whether_given_as_time_or_float_seconds():
    buf = Buffer()
    t = 0.1 + 0.2  # 0.30000000000000004
    buf.set_transform(msg("odom", "base", 0.1))
    buf.set_transform(msg("odom", "base", t, (1.0, 0.0, 0.0)))
    assert buf.lookup_tuple("odom", "base", t)[0] == 1.0
    assert buf.lookup_tuple("odom", "base", Time.from_sec(t))[0] == 1.0


def test_cache_window_prunes_old_entries_and_reports_past_extrapolation():
    buf = Buffer(cache_time=10.0)
    for k in range(21):
        buf.set_transform(msg("odom", "base", float(k), (float(k), 0.0, 0.0)))
    info = buf.frame_info("base")
    assert (info.oldest, info.most_recent) == (10.0, 20.0)
    with pytest.raises(
        ExtrapolationError,
        match=r"lookup of 'base' in 'odom' at time 5\.000000000 s would require extrapolation "
        r"into the past: the edge 'odom' -> 'base' has data from 10\.000000000 to 20\.0+ s",
    ):
        buf.lookup_transform("odom", "base", 5.0)
    with pytest.raises(ExtrapolationError, match=r"at time 20\.5\d* s .* into the future"):
        buf.lookup_transform("odom", "base", 20.5)


def test_single_stamp_extrapolation_message_and_can_transform():
    buf = Buffer()
    buf.set_transform(msg("map", "odom", 3.0))
    assert buf.can_transform("map", "odom", 3.0)
    assert buf.can_transform("map", "odom")
    assert not buf.can_transform("map", "odom", 3.5)
    assert not buf.can_transform("map", "nowhere")
    with pytest.raises(ExtrapolationError, match=r"only time 3\.0+ s is in the buffer"):
        buf.lookup_transform("odom", "map", 2.0)


def test_old_data_is_ignored_with_a_warning(caplog):
    buf = Buffer(cache_time=1.0)
    buf.set_transform(msg("odom", "base", 5.0))
    with caplog.at_level(logging.WARNING, logger="fleetsim.tf"):
        assert buf.set_transform(msg("odom", "base", 3.0), authority="/sim") is False
    assert "older than the cache window" in caplog.text and "/sim" in caplog.text


def test_repeated_stamp_replaces_and_out_of_order_inserts_sort():
    buf = Buffer()
    buf.set_transform(msg("odom", "base", 2.0, (2.0, 0, 0)))
    buf.set_transform(msg("odom", "base", 1.0, (1.0, 0, 0)))
    buf.set_transform(msg("odom", "base", 1.5, (7.0, 0, 0)))
    buf.set_transform(msg("odom", "base", 1.5, (1.5, 0, 0)))
    assert buf.lookup_tuple("odom", "base", 1.25)[0] == pytest.approx(1.25)
    assert buf.frame_info("base").rate == pytest.approx(2.0)


def test_frame_not_found_suggests_and_lists_known_frames():
    buf = robot_buffer()
    with pytest.raises(
        FrameNotFound,
        match=r"source_frame 'lizi1/base_lnk' does not exist in the tf tree \(did you mean "
        r"'lizi1/base_link'\?\); known frames: lizi1/base_link, lizi1/laser_link, lizi1/odom, map",
    ):
        buf.lookup_transform("map", "lizi1/base_lnk")
    with pytest.raises(FrameNotFound, match=r"target_frame 'world' does not exist"):
        buf.lookup_transform("world", "map")


def test_a_shared_frame_that_took_a_tf_prefix_is_named_with_the_fix():
    """turtlebot3_navigation's ``global_frame: map`` under a tf_prefix resolves to
    'lizi1/map' (ROS 1's tf::resolve); the message says that '/map' is the shared frame."""
    buf = robot_buffer()
    with pytest.raises(
        FrameNotFound,
        match=r"target_frame 'lizi1/map' does not exist in the tf tree \('map' exists "
        r"unprefixed: if it is the shared frame, write '/map' \(a frame written without a "
        r"leading slash takes the node's tf_prefix\); if it is this robot's own, its publisher "
        r"lacks the tf_prefix\); known frames: ",
    ):
        buf.lookup_transform("lizi1/map", "lizi1/base_link")


def test_a_bare_frame_whose_prefixed_twins_exist_names_the_missing_tf_prefix():
    """Robots in <group ns> without a tf_prefix parameter: the simulator prefixes their
    frames with the namespace (lizi1/odom) while their nodes ask for the bare 'odom', and a
    robot_state_publisher's bare links form a tree of their own."""
    buf = robot_buffer()
    buf.set_transform(msg("lizi2/odom", "lizi2/base_link", 1.0))
    buf.set_transform(msg("base_link", "wheel", 1.0))
    fix = (
        r"frames named 'odom' under a tf_prefix exist \(lizi1/odom, lizi2/odom\): a node without "
        r"a tf_prefix uses the bare name, while the simulator prefixes a robot's frames with its "
        r"namespace; set the tf_prefix parameter in each robot's namespace \(<param "
        r'name="tf_prefix" value="lizi1"/> in its <group ns>\) so that its nodes use it too; '
        r"known frames: "
    )
    with pytest.raises(
        FrameNotFound, match=r"target_frame 'odom' does not exist in the tf tree; " + fix
    ):
        buf.lookup_transform("odom", "base_link")
    # not hinted: a prefixed name; a bare one with no twin; a bare one looked up from a
    # prefixed frame (each hunter's gmapping publishes hunterN/map before the shared 'map'
    # exists: these robots have their prefix); two trees apart, where a missing localization
    # is the likelier cause
    hunters = Buffer()
    for n in (1, 2):
        hunters.set_transform(msg(f"hunter{n}/map", f"hunter{n}/odom", 1.0))
    for b, target, source, error in (
        (buf, "lizi3/odom", "lizi1/base_link", FrameNotFound),
        (buf, "world", "base_link", FrameNotFound),
        (buf, "map", "base_link", ConnectivityError),
        (hunters, "map", "hunter1/odom", FrameNotFound),
    ):
        with pytest.raises(error) as e:
            b.lookup_transform(target, source)
        assert "under a tf_prefix" not in str(e.value), (target, source)


def test_disconnected_trees_name_both_roots():
    buf = robot_buffer()
    buf.set_transform(msg("lizi2/odom", "lizi2/base_link", 1.0))
    with pytest.raises(
        ConnectivityError,
        match=r"cannot transform 'lizi2/base_link' into 'lizi1/laser_link': they are in "
        r"disconnected tf trees \('lizi1/laser_link' is under root 'map', 'lizi2/base_link' "
        r"under root 'lizi2/odom'\)",
    ):
        buf.lookup_transform("lizi1/laser_link", "lizi2/base_link")


def test_leading_slash_is_ignored_and_empty_names_rejected():
    buf = robot_buffer()
    out = buf.lookup_transform("/map", "/lizi1/odom", 1.0)
    assert (out.header.frame_id, out.child_frame_id) == ("map", "lizi1/odom")
    with pytest.raises(InvalidName, match=r"frame id '' is empty"):
        buf.lookup_transform("", "map")
    with pytest.raises(InvalidName, match=r"frame id '' is empty"):
        buf.set_transform(msg("", "base", 1.0))


def test_invalid_transforms_are_rejected_with_the_frames_named():
    buf = Buffer()
    with pytest.raises(TransformError, match=r"child_frame_id equal to frame_id 'base'"):
        buf.set_transform(msg("base", "/base", 1.0))
    with pytest.raises(TransformError, match=r"'odom' -> 'base' has a non-finite value"):
        buf.set_transform(msg("odom", "base", 1.0, (math.nan, 0, 0)))
    with pytest.raises(TransformError, match=r"quaternion of norm 0, not 1"):
        buf.set_transform(msg("odom", "base", 1.0, q=(0, 0, 0, 0)))
    with pytest.raises(TransformError, match=r"translation must be 3 numbers"):
        buf.set_transform_values("odom", "base", 1.0, (1, 2), IDENT_Q)
    buf.set_transform(msg("odom", "base", 1.0, q=(0, 0, 0, 1.0001)))  # close: normalised
    assert buf.lookup_tuple("odom", "base")[6] == 1.0
    with pytest.raises(ParameterError, match=r"cache_time must be a positive number"):
        Buffer(cache_time=0)


def test_a_transform_closing_a_loop_is_rejected():
    buf = Buffer()
    buf.set_transform(msg("a", "b", 1.0))
    buf.set_transform(msg("b", "c", 1.0))
    with pytest.raises(
        TransformError,
        match=r"would close a loop in the tf tree \(parent -> child: a -> b -> c -> a\)",
    ):
        buf.set_transform(msg("c", "a", 1.0))


def test_reparenting_drops_history_and_updates_the_tree():
    buf = Buffer()
    buf.set_transform(msg("odom", "base", 1.0, (1.0, 0, 0)))
    buf.set_transform(msg("map", "odom", 1.0, (0, 1.0, 0)))
    assert buf.lookup_tuple("map", "base")[:2] == (1.0, 1.0)
    buf.set_transform(msg("map", "base", 2.0, (5.0, 0, 0)))
    assert buf.parents()["base"] == "map"
    assert buf.lookup_tuple("map", "base")[:2] == (5.0, 0.0)
    assert not buf.can_transform("map", "base", 1.0)


def test_clear_keeps_static_transforms():
    buf = robot_buffer()
    buf.clear()
    assert buf.can_transform("lizi1/base_link", "lizi1/laser_link")
    assert not buf.can_transform("map", "lizi1/base_link")
    with pytest.raises(ConnectivityError):
        buf.lookup_transform("map", "lizi1/base_link")


def test_same_frame_is_identity():
    buf = robot_buffer()
    assert buf.lookup_tuple("map", "map") == (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def test_lookup_transform_full_through_a_fixed_frame():
    buf = robot_buffer()
    # where is the laser of t=1 s seen from base_link at t=4 s, with odom fixed
    out = buf.lookup_transform_full("lizi1/base_link", 4.0, "lizi1/laser_link", 1.0, "lizi1/odom")
    t4 = buf.lookup_arrays("lizi1/odom", "lizi1/base_link", 4.0)
    t1 = buf.lookup_arrays("lizi1/odom", "lizi1/laser_link", 1.0)
    want = tm.compose_transforms(*tm.inverse_transform(*t4), *t1)
    tr = out.transform.translation
    assert np.allclose([tr.x, tr.y, tr.z], want[0])
    assert out.header.stamp == Time(4, 0)


def test_fast_paths_agree():
    buf = robot_buffer()
    t, q = buf.lookup_arrays("map", "lizi1/laser_link", 3.33)
    m = buf.lookup_matrix("map", "lizi1/laser_link", 3.33)
    assert np.allclose(m, tm.matrix_from_transform(t, q))
    tup = buf.lookup_tuple("map", "lizi1/laser_link", 3.33)
    assert np.allclose(tup, np.r_[t, q])
    x, y, yaw = buf.lookup_pose2d("map", "lizi1/laser_link", 3.33)
    assert (x, y, yaw) == pytest.approx((t[0], t[1], tm.yaw_from_quaternion(q)))


def test_introspection_lists_frames_parents_authority_and_rates():
    buf = robot_buffer()
    buf.set_transform(msg("map", "lizi1/odom", 6.0), authority="/lizi1/fake_localization")
    assert buf.all_frames() == ["lizi1/base_link", "lizi1/laser_link", "lizi1/odom", "map"]
    assert buf.parents() == {
        "lizi1/base_link": "lizi1/odom",
        "lizi1/laser_link": "lizi1/base_link",
        "lizi1/odom": "map",
    }
    info = buf.frame_info("/lizi1/odom")
    assert info.authority == "/lizi1/fake_localization" and info.parent == "map"
    assert info.rate == pytest.approx(1.0) and info.buffer_length == pytest.approx(6.0)
    base = buf.frames_info()["lizi1/base_link"]
    assert base.rate == pytest.approx(10.0) and base.authority == "default_authority"
    laser = buf.frame_info("lizi1/laser_link")
    assert laser.is_static and laser.rate is None
    assert "Frame lizi1/odom exists with parent map.\n" in buf.all_frames_as_string()
    assert "broadcaster: /lizi1/fake_localization" in buf.all_frames_as_yaml()
    dot = buf.all_frames_as_dot(recorded_at=6.0)
    assert dot.count(" -> ") == 3 and '"map" -> "lizi1/odom"' in dot
    with pytest.raises(FrameNotFound, match=r"'map' is a root of the tf tree"):
        buf.frame_info("map")
    with pytest.raises(FrameNotFound, match=r"frame 'mapp' does not exist.*did you mean 'map'"):
        buf.frame_info("mapp")


def test_bad_time_arguments_are_named():
    buf = robot_buffer()
    with pytest.raises(TransformError, match=r"tf time inf is not finite"):
        buf.lookup_transform("map", "lizi1/odom", math.inf)
    with pytest.raises(TransformError, match=r"tf time 'now' is neither seconds nor"):
        buf.lookup_transform("map", "lizi1/odom", "now")


def test_call_after_next_message_fires_once_after_a_message_that_adds_a_transform():
    from fleetsim.msgs.tf2_msgs import TFMessage

    buf = Buffer()
    seen = []

    def retry():
        seen.append(buf.can_transform("odom", "base_link", 1.0))

    buf.call_after_next_message(retry)
    buf.call_after_next_message(retry)  # the same callback waits once
    assert buf.add_message(TFMessage(transforms=[])) == 0 and seen == []  # nothing added
    first = TFMessage(transforms=[msg("odom", "base_link", 1.0, (1.0, 0.0, 0.0))])
    assert buf.add_message(first) == 1
    assert seen == [True]  # after the whole message went in
    buf.add_message(TFMessage(transforms=[msg("odom", "base_link", 2.0, (2.0, 0.0, 0.0))]))
    assert seen == [True]  # one-shot


def test_a_callback_may_wait_again_from_inside_its_call():
    from fleetsim.msgs.tf2_msgs import TFMessage

    buf = Buffer()
    calls = []

    def retry():
        calls.append(len(calls))
        if len(calls) < 2:
            buf.call_after_next_message(retry)

    buf.call_after_next_message(retry)
    for k in range(3):
        buf.add_message(TFMessage(transforms=[msg("odom", "base_link", k + 1.0, (0, 0, 0))]))
    assert calls == [0, 1]


def test_a_callback_waiting_on_frames_ignores_other_robots_transforms():
    """A message filter waiting on robot 1's odom -> base_link edge is not woken by robot 2's
    transforms (N robots' amcl x N robots' /tf), but is by its own and by a tree change."""
    from fleetsim.msgs.tf2_msgs import TFMessage

    buf = Buffer()
    for r in ("r1", "r2"):
        buf.add_message(TFMessage(transforms=[msg(f"{r}/odom", f"{r}/base_link", 1.0, (0, 0, 0))]))
    edges = buf.edges_between("r1/odom", "r1/base_link")
    assert edges == frozenset({"r1/base_link"})
    calls = []
    buf.call_after_next_message(lambda: calls.append("r1"), edges)
    buf.add_message(TFMessage(transforms=[msg("r2/odom", "r2/base_link", 2.0, (0, 0, 0))]))
    assert calls == []
    buf.add_message(TFMessage(transforms=[msg("r1/odom", "r1/base_link", 2.0, (0, 0, 0))]))
    assert calls == ["r1"]
    buf.call_after_next_message(lambda: calls.append("tree"), edges)
    buf.add_message(TFMessage(transforms=[msg("map", "r2/odom", 2.0, (0, 0, 0))]))  # new edge
    assert calls == ["r1", "tree"]
    assert buf.edges_between("r1/odom", "nowhere") is None  # unknown frame: wait on anything
