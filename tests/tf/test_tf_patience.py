"""TransformPatience: failures are reported only once they have lasted the grace period."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fleetsim.tf.patience import GRACE, TransformPatience


def test_a_failure_is_reported_once_it_has_lasted_the_grace_period():
    p = TransformPatience()
    assert not p.missing_too_long("a", 1.0)
    assert not p.missing_too_long("a", 1.0 + GRACE - 0.01)
    assert p.missing_too_long("a", 1.0 + GRACE)
    assert p.missing_for("a", 1.0 + GRACE + 2.0) == pytest.approx(GRACE + 2.0)
    assert not p.missing_too_long("b", 1.0 + GRACE)  # keys wait on their own


def test_a_success_starts_a_new_wait():
    p = TransformPatience(grace=1.0)
    p.missing_too_long("a", 0.0)
    p.found("a")
    assert p.missing_for("a", 5.0) == 0.0
    assert not p.missing_too_long("a", 5.0)
    assert p.missing_too_long("a", 6.0)


def test_a_negative_grace_is_refused():
    with pytest.raises(ValueError, match="grace must be >= 0 s, got -1"):
        TransformPatience(grace=-1.0)


@given(st.lists(st.floats(0.0, 100.0), min_size=1, max_size=20), st.floats(0.0, 10.0))
def test_reported_exactly_when_the_first_failure_is_grace_old(times, grace):
    p = TransformPatience(grace)
    times = sorted(times)
    for t in times:
        assert p.missing_too_long("k", t) == (t - times[0] >= grace)
