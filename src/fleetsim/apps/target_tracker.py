"""A moving target's state from intermittent pose fixes: an extended Kalman filter, constant turn
rate and velocity (CTRV), with predictions over the next seconds and their uncertainty.

State ``[x, y, heading, speed, yaw_rate]`` (m, m, rad, m/s, rad/s) in one fixed frame (``map``);
fixes ``[x, y, heading]`` from the marker detections. The motion model is the CTRV model of
Schubert et al. ("Comparison and evaluation of advanced motion models for vehicle tracking",
2008): the target drives an arc at constant speed and turn rate, disturbed by white
longitudinal and yaw accelerations (``accel_noise``, ``yaw_accel_noise``). Fixes whose
position is implausible (Mahalanobis distance beyond the chi-square gate) are dropped (three in
a row restart the filter from the newest), and a
heading that disagrees with the filter by more than ``heading_gate`` is left out of that update
(a planar marker's pose from solvePnP flips between two mirror solutions far away).

Own code rather than a filter library: the Jacobians are CTRV's (none of the maintained
libraries ships that model), the filter is five lines of linear algebra around them, and
`predicted_states` propagates mean and covariance over a horizon in the same loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fleetsim.errors import ParameterError
from fleetsim.runtime.params import param

#: chi-square 99 % quantile for 2 degrees of freedom: the position gate
POSITION_GATE = 9.21
#: this many fixes gated out in a row restart the filter at the newest (the target was lost
#: long enough for the prediction to go wrong, or the filter diverged)
REINIT_AFTER = 3
#: below this turn rate (rad/s) the CTRV step is taken as a straight line
SMALL_YAW_RATE = 1e-4


@dataclass(frozen=True)
class TrackerParams:
    """The filter's noise model and gates (``~tracker`` of the predictive follower)."""

    accel_noise: float = param(
        0.1, unit="m/s^2", range=(1e-6, None), help="std of the target's longitudinal accel"
    )
    yaw_accel_noise: float = param(
        0.3, unit="rad/s^2", range=(1e-6, None), help="std of the target's yaw acceleration"
    )
    position_noise: float = param(
        0.03, unit="m", range=(1e-6, None), help="std of a fix's position at 1 m range"
    )
    heading_noise: float = param(
        0.15, unit="rad", range=(1e-6, None), help="std of a fix's heading"
    )
    heading_gate: float = param(
        0.8, unit="rad", range=(0.0, math.pi), help="a fix's heading further off is not used"
    )
    max_speed: float = param(
        0.5, unit="m/s", range=(0.0, None), help="the target's speed is clipped to +-this"
    )
    max_yaw_rate: float = param(
        2.0, unit="rad/s", range=(0.0, None), help="its turn rate is clipped to +-this"
    )


def wrap(a):
    """Angles wrapped to [-pi, pi)."""
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


def ctrv_step(state: np.ndarray, dt: float) -> np.ndarray:
    """The CTRV motion of ``state`` (..., 5) over ``dt`` seconds (no noise)."""
    state = np.asarray(state, dtype=float)
    if state.ndim == 1 and math.isfinite(state[2]) and math.isfinite(state[4]):
        return _ctrv_step_one(state, dt)  # (the math module raises on an infinite angle)
    x, y, th, v, w = np.moveaxis(state, -1, 0)
    small = np.abs(w) < SMALL_YAW_RATE
    ws = np.where(small, 1.0, w)
    th2 = th + w * dt
    x2 = np.where(small, x + v * dt * np.cos(th), x + v / ws * (np.sin(th2) - np.sin(th)))
    y2 = np.where(small, y + v * dt * np.sin(th), y + v / ws * (np.cos(th) - np.cos(th2)))
    return np.stack([x2, y2, wrap(th2), v, w], axis=-1)


def _ctrv_step_one(state: np.ndarray, dt: float) -> np.ndarray:
    """`ctrv_step` of one (5,) state in scalar arithmetic: the same operations in the same order
    (numpy's and the math module's sin and cos agree to the bit here, which the tests check),
    ~13x faster than the array path for the predictive follower's per-cycle horizon."""
    x, y, th, v, w = state.tolist()
    th2 = th + w * dt
    if abs(w) < SMALL_YAW_RATE:
        x2 = x + v * dt * math.cos(th)
        y2 = y + v * dt * math.sin(th)
    else:
        x2 = x + v / w * (math.sin(th2) - math.sin(th))
        y2 = y + v / w * (math.cos(th) - math.cos(th2))
    return np.array([x2, y2, (th2 + math.pi) % (2 * math.pi) - math.pi, v, w])


#: central-difference steps of `ctrv_jacobian`, per state component
_JACOBIAN_STEPS = np.array([1e-5, 1e-5, 1e-6, 1e-5, 1e-5])


def ctrv_jacobian(state: np.ndarray, dt: float) -> np.ndarray:
    """d ctrv_step / d state at ``state`` (5,), by central differences (5, 5): the ten
    perturbed states stepped in one batch."""
    shifts = np.diag(_JACOBIAN_STEPS)
    state = np.asarray(state, dtype=float)
    moved = ctrv_step(np.concatenate([state + shifts, state - shifts]), dt)
    diff = moved[:5] - moved[5:]
    diff[:, 2] = wrap(diff[:, 2])
    # C order, as the column-by-column Jacobian was: the covariance products then take the
    # same BLAS path
    return np.ascontiguousarray(diff.T / (2 * _JACOBIAN_STEPS))


