"""Resampling: the low-variance (systematic) resampler and KLD-sampling, both O(N).

ROS amcl draws every sample by a linear search of the cumulative weights (O(N^2)); here:

1. `systematic_resample_indices` draws ``max_particles`` candidates with one random offset and
   a single merge pass over the cumulative weights (O(N + M)); each particle gets
   ``floor(M w)`` or ``ceil(M w)`` copies.
2. Candidates are replaced by random free-space poses with probability ``w_diff`` (amcl's
   recovery, ``1 - w_fast / w_slow``).
3. The candidates are shuffled and read in order, counting occupied histogram bins ``k`` as
   amcl does while it draws; the set stops at the first size ``n > kld_sample_limit(k)``.
   A prefix of a shuffled low-variance sample is a simple random sample of it, so the
   bin count grows as it would for independent draws.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .histogram import occupied_bin_counts, pose_bin_keys


@njit(cache=True)
def systematic_resample_indices(weights, n, u):
    """Indices of ``n`` particles drawn by low-variance (systematic) resampling.

    Parameters
    ----------
    weights : (P,) float64
        Non-negative weights (need not sum to 1; the sum must be > 0).
    n : int
        Number of draws.
    u : float
        Random offset in [0, 1).

    Returns
    -------
    (n,) int64
        Non-decreasing particle indices; particle ``i`` appears ``floor(n w_i / W)`` or
        ``ceil(n w_i / W)`` times, zero-weight particles never.
    """
    p = weights.shape[0]
    out = np.empty(n, dtype=np.int64)
    total = 0.0
    for i in range(p):
        total += weights[i]
    step = total / n
    pos = u * step
    i = 0
    c = weights[0]
    for m in range(n):
        while pos >= c and i < p - 1:
            i += 1
            c += weights[i]
        out[m] = i
        pos += step
    return out


def kld_sample_limits(
    k: np.ndarray, kld_err: float, kld_z: float, min_particles: int, max_particles: int
) -> np.ndarray:
    """Particles needed for ``k`` occupied bins (Fox 2003; amcl's ``pf_resample_limit``).

    ``n = ceil((k - 1) / (2 err) * (1 - 2/(9(k-1)) + sqrt(2/(9(k-1))) z)^3)``, clipped to
    ``[min_particles, max_particles]``; ``k <= 1`` gives ``max_particles`` as in amcl.
    Vectorised over ``k`` (any shape, int).
    """
    k = np.asarray(k, dtype=np.float64)
    km1 = np.maximum(k - 1.0, 1.0)
    b = 2.0 / (9.0 * km1)
    x = 1.0 - b + np.sqrt(b) * kld_z
    n = np.ceil(km1 / (2.0 * kld_err) * x**3)
    n = np.clip(n, min_particles, max_particles)
    n = np.where(k <= 1, max_particles, n)
    return n.astype(np.int64)


def kld_resample(
    particles: np.ndarray,
    weights: np.ndarray,
    rng: np.random.Generator,
    kld_err: float,
    kld_z: float,
    min_particles: int,
    max_particles: int,
    w_diff: float = 0.0,
    random_poses=None,
) -> np.ndarray:
    """A new, equally weighted particle set of adaptive size (KLD-sampling).

    Parameters
    ----------
    particles : (P, 3) float64
        Current poses.
    weights : (P,) float64
        Their weights (sum > 0).
    rng : numpy.random.Generator
    kld_err, kld_z, min_particles, max_particles : amcl parameters.
    w_diff : float
        Probability of replacing a draw by a random pose (recovery), in [0, 1].
    random_poses : callable (n, rng) -> (n, 3), optional
        Sampler of random poses; required when ``w_diff > 0``.

    Returns
    -------
    (N, 3) float64
        New poses, ``min_particles <= N <= max_particles`` (fewer only if ``max_particles``
        draws fill fewer bins).
    """
    m = int(max_particles)
    w = np.ascontiguousarray(weights, dtype=np.float64)
    idx = systematic_resample_indices(w, m, float(rng.random()))
    cand = np.asarray(particles, dtype=np.float64)[idx]
    if w_diff > 0.0:
        if random_poses is None:
            raise ValueError("kld_resample: w_diff > 0 needs random_poses")
        swap = rng.random(m) < w_diff
        n_swap = int(np.count_nonzero(swap))
        if n_swap:
            cand[swap] = random_poses(n_swap, rng)
    cand = cand[rng.permutation(m)]
    k = occupied_bin_counts(pose_bin_keys(cand))
    limits = kld_sample_limits(k, kld_err, kld_z, min_particles, m)
    sizes = np.arange(1, m + 1)
    stop = np.flatnonzero(sizes > limits)
    n = int(stop[0]) + 1 if len(stop) else m
    return np.ascontiguousarray(cand[:n])


def effective_sample_size(weights: np.ndarray) -> float:
    """``1 / sum(w^2)`` of normalised weights (P,)."""
    w = np.asarray(weights, dtype=np.float64)
    s = float(w.sum())
    if s <= 0.0 or not math.isfinite(s):
        return 0.0
    w = w / s
    return 1.0 / float(np.dot(w, w))
