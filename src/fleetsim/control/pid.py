"""control_toolbox's Pid: p, i, d gains with the integral term clamped to ``±i_clamp``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fleetsim.errors import ControlError

GAIN_KEYS = ("p", "i", "d", "i_clamp", "i_clamp_min", "i_clamp_max", "antiwindup")


@dataclass
class Pid:
    """One PID loop (``control_toolbox::Pid``); ``compute`` is called once per control period."""

    p: float = 0.0
    i: float = 0.0
    d: float = 0.0
    i_clamp: float = 0.0
    i_term: float = field(default=0.0, init=False)

    @classmethod
    def from_params(cls, gains: Any, where: str) -> Pid:
        """From a ``{p, i, d, i_clamp}`` dict as ros_control reads ``gains/<joint>``."""
        if not isinstance(gains, dict):
            raise ControlError(
                f"{where}: gains must be a dict with p, i, d, i_clamp; got {gains!r}"
            )
        unknown = sorted(set(gains) - set(GAIN_KEYS))
        if unknown:
            raise ControlError(f"{where}: unknown gain '{unknown[0]}'; gains are p, i, d, i_clamp")
        if "p" not in gains:
            raise ControlError(f"{where}: no 'p' gain (control_toolbox needs at least p)")
        vals = {}
        for k in ("p", "i", "d", "i_clamp"):
            v = gains.get(k, 0.0)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ControlError(f"{where}/{k}: must be a finite number, got {v!r}")
            vals[k] = float(v)
        return cls(**vals)

    def reset(self) -> None:
        self.i_term = 0.0

    def compute(self, error: float, error_dot: float, dt: float) -> float:
        """Command from the error (target - actual), its rate and the period (s)."""
        self.i_term += self.i * error * dt
        lim = abs(self.i_clamp)
        self.i_term = min(max(self.i_term, -lim), lim)
        return self.p * error + self.i_term + self.d * error_dot


class PidArray:
    """Several `Pid` loops computed together, one per joint of a trajectory controller.

    The same arithmetic as `Pid.compute` elementwise over (J,) arrays: a trajectory controller
    runs at the physics rate (the hunter's arm at 250 Hz), where a Python call per joint a step
    was ~6 % of a whole SLAM run's time."""

    def __init__(self, pids: list[Pid]) -> None:
        self.p = np.array([q.p for q in pids], dtype=float)
        self.i = np.array([q.i for q in pids], dtype=float)
        self.d = np.array([q.d for q in pids], dtype=float)
        self.lim = np.abs(np.array([q.i_clamp for q in pids], dtype=float))
        self.i_term = np.zeros(len(pids))

    def reset(self) -> None:
        self.i_term[:] = 0.0

    def compute(self, error: np.ndarray, error_dot: np.ndarray, dt: float) -> np.ndarray:
        """(J,) commands from the (J,) errors (target - actual), their rates and the period."""
        self.i_term += self.i * error * dt
        np.clip(self.i_term, -self.lim, self.lim, out=self.i_term)
        return self.p * error + self.i_term + self.d * error_dot
