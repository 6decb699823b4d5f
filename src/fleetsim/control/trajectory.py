"""Joint trajectories as joint_trajectory_controller samples them: per-segment splines.

Between two waypoints a joint follows a line when only positions are given, a cubic Hermite
spline when velocities are given too, and a quintic when accelerations are given as well
(``QuinticSplineSegment``). Before its start a trajectory is at its first state; after its end
it holds the last position at rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Trajectory:
    """Waypoints at absolute sim times.

    Attributes
    ----------
    times : (K,) s, strictly increasing.
    positions, velocities, accelerations : (K, J) rad, rad/s, rad/s^2 (zeros where not given).
    order : 1 linear, 3 cubic, 5 quintic.
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    order: int = 1

    @property
    def end_time(self) -> float:
        return float(self.times[-1])

    @classmethod
    def hold(cls, t: float, positions: np.ndarray) -> Trajectory:
        """Stay at ``positions`` (J,) from time ``t`` on."""
        p = np.asarray(positions, np.float64)[None, :]
        z = np.zeros_like(p)
        return cls(np.array([t]), p, z, z.copy(), 1)


def _coefficients(order, T, p0, v0, a0, p1, v1, a1):
    """(6, J) polynomial coefficients a0..a5 of one segment of duration T > 0."""
    c = np.zeros((6, p0.size))
    c[0] = p0
    if order == 1:
        c[1] = (p1 - p0) / T
    elif order == 3:
        c[1] = v0
        c[2] = (3 * (p1 - p0) - (2 * v0 + v1) * T) / T**2
        c[3] = (2 * (p0 - p1) + (v0 + v1) * T) / T**3
    else:
        c[1] = v0
        c[2] = a0 / 2
        c[3] = (20 * (p1 - p0) - (8 * v1 + 12 * v0) * T - (3 * a0 - a1) * T**2) / (2 * T**3)
        c[4] = (30 * (p0 - p1) + (14 * v1 + 16 * v0) * T + (3 * a0 - 2 * a1) * T**2) / (2 * T**4)
        c[5] = (12 * (p1 - p0) - 6 * (v1 + v0) * T - (a0 - a1) * T**2) / (2 * T**5)
    return c


def sample(traj: Trajectory, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Desired ``(position, velocity, acceleration)``, each (J,), at sim time ``t`` (s)."""
    times = traj.times
    if t <= times[0]:
        return traj.positions[0].copy(), traj.velocities[0].copy(), traj.accelerations[0].copy()
    if t >= times[-1]:
        z = np.zeros(traj.positions.shape[1])
        return traj.positions[-1].copy(), z, z.copy()
    k = int(np.searchsorted(times, t, side="right")) - 1
    T = times[k + 1] - times[k]
    c = _coefficients(
        traj.order,
        T,
        traj.positions[k],
        traj.velocities[k],
        traj.accelerations[k],
        traj.positions[k + 1],
        traj.velocities[k + 1],
        traj.accelerations[k + 1],
    )
    s = t - times[k]
    powers = s ** np.arange(6)
    pos = powers @ c
    vel = (np.arange(1, 6) * powers[:5]) @ c[1:]
    acc = (np.arange(2, 6) * np.arange(1, 5) * powers[:4]) @ c[2:]
    return pos, vel, acc
