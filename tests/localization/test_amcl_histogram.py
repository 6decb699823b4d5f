"""Tests for fleetsim.localization.amcl.histogram: pose bins, first appearances, clusters."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.localization.amcl.histogram import (
    bin_index,
    cluster_labels,
    occupied_bin_counts,
    pose_bin_keys,
)


def bins_of(poses):
    """Reference bin triples (ix, iy, iyaw) with yaw wrapped to [-pi, pi)."""
    yaw = (poses[:, 2] + np.pi) % (2 * np.pi)
    return np.stack(
        [
            np.floor(poses[:, 0] / 0.5),
            np.floor(poses[:, 1] / 0.5),
            np.minimum(np.floor(yaw / np.radians(10)), 35),
        ],
        axis=1,
    ).astype(np.int64)


def random_poses(seed, n, spread):
    rng = np.random.default_rng(seed)
    return np.column_stack(
        [rng.normal(0, spread, n), rng.normal(0, spread, n), rng.uniform(-4, 4, n)]
    )


@settings(max_examples=30, deadline=None, derandomize=True)
@given(st.integers(0, 10_000), st.integers(1, 400), st.floats(0.1, 50))
def test_bins_and_first_appearances_match_numpy_unique(seed, n, spread):
    poses = random_poses(seed, n, spread)
    keys = pose_bin_keys(poses)
    ref = bins_of(poses)
    # same key <=> same bin triple
    _, ref_inv = np.unique(ref, axis=0, return_inverse=True)
    _, key_inv = np.unique(keys, return_inverse=True)
    assert np.array_equal(ref_inv[:, None] == ref_inv[None, :], key_inv[:, None] == key_inv[None])
    ids, first, _, _ = bin_index(keys)
    assert np.array_equal(ids[:, None] == ids[None, :], key_inv[:, None] == key_inv[None])
    seen = [len({tuple(b) for b in ref[: k + 1]}) for k in range(n)]
    assert list(occupied_bin_counts(keys)) == seen
    assert first.sum() == seen[-1]


@settings(max_examples=20, deadline=None, derandomize=True)
@given(st.integers(0, 10_000), st.floats(0.3, 5))
def test_clusters_are_connected_components_of_occupied_bins(seed, spread):
    poses = random_poses(seed, 150, spread)
    labels, n = cluster_labels(poses)
    ref = bins_of(poses)
    # brute force: union adjacent occupied bins (|dx|, |dy| <= 1, cyclic |dyaw| <= 1)
    bins, inv = np.unique(ref, axis=0, return_inverse=True)
    parent = list(range(len(bins)))

    def find(a):
        while parent[a] != a:
            a = parent[a]
        return a

    for a in range(len(bins)):
        for b in range(a + 1, len(bins)):
            d = np.abs(bins[a] - bins[b])
            if d[0] <= 1 and d[1] <= 1 and min(d[2], 36 - d[2]) <= 1:
                parent[find(a)] = find(b)
    comp = np.array([find(a) for a in range(len(bins))])[inv.ravel()]
    same_ref = comp[:, None] == comp[None, :]
    same = labels[:, None] == labels[None, :]
    assert np.array_equal(same, same_ref)
    assert n == len(np.unique(labels)) and labels.max() == n - 1


def test_two_separate_blobs_are_two_clusters_and_yaw_wraps():
    rng = np.random.default_rng(0)
    a = np.column_stack([rng.normal(0, 0.1, 100), rng.normal(0, 0.1, 100), np.full(100, 3.1)])
    b = np.column_stack([rng.normal(5, 0.1, 50), rng.normal(5, 0.1, 50), np.zeros(50)])
    a[::2, 2] = -3.1  # across the +-pi seam: same cluster
    labels, n = cluster_labels(np.vstack([a, b]))
    assert n == 2
    assert len(set(labels[:100])) == 1 and len(set(labels[100:])) == 1
