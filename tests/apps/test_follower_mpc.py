"""The predictive follower's rollout kernel on small hand-made scenes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fleetsim.apps.follower_mpc import costs_without_target, rollout_costs, velocity_samples
from fleetsim.apps.target_tracker import ctrv_step
from fleetsim.nav.costmap.footprint import outline_points

RES = 0.05
ORIGIN = (-2.5, -2.5)
FOOTPRINT = np.array([[-0.205, -0.155], [-0.205, 0.155], [0.077, 0.155], [0.077, -0.155]])
OUTLINE = outline_points(FOOTPRINT, RES)
SAMPLES = velocity_samples(-0.1, 0.26, 1.82, 8, 21)
DT, STEPS = 0.1, 30
#: half fov, margin, range, min range, follow distance, min gap, face angle
GEOMETRY = np.array([1.3439 / 2, 0.6, 3.75, 0.4, 0.8, 0.45, 1.0])
WEIGHTS = np.array([20.0, 30.0, 4.0, 1.0, 0.5, 2.0, 0.3])


def free_map() -> np.ndarray:
    return np.zeros((100, 100), dtype=np.uint8)


def target_track(x, y, heading, v, w) -> np.ndarray:
    s = np.array([x, y, heading, v, w], float)
    out = []
    for _ in range(STEPS):
        s = ctrv_step(s, DT)
        out.append(s[:3])
    return np.array(out)


def best(costs_map, targets, pose=(0.0, 0.0, 0.0), velocity=(0.0, 0.0), previous=(0.0, 0.0)):
    costs, poses = rollout_costs(
        costs_map,
        *ORIGIN,
        RES,
        OUTLINE,
        np.array(pose, float),
        np.array(velocity, float),
        SAMPLES,
        np.array([2.5, 3.2]),
        DT,
        targets,
        np.full(len(targets), 0.05),
        0.07,
        GEOMETRY,
        WEIGHTS,
        np.array(previous, float),
    )
    return costs, poses, SAMPLES[int(np.argmin(costs))]


def test_it_follows_a_target_driving_away():
    targets = target_track(1.2, 0.0, 0.0, 0.2, 0.0)
    _, _, (v, w) = best(free_map(), targets)
    assert v > 0.15 and abs(w) < 0.2


def test_it_turns_toward_a_target_at_the_edge_of_the_view():
    bearing = 0.55  # rad, beyond the free cone (0.6 x 0.67 rad)
    targets = target_track(1.3 * math.cos(bearing), 1.3 * math.sin(bearing), 1.0, 0.1, 0.0)
    _, _, (_, w) = best(free_map(), targets)
    assert w > 0.3


def test_it_backs_off_a_target_coming_at_it():
    targets = target_track(0.9, 0.0, math.pi, 0.15, 0.0)
    costs, _, (v, _) = best(free_map(), targets)
    assert v < 0
    forward = np.flatnonzero((SAMPLES[:, 0] > 0.2) & (SAMPLES[:, 1] == 0.0))
    assert np.isinf(costs[forward]).all()  # it would come within min_gap of the target


def test_samples_into_a_wall_are_infeasible():
    grid = free_map()
    x_wall = int((0.5 - ORIGIN[0]) / RES)
    grid[:, x_wall : x_wall + 2] = 254  # a wall 0.5 m ahead, across the map
    targets = target_track(1.5, 0.0, 0.0, 0.0, 0.0)  # behind the wall: seen, unreachable
    costs, poses, _ = best(grid, targets)
    fast = np.flatnonzero((SAMPLES[:, 0] > 0.2) & (np.abs(SAMPLES[:, 1]) < 0.2))
    assert np.isinf(costs[fast]).all()
    ok = np.isfinite(costs)
    assert ok.any() and (poses[ok][:, :, 0] < 0.5 - 0.077).all()


def test_out_of_view_costs_more_than_in_view():
    targets = target_track(1.5, 0.0, 0.0, 0.0, 0.0)
    costs, _, _ = best(free_map(), targets, velocity=(0.0, 0.0))
    still = np.flatnonzero((SAMPLES[:, 0] == 0.0) & (SAMPLES[:, 1] == 0.0))[0]
    spin = np.flatnonzero((SAMPLES[:, 0] == 0.0) & (SAMPLES[:, 1] == SAMPLES[:, 1].max()))[0]
    assert costs[spin] > costs[still] + 10  # turning away loses the marker for seconds


def test_velocity_samples_hold_zero_and_the_limits():
    s = velocity_samples(-0.1, 0.26, 1.82, 8, 20)
    assert {0.0, -0.1, 0.26} <= set(s[:, 0]) and {0.0, -1.82, 1.82} <= set(s[:, 1])
    assert s.flags.c_contiguous and s.dtype == np.float64
    assert len(s) == pytest.approx(len(np.unique(s, axis=0)))


def test_the_targets_own_marks_are_freed_and_walls_kept():
    grid = free_map()
    grid[50, 40:44] = 254  # the target's mark at (-0.5..-0.3, 0.0)
    grid[50, 80] = 254  # a wall cell 1.5 m away
    grid[51, 40] = 253  # inflation stays
    out = costs_without_target(grid, *ORIGIN, RES, np.array([[-0.4, 0.0]]), 0.2)
    assert (out[50, 40:44] == 0).all() and out[50, 80] == 254 and out[51, 40] == 253
    assert grid[50, 40] == 254  # a copy


def test_node_parameters_are_checked_and_named():
    from fleetsim.apps.predictive_follower import PredictiveFollower
    from fleetsim.errors import ParameterError
    from fleetsim.runtime import Runtime

    with pytest.raises(ParameterError, match=r"/predictive_follower: parameter 'horizon'"):
        PredictiveFollower(Runtime(seed=0), params={"horizon": 0.0})
    with pytest.raises(ParameterError, match=r"/predictive_follower/tracker: .*'accel_noise'"):
        PredictiveFollower(Runtime(seed=0), params={"tracker": {"accel_noise": -1.0}})
    with pytest.raises(ParameterError, match=r"exploration: parameter 'strategy'.*'spin'"):
        PredictiveFollower(Runtime(seed=0), params={"exploration": {"strategy": "spin"}})
