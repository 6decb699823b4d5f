"""Tests for fleetsim.localization.amcl.laser: scan conditioning and the three laser models."""

import numpy as np
import pytest
from amcl_world import exact_ranges, world_map
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.localization.amcl.laser import (
    beam_model_weights,
    endpoint_likelihoods,
    endpoint_table_sums,
    laser_likelihoods,
    likelihood_field_prob_log_weights,
    likelihood_field_table,
    ranges_from_map,
)
from fleetsim.localization.amcl.params import AmclParams
from fleetsim.localization.amcl.scan import ScanBeams, beams_from_scan

GRID = world_map()
TRUE = np.array([5.0, 5.0, 0.3])


def brute_force_sums(particles, laser_pose, ranges, bearings, table, off):
    """Reference for endpoint_table_sums: plain NumPy, composing poses explicitly."""
    out = []
    for x, y, a in particles:
        sx = x + laser_pose[0] * np.cos(a) - laser_pose[1] * np.sin(a)
        sy = y + laser_pose[0] * np.sin(a) + laser_pose[1] * np.cos(a)
        ang = a + laser_pose[2] + bearings
        i, j = GRID.cells_from_points(
            np.stack([sx + ranges * np.cos(ang), sy + ranges * np.sin(ang)], axis=1)
        )
        ok = (i >= 0) & (j >= 0) & (i < GRID.width) & (j < GRID.height)
        vals = np.full(len(ranges), off)
        vals[ok] = table[j[ok], i[ok]]
        out.append(vals.sum())
    return np.array(out)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(st.integers(0, 10_000))
def test_table_sums_match_brute_force(seed):
    rng = np.random.default_rng(seed)
    parts = np.column_stack(
        [rng.uniform(-2, 18, 50), rng.uniform(-2, 12, 50), rng.uniform(-np.pi, np.pi, 50)]
    )
    laser_pose = np.array([0.2, -0.1, 0.4])
    ranges = rng.uniform(0.1, 8.0, 40)
    bearings = rng.uniform(-np.pi, np.pi, 40)
    table, off = likelihood_field_table(GRID, 2.0, 0.95, 0.05, 0.2, 10.0)
    got = endpoint_table_sums(
        parts, laser_pose, ranges, bearings, table, off, GRID.origin_x, GRID.origin_y, 0.05
    )
    np.testing.assert_allclose(
        got, brute_force_sums(parts, laser_pose, ranges, bearings, table, off)
    )
    pz, _ = endpoint_likelihoods(
        parts, laser_pose, ranges, bearings, table, off, GRID.distance_field(2.0), 0.5, 0, 0, 0.05
    )
    np.testing.assert_allclose(pz.sum(axis=1), got)


def test_ray_casting_matches_exact_ranges():
    rng = np.random.default_rng(5)
    angles = rng.uniform(-np.pi, np.pi, 200)
    exact = exact_ranges(TRUE, angles, 20.0)
    cast = np.array(
        [
            ranges_from_map(GRID.occ_state, 0.0, 0.0, 0.05, TRUE[0], TRUE[1], TRUE[2] + a, 20.0)
            for a in angles
        ]
    )
    # Bresenham on 0.05 m cells measures cell-to-cell distance: within two cell diagonals,
    # except rays that graze a box corner (a diagonal step can slip between two cells)
    close = np.abs(cast - exact) < 2 * 0.05 * np.sqrt(2)
    assert close.mean() >= 0.97
    assert ranges_from_map(GRID.occ_state, 0.0, 0.0, 0.05, 5.0, 5.0, 0.0, 1.0) == 1.0
    assert ranges_from_map(GRID.occ_state, 0.0, 0.0, 0.05, 0.1, 5.0, 0.0, 5.0) == 0.0  # in wall


def scan_beams(pose, n=90, model="likelihood_field"):
    inc = 2 * np.pi / n
    r = exact_ranges(pose, -np.pi + inc * np.arange(n), 10.0)
    return beams_from_scan(r, -np.pi, inc, 0.05, 10.0, n, model)


@pytest.mark.parametrize("model", ["likelihood_field", "likelihood_field_prob", "beam"])
def test_true_pose_scores_best(model):
    params = AmclParams(laser_model_type=model, laser_max_beams=90)
    beams = scan_beams(TRUE, model=model)
    offsets = np.array([[0, 0, 0], [0.3, 0, 0], [0, -0.3, 0], [0, 0, 0.15], [1.0, 1.0, 1.0]])
    vals, is_log = laser_likelihoods(TRUE + offsets, beams, np.zeros(3), GRID, params, False)
    assert is_log == (model == "likelihood_field_prob")
    assert np.argmax(vals) == 0 and np.all(vals[1:] < vals[0])


def test_laser_pose_is_applied():
    laser_pose = np.array([0.3, 0.1, np.pi / 2])
    c, s = np.cos(TRUE[2]), np.sin(TRUE[2])
    sensor = TRUE + np.array([0.3 * c - 0.1 * s, 0.3 * s + 0.1 * c, np.pi / 2])
    beams = scan_beams(sensor)
    params = AmclParams(laser_max_beams=90)
    with_pose, _ = laser_likelihoods(TRUE[None], beams, laser_pose, GRID, params, False)
    without, _ = laser_likelihoods(TRUE[None], beams, np.zeros(3), GRID, params, False)
    assert with_pose[0] > without[0]


def test_beam_model_scores_max_range_with_z_max():
    pose = np.array([[5.0, 5.0, 0.0]])
    args = (GRID.occ_state, 0.0, 0.0, 0.05, 0.95, 0.1, 0.05, 0.05, 0.2, 0.1)
    far = beam_model_weights(pose, np.zeros(3), np.array([3.0]), np.zeros(1), *args, 3.0)
    # expected range 3 (max), measured 3 (max): z_hit (z = 0) + z_max, no z_rand
    assert far[0] == pytest.approx(1.0 + (0.95 + 0.05) ** 3)


def test_beam_skipping_leaves_out_unmapped_obstacles():
    beams = scan_beams(TRUE, n=60, model="likelihood_field_prob")
    r = beams.ranges.copy()
    r[:10] = 0.7  # a person in front of ten beams
    blocked = ScanBeams(r, beams.bearings, beams.range_max)
    rng = np.random.default_rng(0)
    parts = TRUE + rng.normal(0, [0.05, 0.05, 0.02], (200, 3))
    table, off = likelihood_field_table(GRID, 2.0, 0.95, 0.05, 0.2, 10.0)
    pz, near = endpoint_likelihoods(
        parts,
        np.zeros(3),
        r,
        blocked.bearings,
        table,
        off,
        GRID.distance_field(2.0),
        0.5,
        0,
        0,
        0.05,
    )
    logw, mask = likelihood_field_prob_log_weights(pz, near, True, 0.3, 0.9)
    assert not mask[:10].any() and mask[10:].all()
    np.testing.assert_allclose(logw, np.log(pz[:, 10:]).sum(axis=1))
    # too many disagreeing beams: the filter probably converged wrongly, integrate all beams
    _, mask_all = likelihood_field_prob_log_weights(pz, near, True, 0.3, 0.1)
    assert mask_all.all()
    # via the model entry point: beam skipping only once converged
    p = AmclParams(laser_model_type="likelihood_field_prob", do_beamskip=True, laser_max_beams=60)
    skip, _ = laser_likelihoods(parts, blocked, np.zeros(3), GRID, p, True)
    np.testing.assert_allclose(skip, logw)
    noskip, _ = laser_likelihoods(parts, blocked, np.zeros(3), GRID, p, False)
    np.testing.assert_allclose(noskip, np.log(pz).sum(axis=1))
