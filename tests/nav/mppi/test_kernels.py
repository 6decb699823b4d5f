"""MPPI kernels: motion models against closed forms, acceleration limits, softmax, warm start."""

import math

import numpy as np
import pytest

from fleetsim.nav.controllers.mppi.kernels import (
    ACKERMANN,
    DIFF_DRIVE,
    OMNI,
    integrated_poses,
    rollouts,
    shifted_sequence,
    softmax_sequence,
)

NO_ACC = np.array([-0.35, 0.5, 0.5, 1.9, -3.0, 3.0, 3.0, 3.5, 0.0])


def roll(sequence, noise, pose, vel, limits=NO_ACC, model=DIFF_DRIVE, dt=0.05, r=0.2):
    b, t = noise.shape[:2]
    out = [np.empty((b, t, 3)) for _ in range(3)] + [np.empty((b, t, 2))]
    rollouts(
        np.asarray(sequence, float), np.asarray(noise, float), np.asarray(pose, float),
        np.asarray(vel, float), limits, model, dt, r, *out,
    )  # fmt: skip
    return out


def test_diff_drive_constant_twist_follows_the_arc():
    v, w, dt, n = 0.4, 0.8, 0.001, 2000
    seq = np.tile([v, 0.0, w], (n, 1))
    controls, vels, poses, headings = roll(
        seq, np.zeros((1, n, 3)), (1.0, 2.0, 0.3), (v, 0, w), dt=dt
    )
    t = dt * np.arange(1, n + 1)
    yaw = 0.3 + w * t
    x = 1.0 + v / w * (np.sin(yaw) - np.sin(0.3))
    y = 2.0 - v / w * (np.cos(yaw) - np.cos(0.3))
    assert np.allclose(poses[0, :, 2], yaw, atol=1e-12)
    # Euler's error over the arc: O(v * w * dt * T)
    assert np.abs(poses[0, :, 0] - x).max() < 2e-3 and np.abs(poses[0, :, 1] - y).max() < 2e-3
    assert np.allclose(headings[0, :, 0], np.cos(yaw), atol=1e-9)
    assert np.allclose(headings[0, :, 1], np.sin(yaw), atol=1e-9)
    assert np.all(vels[0, :, 1] == 0.0)


def test_straight_line_is_exact_and_omni_strafes():
    seq = np.tile([0.3, 0.2, 0.0], (10, 1))
    _, _, poses, _ = roll(
        seq, np.zeros((1, 10, 3)), (0.0, 0.0, math.pi / 2), (0.3, 0.2, 0.0), model=OMNI
    )
    k = np.arange(1, 11) * 0.05
    # heading +y: forward is +y, left (vy) is -x
    assert np.allclose(poses[0, :, 0], -0.2 * k, atol=1e-12)
    assert np.allclose(poses[0, :, 1], 0.3 * k, atol=1e-12)
    _, vels, poses, _ = roll(seq, np.zeros((1, 10, 3)), (0.0, 0.0, 0.0), (0.3, 0.2, 0.0))
    assert np.all(vels[0, :, 1] == 0.0) and np.allclose(poses[0, :, 1], 0.0)  # DiffDrive: no vy


def test_controls_are_clamped_and_ackermann_bounds_the_turn_rate():
    seq = np.tile([2.0, 0.0, 5.0], (5, 1))
    controls, _, _, _ = roll(seq, np.zeros((1, 5, 3)), (0, 0, 0), (0, 0, 0))
    assert np.allclose(controls[0], [[0.5, 0.0, 1.9]] * 5)
    seq = np.tile([0.1, 0.0, 5.0], (5, 1))
    controls, _, _, _ = roll(
        seq, np.zeros((1, 5, 3)), (0, 0, 0), (0.1, 0, 0), model=ACKERMANN, r=0.5
    )
    assert np.allclose(controls[0, :, 2], 0.1 / 0.5)


def test_acceleration_limits_shape_the_state_velocities():
    limits = NO_ACC.copy()
    limits[8] = 1.0
    seq = np.tile([0.5, 0.0, 1.9], (20, 1))
    controls, vels, _, _ = roll(seq, np.zeros((1, 20, 3)), (0, 0, 0), (0, 0, 0), limits=limits)
    assert vels[0, 0].tolist() == [0.0, 0.0, 0.0]  # the robot's own velocity first
    assert np.allclose(np.diff(vels[0, :4, 0]), 3.0 * 0.05)  # ax_max
    assert np.allclose(np.diff(vels[0, :5, 2]), 3.5 * 0.05)  # az_max
    assert vels[0, -1, 0] == pytest.approx(0.5) and vels[0, -1, 2] == pytest.approx(1.9)
    assert np.allclose(controls[0, :-1], vels[0, 1:])  # samples are what the base follows
    seq = np.tile([-0.35, 0.0, 0.0], (10, 1))
    _, vels, _, _ = roll(seq, np.zeros((1, 10, 3)), (0, 0, 0), (0.5, 0, 0), limits=limits)
    assert np.allclose(np.diff(vels[0, :4, 0]), -3.0 * 0.05)  # braking at ax_min


def test_integrated_poses_matches_rollouts():
    rng = np.random.default_rng(3)
    vel = rng.uniform(-0.3, 0.3, (30, 3))
    vel[:, 1] = 0.0
    seq = np.vstack([vel[1:], vel[-1:]])
    _, _, poses, _ = roll(seq, np.zeros((1, 30, 3)), (0.5, -0.5, 1.0), vel[0])
    assert np.allclose(integrated_poses(vel, (0.5, -0.5, 1.0), 0.05), poses[0], atol=1e-9)


def test_softmax_weights_cheap_samples_and_zero_temperature_takes_the_best():
    controls = np.zeros((3, 4, 3))
    controls[:, :, 0] = np.array([0.1, 0.2, 0.3])[:, None]
    costs = np.array([2.0, 1.0, 3.0])
    seq = np.zeros((4, 3))
    w = softmax_sequence(costs, controls, seq, np.array([0.2, 0.0, 0.4]), 0.0, 0.3)
    expected = np.exp(-(costs - 1.0) / 0.3)
    assert np.allclose(w, expected / expected.sum())
    assert np.allclose(seq[:, 0], (w * [0.1, 0.2, 0.3]).sum())
    seq = np.zeros((4, 3))
    w = softmax_sequence(costs, controls, seq, np.array([0.2, 0.0, 0.4]), 0.0, 0.0)
    assert w.tolist() == [0.0, 1.0, 0.0] and np.allclose(seq[:, 0], 0.2)
    # gamma: moving away from a non-zero sequence costs u * (v - u) / std^2
    seq = np.full((4, 3), 0.2)
    controls[:, :, 1:] = 0.2
    softmax_sequence(np.zeros(3), controls, seq, np.array([0.2, 0.0, 0.4]), 1.0, 0.0)
    assert np.allclose(seq[:, 0], 0.1)  # the sample below the sequence is cheapest


def test_warm_start_shifts_and_repeats_the_last_control():
    seq = np.arange(15, dtype=float).reshape(5, 3)
    out = shifted_sequence(seq, 2)
    assert np.array_equal(out[:3], seq[2:]) and np.array_equal(out[3:], [seq[-1], seq[-1]])
