"""FrameCache: sorted insertion, window pruning, interpolation, and stamp conversion."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from tf_strategies import tf_settings

from fleetsim.errors import ExtrapolationError, TransformError
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.tf.cache import FrameCache, checked_value, ns_from_time

S = 1_000_000_000


def value(x: float) -> tuple:
    return (x, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


@tf_settings
@given(st.lists(st.integers(0, 100), min_size=1, max_size=40), st.integers(1, 30))
def test_insert_keeps_stamps_sorted_unique_and_within_the_window(stamps_s, window_s):
    cache = FrameCache("base")
    cache.reset("odom", is_static=False)
    for s in stamps_s:
        cache.insert(s * S, value(s), window_s * S)
    assert cache.stamps == sorted(set(cache.stamps))
    assert cache.stamps[-1] == max(stamps_s) * S
    assert cache.stamps[0] >= cache.stamps[-1] - window_s * S
    assert [v[0] for v in cache.values] == [t / S for t in cache.stamps]
    # exactly the stamps inside the final window survive, whatever the insertion order
    newest = max(stamps_s)
    assert {t // S for t in cache.stamps} == {s for s in stamps_s if s >= newest - window_s}


def test_insert_rejects_data_older_than_the_window():
    cache = FrameCache("base")
    cache.reset("odom", is_static=False)
    assert cache.insert(10 * S, value(10), 2 * S)
    assert not cache.insert(7 * S, value(7), 2 * S)
    assert cache.insert(8 * S, value(8), 2 * S)
    assert cache.stamps == [8 * S, 10 * S]


def test_value_at_interpolates_and_raises_outside_the_window():
    cache = FrameCache("base")
    cache.reset("odom", is_static=False)
    for s in (1, 2, 4):
        cache.insert(s * S, value(s), 10 * S)
    assert cache.value_at(3 * S, "odom", "base")[0] == pytest.approx(3.0)
    assert cache.value_at(2 * S, "odom", "base") == value(2)
    with pytest.raises(ExtrapolationError, match=r"into the future: the edge 'odom' -> 'base'"):
        cache.value_at(5 * S, "odom", "base")
    with pytest.raises(ExtrapolationError, match=r"'base' in 'odom' at time 0\.5\d* s .* the past"):
        cache.value_at(S // 2, "odom", "base")


def test_static_cache_holds_one_value_for_all_times():
    cache = FrameCache("laser")
    cache.reset("base", is_static=True)
    cache.insert(5 * S, value(1), S)
    cache.insert(1 * S, value(2), S)  # a static edge is replaced whatever its stamp
    assert cache.value_at(10**6 * S, "base", "laser") == value(2)


def test_ns_from_time_accepts_seconds_and_time_messages():
    assert ns_from_time(None) == 0
    assert ns_from_time(0.1 + 0.2) == 300_000_000
    assert ns_from_time(Time(3, 5)) == 3 * S + 5
    assert ns_from_time(2) == 2 * S
    assert ns_from_time(np.float32(0.5)) == S // 2 and ns_from_time(np.int64(3)) == 3 * S
    with pytest.raises(TransformError, match=r"tf time nan is not finite"):
        ns_from_time(float("nan"))


def test_checked_value_normalises_near_unit_quaternions():
    v = checked_value("odom", "base", (1, 2, 3), (0, 0, 0, 1.0002))
    assert v == (1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0)
    with pytest.raises(
        TransformError, match=r"'odom' -> 'base' has a rotation quaternion of norm 2"
    ):
        checked_value("odom", "base", (0, 0, 0), (0, 0, 0, 2))
    with pytest.raises(TransformError, match=r"rotation 4 numbers \(x, y, z, w\)"):
        checked_value("odom", "base", (0, 0, 0), ("a", 0, 0, 1))
