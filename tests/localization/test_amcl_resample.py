"""Tests for fleetsim.localization.amcl.resample: low-variance resampler and KLD-sampling."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.localization.amcl.resample import (
    effective_sample_size,
    kld_resample,
    kld_sample_limits,
    systematic_resample_indices,
)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    st.lists(st.floats(0, 10), min_size=1, max_size=200).filter(lambda w: sum(w) > 1e-3),
    st.integers(1, 3000),
    st.floats(0, 0.999999),
)
def test_copies_within_one_of_expected(weights, n, u):
    w = np.array(weights)
    idx = systematic_resample_indices(w, n, u)
    assert len(idx) == n and np.all(np.diff(idx) >= 0)
    copies = np.bincount(idx, minlength=len(w))
    expected = n * w / w.sum()
    assert np.all(np.abs(copies - expected) < 1 + 1e-6)
    assert np.all(copies[w == 0] == 0)


def test_resampler_is_linear_time():
    """O(N): one merge pass; time per particle stays flat from 10^4 to 10^6 particles."""
    import time

    rng = np.random.default_rng(0)
    per = []
    for n in (10_000, 1_000_000):
        w = rng.random(n)
        systematic_resample_indices(w, n, 0.5)
        t0 = time.perf_counter()
        systematic_resample_indices(w, n, 0.5)
        per.append((time.perf_counter() - t0) / n)
    assert per[1] < 20 * per[0]  # quadratic would be 100x


def amcl_limit(k, err, z, lo, hi):
    """amcl's pf_resample_limit, transcribed."""
    if k <= 1:
        return hi
    b = 2 / (9 * (k - 1))
    x = 1 - b + math.sqrt(b) * z
    n = math.ceil((k - 1) / (2 * err) * x**3)
    return min(max(n, lo), hi)


def test_kld_limits_match_amcl_formula():
    ks = np.arange(0, 400)
    got = kld_sample_limits(ks, 0.01, 0.99, 100, 5000)
    assert list(got) == [amcl_limit(k, 0.01, 0.99, 100, 5000) for k in ks]
    assert np.all(np.diff(got[2:]) >= 0)


def test_kld_size_shrinks_with_concentration():
    rng = np.random.default_rng(1)
    spread = np.column_stack(
        [rng.uniform(0, 20, 5000), rng.uniform(0, 20, 5000), rng.uniform(-3, 3, 5000)]
    )
    tight = np.column_stack([rng.normal(5, 0.05, 5000), rng.normal(5, 0.05, 5000), np.zeros(5000)])
    w = np.full(5000, 1 / 5000)
    n_spread = len(kld_resample(spread, w, rng, 0.01, 0.99, 100, 5000))
    n_tight = len(kld_resample(tight, w, rng, 0.01, 0.99, 100, 5000))
    assert n_spread == 5000 and 100 < n_tight < 300


def test_kld_resample_follows_weights_and_injects_random_poses():
    rng = np.random.default_rng(2)
    parts = np.array([[0.0, 0, 0], [10.0, 0, 0], [20.0, 0, 0]])
    w = np.array([0.0, 0.25, 0.75])
    out = kld_resample(parts, w, rng, 0.01, 0.99, 1000, 1000)
    assert not np.any(out[:, 0] == 0.0)
    assert np.mean(out[:, 0] == 20.0) == pytest.approx(0.75, abs=0.01)

    def far_away(n, rng):
        return np.column_stack([np.full(n, 100.0), rng.uniform(0, 1, n), np.zeros(n)])

    out = kld_resample(parts, w, rng, 0.01, 0.99, 1000, 1000, w_diff=0.3, random_poses=far_away)
    assert np.mean(out[:, 0] == 100.0) == pytest.approx(0.3, abs=0.05)
    with pytest.raises(ValueError, match="needs random_poses"):
        kld_resample(parts, w, rng, 0.01, 0.99, 10, 10, w_diff=0.5)


def test_effective_sample_size():
    assert effective_sample_size(np.full(10, 0.1)) == pytest.approx(10)
    assert effective_sample_size(np.array([1.0, 0, 0])) == pytest.approx(1)
    assert effective_sample_size(np.zeros(3)) == 0.0
