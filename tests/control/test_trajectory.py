"""Trajectory sampling: lines, cubic and quintic segments meet their waypoints, and hold."""

import numpy as np
import pytest

from fleetsim.control.trajectory import Trajectory, sample


def _traj(order):
    t = np.array([1.0, 2.0, 4.0])
    p = np.array([[0.0, 1.0], [1.0, 0.0], [2.0, -1.0]])
    v = np.array([[0.0, 0.0], [0.5, -0.5], [0.0, 0.0]]) if order > 1 else np.zeros((3, 2))
    a = np.array([[0.0, 0.0], [0.1, 0.2], [0.0, 0.0]]) if order > 3 else np.zeros((3, 2))
    return Trajectory(t, p, v, a, order)


@pytest.mark.parametrize("order", [1, 3, 5])
def test_waypoints_are_met_with_their_velocities(order):
    tr = _traj(order)
    for k, t in enumerate(tr.times):
        pos, vel, acc = sample(tr, t)
        np.testing.assert_allclose(pos, tr.positions[k], atol=1e-12)
        if order > 1 and 0 < k < 2:
            np.testing.assert_allclose(vel, tr.velocities[k], atol=1e-9)
        if order > 3 and 0 < k < 2:
            np.testing.assert_allclose(acc, tr.accelerations[k], atol=1e-9)


@pytest.mark.parametrize("order", [3, 5])
def test_velocity_is_the_derivative_of_position(order):
    tr = _traj(order)
    h = 1e-6
    for t in np.linspace(1.01, 3.99, 17):
        pos_a, vel, _ = sample(tr, t - h)
        pos_b, _, _ = sample(tr, t + h)
        np.testing.assert_allclose((pos_b - pos_a) / (2 * h), sample(tr, t)[1], atol=1e-5)


def test_line_between_positions_only_points():
    tr = _traj(1)
    pos, vel, _ = sample(tr, 1.5)
    np.testing.assert_allclose(pos, [0.5, 0.5])
    np.testing.assert_allclose(vel, [1.0, -1.0])


def test_before_start_and_after_end():
    tr = _traj(3)
    np.testing.assert_allclose(sample(tr, 0.0)[0], tr.positions[0])
    pos, vel, acc = sample(tr, 10.0)
    np.testing.assert_allclose(pos, tr.positions[-1])
    assert not vel.any() and not acc.any()
    hold = Trajectory.hold(3.0, np.array([0.2, 0.3]))
    np.testing.assert_allclose(sample(hold, 5.0)[0], [0.2, 0.3])
