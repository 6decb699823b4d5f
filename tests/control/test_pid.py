"""control_toolbox-style PID: gains from YAML, integral clamp, clear errors."""

import pytest

from fleetsim.control.pid import Pid
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
    with pytest.raises(ControlError, match="gains/j1/d: must be a number"):
        Pid.from_params({"p": 1, "d": "x"}, "gains/j1")
