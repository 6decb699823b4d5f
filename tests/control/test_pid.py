"""control_toolbox-style PID: gains from YAML, integral clamp, clear errors."""

import numpy as np
import pytest

from fleetsim.control.pid import Pid, PidArray
from fleetsim.errors import ControlError


def test_pd_and_clamped_integral():
    pid = Pid.from_params({"p": 10, "i": 100, "d": 2, "i_clamp": 0.5}, "g")
    assert pid.compute(0.1, -1.0, 0.01) == pytest.approx(10 * 0.1 + 0.1 - 2.0)
    for _ in range(100):
        pid.compute(1.0, 0.0, 0.01)
    assert pid.i_term == pytest.approx(0.5)
    pid.reset()
    assert pid.i_term == 0.0


def test_bad_gains_name_the_key():
    with pytest.raises(ControlError, match="gains/j1: unknown gain 'kp'"):
        Pid.from_params({"kp": 1}, "gains/j1")
    with pytest.raises(ControlError, match="gains/j1: no 'p' gain"):
        Pid.from_params({"d": 1}, "gains/j1")
    with pytest.raises(ControlError, match="gains/j1/d: must be a finite number"):
        Pid.from_params({"p": 1, "d": "x"}, "gains/j1")
    with pytest.raises(ControlError, match="gains/j1/i_clamp: must be a finite number, got nan"):
        Pid.from_params({"p": 1, "i_clamp": float("nan")}, "gains/j1")


def test_pid_array_matches_one_pid_per_joint_bit_for_bit():
    gains = [
        {"p": 10, "i": 100, "d": 2, "i_clamp": 0.5},
        {"p": 3.5, "i": 0.0, "d": 0.1},
        {"p": 1, "i": 7, "d": 0, "i_clamp": -0.2},  # control_toolbox takes |i_clamp|
    ]
    pids = [Pid.from_params(g, "g") for g in gains]
    arr = PidArray(pids)
    rng = np.random.default_rng(3)
    for _ in range(200):
        err, err_dot = rng.normal(size=3), rng.normal(size=3)
        want = [q.compute(e, ed, 0.004) for q, e, ed in zip(pids, err, err_dot, strict=True)]
        assert arr.compute(err, err_dot, 0.004).tolist() == want
    assert arr.i_term.tolist() == [q.i_term for q in pids]
    assert abs(arr.i_term[2]) <= 0.2
    arr.reset()
    assert not arr.i_term.any()
