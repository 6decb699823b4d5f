"""The CTRV tracker on synthetic tracks (straight, circle, stop) against the ground truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fleetsim.apps.target_tracker import (
    TargetTracker,
    TrackerParams,
    ctrv_jacobian,
    ctrv_step,
    wrap,
)
from fleetsim.errors import ParameterError

DT = 0.1  # s, the camera's 10 Hz


def track(kind: str, duration: float) -> np.ndarray:
    """Ground truth (N, 6): t, x, y, heading, speed, yaw rate, every DT."""
    t = np.arange(0.0, duration, DT)
    if kind == "straight":
        v, w = np.full_like(t, 0.2), np.zeros_like(t)
    elif kind == "circle":  # the tutorial's patrol: 0.1 m/s round a 1.5 m radius, clockwise
        v, w = np.full_like(t, 0.1), np.full_like(t, -0.1 / 1.5)
    elif kind == "stop":  # drives, stops for 4 s, drives on
        v = np.where((t > 6) & (t < 10), 0.0, 0.2)
        w = np.zeros_like(t)
    else:
        raise ValueError(kind)
    states = [np.array([1.0, -2.0, 0.7, v[0], w[0]])]
    for k in range(1, len(t)):
        s = ctrv_step(np.array([*states[-1][:3], v[k - 1], w[k - 1]]), DT)
        states.append(np.array([*s[:3], v[k], w[k]]))
    return np.column_stack([t, np.array(states)])


def run_filter(truth: np.ndarray, rng: np.random.Generator, noise=(0.03, 0.1), every=1):
    tracker = TargetTracker()
    for k, row in enumerate(truth):
        if k % every:
            continue
        fix = row[1:4] + rng.normal(0.0, [noise[0], noise[0], noise[1]])
        tracker.update(row[0], fix, distance=1.0)
    return tracker


@pytest.mark.parametrize("kind", ["straight", "circle", "stop"])
def test_the_filter_converges_on_the_true_state(kind):
    truth = track(kind, 20.0)
    tracker = run_filter(truth, np.random.default_rng(0))
    x, want = tracker.x, truth[-1, 1:]
    assert np.hypot(*(x[:2] - want[:2])) < 0.05
    assert abs(wrap(x[2] - want[2])) < 0.1
    assert x[3] == pytest.approx(want[3], abs=0.03)
    assert x[4] == pytest.approx(want[4], abs=0.05)


@pytest.mark.parametrize("kind", ["straight", "circle"])
def test_the_prediction_three_seconds_ahead_beats_holding_the_last_fix(kind):
    truth = track(kind, 23.0)
    cut = int(20.0 / DT)
    tracker = run_filter(truth[:cut], np.random.default_rng(1))
    means, covs = tracker.predicted_states(truth[cut - 1, 0], DT, 30)
    future = truth[cut : cut + 30, 1:3]
    err = np.hypot(*(means[:, :2] - future).T)
    held = np.hypot(*(truth[cut - 1, 1:3] - future).T)
    assert err[-1] < 0.2 and err[-1] < 0.5 * held[-1]  # 3 s ahead
    # the uncertainty grows along the horizon and covers the error
    sd = np.sqrt(np.trace(covs, axis1=1, axis2=2))
    assert np.all(np.diff(sd) > 0)
    assert np.all(err < 3 * sd + 0.02)


def test_a_stopped_target_is_predicted_to_stay():
    truth = track("stop", 9.5)  # stopped since 6 s
    tracker = run_filter(truth, np.random.default_rng(2))
    means, _ = tracker.predicted_states(truth[-1, 0], DT, 20)
    assert np.hypot(*(means[-1, :2] - truth[-1, 1:3])) < 0.1


def test_outliers_and_flipped_headings_are_not_believed():
    truth = track("straight", 10.0)
    tracker = run_filter(truth, np.random.default_rng(3))
    t, x, y, th = truth[-1, :4]
    rejected = tracker.rejected
    assert not tracker.update(t + DT, np.array([x + 3.0, y, th]), distance=1.5)  # gated out
    assert tracker.rejected == rejected + 1
    before = tracker.x[2]
    assert tracker.update(t + 2 * DT, np.array([x + 0.04, y, th + math.pi]), distance=1.5)
    assert abs(wrap(tracker.x[2] - before)) < 0.05  # the flipped heading was left out


def test_fixes_that_keep_disagreeing_restart_the_filter():
    truth = track("straight", 5.0)
    tracker = run_filter(truth, np.random.default_rng(4))
    t = truth[-1, 0]
    for k in range(4):
        tracker.update(t + (k + 1) * DT, np.array([-3.0, 4.0, 0.0]))
    assert np.hypot(tracker.x[0] + 3.0, tracker.x[1] - 4.0) < 0.05


def test_sparse_fixes_still_track_the_circle():
    truth = track("circle", 30.0)
    tracker = run_filter(truth, np.random.default_rng(5), every=10)  # one fix a second
    assert np.hypot(*(tracker.x[:2] - truth[-10, 1:3])) < 0.1


def test_bad_input_is_named():
    tracker = TargetTracker(TrackerParams())
    with pytest.raises(ParameterError, match="no estimate yet"):
        tracker.predicted_states(0.0, DT, 3)
    with pytest.raises(ParameterError, match="3 finite numbers"):
        tracker.update(0.0, np.array([1.0, math.nan, 0.0]))


def test_one_state_step_and_batched_jacobian_equal_the_array_path_bit_for_bit():
    """The scalar step of one state and the Jacobian's batched differences are speed paths:
    they give what the (..., 5) array path and one difference per column give, to the bit."""
    rng = np.random.default_rng(7)
    states = rng.normal(size=(400, 5)) * [3.0, 3.0, 20.0, 0.5, 1.0]
    states[::5, 4] *= 1e-4  # straight-line cases, under SMALL_YAW_RATE
    steps = (1e-5, 1e-5, 1e-6, 1e-5, 1e-5)
    for s, dt in zip(states, rng.choice([0.033, 0.05, 0.1, 0.2], size=len(states)), strict=True):
        one = ctrv_step(s, dt)
        assert np.array_equal(one, ctrv_step(s[None], dt)[0])
        want = np.empty((5, 5))
        for i, h in enumerate(steps):
            d = np.zeros(5)
            d[i] = h
            diff = ctrv_step((s + d)[None], dt)[0] - ctrv_step((s - d)[None], dt)[0]
            diff[2] = wrap(diff[2])
            want[:, i] = diff / (2 * h)
        assert np.array_equal(ctrv_jacobian(s, dt), want)
        assert ctrv_jacobian(s, dt).flags.c_contiguous


def test_a_state_with_an_infinite_heading_or_turn_rate_steps_to_nan_not_an_error():
    for bad in ([0.0, 0.0, np.inf, 0.3, 0.1], [0.0, 0.0, 0.2, 0.3, -np.inf]):
        with np.errstate(invalid="ignore"):
            assert np.isnan(ctrv_step(np.array(bad), 0.1)).any()
