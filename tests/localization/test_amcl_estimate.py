"""Tests for fleetsim.localization.amcl.estimate: cluster statistics and the pose estimate."""

import numpy as np
import pytest

from fleetsim.localization.amcl.estimate import (
    cluster_statistics,
    covariance_3x3,
    covariance_6x6,
    pose_estimate,
)


def test_cluster_statistics_match_direct_computation():
    rng = np.random.default_rng(0)
    poses = np.column_stack(
        [rng.normal(0, 1, 300), rng.normal(0, 2, 300), rng.normal(0.2, 0.1, 300)]
    )
    labels = rng.integers(0, 3, 300)
    w = rng.random(300)
    w /= w.sum()
    cw, means, covs = cluster_statistics(poses, w, labels, 3)
    for c in range(3):
        sel = labels == c
        ww = w[sel] / w[sel].sum()
        assert cw[c] == pytest.approx(w[sel].sum())
        np.testing.assert_allclose(means[c, :2], ww @ poses[sel, :2])
        d = poses[sel, :2] - means[c, :2]
        np.testing.assert_allclose(covs[c, :2, :2], (d * ww[:, None]).T @ d, atol=1e-12)
        r = np.hypot(ww @ np.cos(poses[sel, 2]), ww @ np.sin(poses[sel, 2]))
        assert covs[c, 2, 2] == pytest.approx(-2 * np.log(r))


def test_circular_mean_across_the_seam():
    poses = np.array([[0, 0, np.pi - 0.1], [0, 0, -np.pi + 0.1]])
    _, means, _ = cluster_statistics(poses, np.array([0.5, 0.5]), np.array([0, 0]), 1)
    assert abs(abs(means[0, 2]) - np.pi) < 1e-9


def test_estimate_is_the_heaviest_cluster():
    rng = np.random.default_rng(1)
    a = np.column_stack([rng.normal(2, 0.05, 100), rng.normal(2, 0.05, 100), np.full(100, 0.5)])
    b = np.column_stack([rng.normal(8, 0.05, 300), rng.normal(1, 0.05, 300), np.full(300, -1.0)])
    w = np.concatenate([np.full(100, 0.006), np.full(300, 0.4 / 300)])
    est = pose_estimate(np.vstack([a, b]), w / w.sum())
    assert est.cluster_count == 2
    np.testing.assert_allclose(est.pose, [2, 2, 0.5], atol=0.02)
    assert est.weight == pytest.approx(0.6)
    assert est.covariance.shape == (6, 6) and est.covariance[0, 0] == pytest.approx(0.0025, rel=0.3)


def test_covariance_layout():
    c3 = np.array([[1.0, 0.2, 0.0], [0.2, 2.0, 0.0], [0.0, 0.0, 3.0]])
    c6 = covariance_6x6(c3)
    assert c6[0, 0] == 1 and c6[0, 1] == 0.2 and c6[1, 1] == 2 and c6[5, 5] == 3
    assert c6[2, 2] == 0 and c6[3, 3] == 0
    np.testing.assert_array_equal(covariance_3x3(c6.ravel()), c3)