def ctrv_process_noise(state: np.ndarray, dt: float, p: TrackerParams) -> np.ndarray:
    """Q over ``dt`` (5, 5): white longitudinal and yaw accelerations mapped into the state."""
    th = state[2]
    g = np.array(
        [
            [0.5 * dt * dt * math.cos(th), 0.0],
            [0.5 * dt * dt * math.sin(th), 0.0],
            [0.0, 0.5 * dt * dt],
            [dt, 0.0],
            [0.0, dt],
        ]
    )
    return g @ np.diag([p.accel_noise**2, p.yaw_accel_noise**2]) @ g.T


class TargetTracker:
    """The filter; state: ``x`` (5,), ``cov`` (5, 5), ``stamp`` (s) of ``x``, the last fix."""

    def __init__(self, params: TrackerParams | None = None) -> None:
        self.params = params or TrackerParams()
        self.reset()

    def reset(self) -> None:
        self.x: np.ndarray | None = None
        self.cov = np.eye(5)
        self.stamp = math.nan
        self.last_fix: tuple[float, np.ndarray] | None = None  # stamp, (x, y, heading)
        self.fixes = 0
        self.rejected = 0
        self.rejected_in_row = 0

    @property
    def initialized(self) -> bool:
        return self.x is not None

    def _clip(self) -> None:
        p = self.params
        self.x[2] = float(wrap(self.x[2]))
        self.x[3] = float(np.clip(self.x[3], -p.max_speed, p.max_speed))
        self.x[4] = float(np.clip(self.x[4], -p.max_yaw_rate, p.max_yaw_rate))

    def predict(self, stamp: float) -> None:
        """Move the estimate forward to ``stamp`` (s); earlier stamps are ignored."""
        if self.x is None or stamp <= self.stamp:
            return
        dt = stamp - self.stamp
        while dt > 1e-9:  # steps of at most 0.1 s keep the linearisation close
            h = min(dt, 0.1)
            f = ctrv_jacobian(self.x, h)
            q = ctrv_process_noise(self.x, h, self.params)
            self.x = ctrv_step(self.x, h)
            self.cov = f @ self.cov @ f.T + q
            self._clip()
            dt -= h
        self.stamp = stamp

    def update(self, stamp: float, fix: np.ndarray, distance: float = 1.0) -> bool:
        """Fold in a fix (x, y, heading) taken at ``stamp`` from ``distance`` m away; False
        when the fix was gated out as implausible."""
        fix = np.asarray(fix, dtype=float)
        if fix.shape != (3,) or not np.all(np.isfinite(fix)):
            raise ParameterError(f"a target fix must be 3 finite numbers (x, y, heading): {fix}")
        p = self.params
        sp = p.position_noise * max(distance, 0.3) ** 2  # PnP's error grows with range squared
        if self.x is None or stamp < self.stamp - 1.0 or self.rejected_in_row >= REINIT_AFTER:
            self.x = np.array([fix[0], fix[1], fix[2], 0.0, 0.0])
            self.cov = np.diag([sp**2, sp**2, p.heading_noise**2, 0.1**2, 0.3**2])
            self.stamp = stamp
            self.last_fix = (stamp, fix.copy())
            self.fixes += 1
            self.rejected_in_row = 0
            return True
        self.predict(stamp)  # a fix older than the estimate is folded in at the estimate's time
        innov = fix - self.x[:3]
        innov[2] = float(wrap(innov[2]))
        rows = [0, 1] if abs(innov[2]) > p.heading_gate else [0, 1, 2]
        h = np.eye(5)[rows]
        r = np.diag([sp**2, sp**2, p.heading_noise**2][: len(rows)])
        s = h @ self.cov @ h.T + r
        pos_s = s[:2, :2]
        if float(innov[:2] @ np.linalg.solve(pos_s, innov[:2])) > POSITION_GATE:
            self.rejected += 1
            self.rejected_in_row += 1
            return False
        self.rejected_in_row = 0
        k = self.cov @ h.T @ np.linalg.inv(s)
        self.x = self.x + k @ innov[rows]
        self.cov = (np.eye(5) - k @ h) @ self.cov
        self.cov = 0.5 * (self.cov + self.cov.T)
        self._clip()
        self.last_fix = (stamp, fix.copy())
        self.fixes += 1
        return True

    def predicted_states(self, start: float, dt: float, steps: int) -> tuple:
        """The target's mean states and position covariances at ``start + k dt``, k = 1..steps:
        ((steps, 5), (steps, 2, 2)). The estimate itself is not changed."""
        if self.x is None:
            raise ParameterError("the target tracker has no estimate yet (no fix so far)")
        x, cov = self.x.copy(), self.cov.copy()
        lead = start - self.stamp
        while lead > 1e-9:
            h = min(lead, 0.1)
            f = ctrv_jacobian(x, h)
            cov = f @ cov @ f.T + ctrv_process_noise(x, h, self.params)
            x = ctrv_step(x, h)
            lead -= h
        means = np.empty((steps, 5))
        covs = np.empty((steps, 2, 2))
        for k in range(steps):
            f = ctrv_jacobian(x, dt)
            cov = f @ cov @ f.T + ctrv_process_noise(x, dt, self.params)
            x = ctrv_step(x, dt)
            means[k], covs[k] = x, cov[:2, :2]
        return means, covs
