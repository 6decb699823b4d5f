"""Pose estimate from a particle set: cluster statistics (amcl's ``pf_cluster_stats``).

amcl publishes the mean of the heaviest cluster of particles. Each cluster gets its weight,
weighted mean (circular mean for yaw) and a 3 x 3 covariance: the x/y block is the weighted
covariance, yaw gets the circular variance ``-2 log R`` with ``R`` the mean resultant length
(amcl computes ``R`` without dividing by the cluster weight; here it is normalised, so a light
cluster does not get an inflated yaw variance), and x/y-yaw cross terms are zero as in amcl.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .histogram import cluster_labels


@dataclass(frozen=True)
class PoseEstimate:
    """The filter's pose estimate.

    Attributes
    ----------
    pose : (3,) float64
        ``(x, y, yaw)`` in the global frame, m and rad (mean of the heaviest cluster).
    covariance : (6, 6) float64
        Row-major ``PoseWithCovariance.covariance`` (x, y, z, roll, pitch, yaw).
    weight : float
        Total weight of that cluster (0..1).
    cluster_count : int
        Number of clusters (hypotheses) in the set.
    """

    pose: np.ndarray
    covariance: np.ndarray
    weight: float
    cluster_count: int


def cluster_statistics(
    poses: np.ndarray, weights: np.ndarray, labels: np.ndarray, n_clusters: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weight, mean and covariance of each cluster, in O(N).

    Parameters
    ----------
    poses : (N, 3) float64
        ``(x, y, yaw)``.
    weights : (N,) float64
        Normalised weights.
    labels : (N,) int64
        Cluster of each pose, 0 .. n_clusters-1.
    n_clusters : int

    Returns
    -------
    weights : (C,) float64
    means : (C, 3) float64
    covs : (C, 3, 3) float64
    """
    c = int(n_clusters)
    w = np.asarray(weights, dtype=np.float64)
    x, y, a = poses[:, 0], poses[:, 1], poses[:, 2]

    def total(values: np.ndarray) -> np.ndarray:
        return np.bincount(labels, weights=w * values, minlength=c)

    cw = np.bincount(labels, weights=w, minlength=c)
    safe = np.where(cw > 0, cw, 1.0)
    mx, my = total(x) / safe, total(y) / safe
    mc, ms = total(np.cos(a)) / safe, total(np.sin(a)) / safe
    means = np.stack([mx, my, np.arctan2(ms, mc)], axis=1)
    covs = np.zeros((c, 3, 3))
    covs[:, 0, 0] = total(x * x) / safe - mx * mx
    covs[:, 1, 1] = total(y * y) / safe - my * my
    covs[:, 0, 1] = covs[:, 1, 0] = total(x * y) / safe - mx * my
    r = np.clip(np.hypot(mc, ms), 1e-300, 1.0)
    covs[:, 2, 2] = -2.0 * np.log(r)
    covs[:, 0, 0] = np.maximum(covs[:, 0, 0], 0.0)
    covs[:, 1, 1] = np.maximum(covs[:, 1, 1], 0.0)
    return cw, means, covs


def covariance_6x6(cov3: np.ndarray) -> np.ndarray:
    """(6, 6) ``PoseWithCovariance`` covariance from a (3, 3) ``(x, y, yaw)`` covariance."""
    out = np.zeros((6, 6))
    idx = np.array([0, 1, 5])
    out[np.ix_(idx, idx)] = cov3
    return out


def covariance_3x3(cov6: np.ndarray) -> np.ndarray:
    """(3, 3) ``(x, y, yaw)`` block of a 36-element or (6, 6) ``PoseWithCovariance`` covariance."""
    c = np.asarray(cov6, dtype=np.float64).reshape(6, 6)
    idx = np.array([0, 1, 5])
    return c[np.ix_(idx, idx)].copy()


def pose_estimate(poses: np.ndarray, weights: np.ndarray) -> PoseEstimate:
    """The heaviest cluster's mean and covariance (amcl's choice of the published pose)."""
    labels, n = cluster_labels(np.ascontiguousarray(poses, dtype=np.float64))
    cw, means, covs = cluster_statistics(poses, weights, labels, n)
    best = int(np.argmax(cw))
    return PoseEstimate(means[best].copy(), covariance_6x6(covs[best]), float(cw[best]), int(n))
