"""Time parameterisation of a joint path within velocity and acceleration limits (toppra).

MoveIt's AddTimeParameterization step: the path's waypoints are timed so that no joint exceeds
``max_velocity * velocity_scaling`` or ``max_acceleration * acceleration_scaling``, starting
and ending at rest. toppra gives the time-optimal parameterisation of the path through the
waypoints (as TOTG does; MoveIt 1's default IPTP is slower but stays within the same limits).
"""

from __future__ import annotations

import logging

import numpy as np

from fleetsim.errors import PlanningError

SAMPLE_PERIOD = 0.1  # s between output points
#: rad of joint-space length below which a straight move is timed in closed form: toppra's
#: solver finds no profile for a path of ~5e-5 rad (a goal a hair from where the arm stands)
TINY_MOTION = 1e-3
logging.getLogger("toppra").setLevel(logging.WARNING)  # it logs every parameterisation at INFO


def time_parameterize(
    path: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    velocity_scaling: float = 1.0,
    acceleration_scaling: float = 1.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(t (K,), positions (K, J), velocities (K, J), accelerations (K, J))`` along ``path``
    (N, J), at rest at both ends."""
    import toppra as ta
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    for what, s in (("velocity", velocity_scaling), ("acceleration", acceleration_scaling)):
        if not 0 < s <= 1:
            raise PlanningError(f"max_{what}_scaling_factor must be in (0, 1], got {s}")
    path = np.asarray(path, float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(path, axis=0), axis=1) > 1e-9])
    path = path[keep]
    J = path.shape[1]
    if len(path) < 2:
        z = np.zeros((1, J))
        return np.zeros(1), path[:1].copy(), z, z.copy()
    # the path parameter is the cumulative joint-space length, so segments keep their shape
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    vmax = np.asarray(max_velocity, float) * velocity_scaling
    amax = np.asarray(max_acceleration, float) * acceleration_scaling
    if s[-1] < TINY_MOTION:
        return _tiny_motion(path, s, vmax, amax)
    spline = ta.SplineInterpolator(s / s[-1], path) if len(path) > 2 else None
    if spline is None:  # two points: a straight line (toppra's spline needs three)
        mid = 0.5 * (path[0] + path[1])
        spline = ta.SplineInterpolator([0.0, 0.5, 1.0], np.array([path[0], mid, path[1]]))
    cons = [
        constraint.JointVelocityConstraint(np.stack([-vmax, vmax], axis=1)),
        constraint.JointAccelerationConstraint(np.stack([-amax, amax], axis=1)),
    ]
    gridpoints = np.linspace(0, 1, max(50, 10 * len(path)))
    inst = algo.TOPPRA(cons, spline, gridpoints=gridpoints, parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0.0, 0.0)
    if traj is None:
        raise PlanningError("time parameterisation failed (toppra found no feasible profile)")
    T = float(traj.duration)
    n = max(2, int(np.ceil(T / SAMPLE_PERIOD)) + 1)
    t = np.linspace(0.0, T, n)
    pos, vel, acc = traj(t), traj(t, 1), traj(t, 2)
    pos[0], pos[-1] = path[0], path[-1]
    vel[0] = vel[-1] = 0.0
    return t, pos, vel, acc


def _tiny_motion(path: np.ndarray, s: np.ndarray, vmax: np.ndarray, amax: np.ndarray):
    """A move of less than `TINY_MOTION` along ``path`` (its cumulative length ``s``), timed in
    closed form: accelerate along the path for half the time and brake for the other half, the
    duration the longest any joint needs within its acceleration and peak velocity limits at
    the path's steepest segment for it."""
    S = s[-1]
    slope = np.abs(np.diff(path, axis=0)) / np.diff(s)[:, None]  # |dq/ds| per segment, joint
    reach = S * slope.max(axis=0)  # what each joint would move along the whole path's length
    T = float(np.max(np.maximum(2 * np.sqrt(reach / amax), 2 * reach / vmax)))
    n = max(3, int(np.ceil(T / SAMPLE_PERIOD)) + 1)
    t = np.linspace(0.0, T, n)
    x = t / T
    u = np.where(x <= 0.5, 2 * x**2, 1 - 2 * (1 - x) ** 2)  # share of the path's length
    du = np.where(x <= 0.5, 4 * x, 4 * (1 - x)) / T
    ddu = np.where(x < 0.5, 4.0, -4.0) / T**2
    at = u * S
    pos = np.column_stack([np.interp(at, s, path[:, j]) for j in range(path.shape[1])])
    seg = np.clip(np.searchsorted(s, at, side="right") - 1, 0, len(s) - 2)
    dq_ds = np.diff(path, axis=0)[seg] / np.diff(s)[seg][:, None]
    pos[-1] = path[-1]
    return t, pos, (du * S)[:, None] * dq_ds, (ddu * S)[:, None] * dq_ds
