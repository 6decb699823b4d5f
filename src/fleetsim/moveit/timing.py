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
    spline = ta.SplineInterpolator(s / s[-1], path) if len(path) > 2 else None
    if spline is None:  # two points: a straight line (toppra's spline needs three)
        mid = 0.5 * (path[0] + path[1])
        spline = ta.SplineInterpolator([0.0, 0.5, 1.0], np.array([path[0], mid, path[1]]))
    vmax = np.asarray(max_velocity, float) * velocity_scaling
    amax = np.asarray(max_acceleration, float) * acceleration_scaling
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
