"""Pose histogram of amcl's ``pf_kdtree``: 0.5 m x 0.5 m x 10 deg bins, in O(N).

amcl keeps its histogram in a kd-tree; here bins are packed into int64 keys and held in an
open-addressing hash table (numba), which gives the same three services in linear time:
the number of occupied bins while samples are drawn (KLD-sampling), and the clusters of
neighbouring occupied bins (26-neighbourhood in x, y, yaw; yaw bins wrap around, which amcl's
unwrapped yaw does not).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

BIN_XY = 0.5  # m, pf_kdtree cell size in x and y
BIN_YAW = math.radians(10.0)  # rad, pf_kdtree cell size in yaw
YAW_BINS = 36
_OFFSET = 1 << 23  # x/y bin indices in [-2^23, 2^23): +-4000 km at 0.5 m
_EMPTY = -1
_GOLDEN = 0x9E3779B97F4A7C15 - (1 << 64)  # 2^64 / golden ratio, as signed int64


@njit(cache=True)
def _key(ix, iy, it):
    return ((ix + _OFFSET) << 30) | ((iy + _OFFSET) << 6) | it


@njit(cache=True)
def pose_bin_keys(poses):
    """(N,) int64 histogram-bin key of each pose ``(x, y, yaw)`` in ``poses`` (N, 3)."""
    n = poses.shape[0]
    out = np.empty(n, dtype=np.int64)
    for k in range(n):
        ix = math.floor(poses[k, 0] / BIN_XY)
        iy = math.floor(poses[k, 1] / BIN_XY)
        a = (poses[k, 2] + math.pi) % (2.0 * math.pi)
        it = math.floor(a / BIN_YAW)
        if it >= YAW_BINS:
            it = YAW_BINS - 1
        out[k] = _key(ix, iy, it)
    return out


@njit(cache=True)
def _slot(tkeys, key):
    mask = tkeys.shape[0] - 1
    s = ((key * _GOLDEN) >> 32) & mask  # int64 multiply wraps in numba (Fibonacci hashing)
    while tkeys[s] != _EMPTY and tkeys[s] != key:
        s = (s + 1) & mask
    return s


@njit(cache=True)
def bin_index(keys):
    """Assign each key a dense bin id in order of first appearance.

    Parameters
    ----------
    keys : (N,) int64
        Bin keys (`pose_bin_keys`).

    Returns
    -------
    ids : (N,) int64
        Bin id of each key, 0 .. n_bins-1.
    first : (N,) bool
        True where the key appears for the first time.
    tkeys, tvals : (T,) int64
        The hash table (key -> bin id), for neighbour look-ups.
    """
    n = keys.shape[0]
    size = 16
    while size < 2 * n:
        size *= 2
    tkeys = np.full(size, _EMPTY, dtype=np.int64)
    tvals = np.full(size, -1, dtype=np.int64)
    ids = np.empty(n, dtype=np.int64)
    first = np.zeros(n, dtype=np.bool_)
    count = 0
    for k in range(n):
        s = _slot(tkeys, keys[k])
        if tkeys[s] == _EMPTY:
            tkeys[s] = keys[k]
            tvals[s] = count
            first[k] = True
            count += 1
        ids[k] = tvals[s]
    return ids, first, tkeys, tvals


@njit(cache=True)
def occupied_bin_counts(keys):
    """(N,) int64 number of distinct bins among ``keys[:n+1]`` for every prefix ``n``."""
    _, first, _, _ = bin_index(keys)
    return np.cumsum(first.astype(np.int64))


@njit(cache=True)
def cluster_labels(poses):
    """Cluster poses by connected occupied histogram bins (amcl's ``pf_kdtree_cluster``).

    Parameters
    ----------
    poses : (N, 3) float64
        ``(x, y, yaw)``, m and rad.

    Returns
    -------
    labels : (N,) int64
        Cluster of each pose, 0 .. n_clusters-1 (numbered in order of first appearance).
    n_clusters : int
    """
    keys = pose_bin_keys(poses)
    ids, first, tkeys, tvals = bin_index(keys)
    n_bins = 0
    for k in range(first.shape[0]):
        if first[k]:
            n_bins += 1
    bin_keys = np.empty(n_bins, dtype=np.int64)
    for k in range(first.shape[0]):
        if first[k]:
            bin_keys[ids[k]] = keys[k]
    bin_label = np.full(n_bins, -1, dtype=np.int64)
    stack = np.empty(n_bins, dtype=np.int64)
    n_clusters = 0
    for b in range(n_bins):
        if bin_label[b] >= 0:
            continue
        bin_label[b] = n_clusters
        top = 0
        stack[top] = b
        top += 1
        while top > 0:
            top -= 1
            cur = stack[top]
            key = bin_keys[cur]
            it = key & 63
            iy = ((key >> 6) & ((1 << 24) - 1)) - _OFFSET
            ix = (key >> 30) - _OFFSET
            for dx in range(-1, 2):
                for dy in range(-1, 2):
                    for dt in range(-1, 2):
                        nt = (it + dt + YAW_BINS) % YAW_BINS
                        nkey = _key(ix + dx, iy + dy, nt)
                        s = _slot(tkeys, nkey)
                        if tkeys[s] == _EMPTY:
                            continue
                        nb = tvals[s]
                        if bin_label[nb] < 0:
                            bin_label[nb] = n_clusters
                            stack[top] = nb
                            top += 1
        n_clusters += 1
    labels = np.empty(ids.shape[0], dtype=np.int64)
    for k in range(ids.shape[0]):
        labels[k] = bin_label[ids[k]]
    return labels, n_clusters
