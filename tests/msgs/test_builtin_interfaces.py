from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fleetsim.errors import MessageError
from fleetsim.msgs.builtin_interfaces import Duration, Time


@given(st.integers(min_value=-(2**31) * 10**9, max_value=(2**31 - 1) * 10**9))
def test_nsec_round_trip_and_normal_form(ns):
    for cls in (Time, Duration):
        t = cls.from_nsec(ns)
        assert 0 <= t.nanosec < 1_000_000_000
        assert t.to_nsec() == ns


@given(st.floats(min_value=-1e6, max_value=1e6))
def test_sec_round_trip_within_a_nanosecond(s):
    for cls in (Time, Duration):
        assert abs(cls.from_sec(s).to_sec() - s) <= 1e-9 + abs(s) * 1e-15


def test_examples():
    assert Time.from_sec(1.5) == Time(1, 500_000_000)
    assert Duration.from_sec(-0.25) == Duration(-1, 750_000_000)
    assert Time(2, 5).to_nsec() == 2_000_000_005
    assert Time.from_sec(1e-9).nanosec == 1


def test_not_finite_is_an_error():
    with pytest.raises(MessageError, match=r"Time\.from_sec: inf seconds"):
        Time.from_sec(float("inf"))
    with pytest.raises(MessageError, match=r"Duration\.from_sec: nan"):
        Duration.from_sec(float("nan"))
