"""Localization uncertainty as a safety radius (collvoid's me_publisher, radius mode "CALU").

Hennes, Claes, Meeussen, Tuyls, "Multi-robot collision avoidance with localization
uncertainty" (AAMAS 2012): sort amcl's particles by their distance from the pose estimate and
take the distance at which the accumulated weight first exceeds ``1 - eps``; the robot is then
advertised that much larger, so that neighbours keep clear of wherever it probably is.
"""

from __future__ import annotations

import numpy as np


def uncertainty_radius(
    particles: np.ndarray,
    center: np.ndarray,
    eps: float,
    cap: float,
    weights: np.ndarray | None = None,
) -> float:
    """Radius around ``center`` holding more than ``1 - eps`` of the particle weight, m.

    Parameters
    ----------
    particles : (P, 2) particle positions, map frame, m.
    center : (2,) the pose estimate, map frame, m.
    eps : share of the weight allowed outside the radius, in [0, 1).
    cap : m, the largest radius returned (collvoid: twice the robot radius).
    weights : (P,) particle weights (any positive scale); None for equal weights (amcl's
        ``particlecloud`` after resampling carries none).

    Returns 0.0 for an empty particle set (fake_localization: the pose is exact).
    """
    pts = np.asarray(particles, dtype=np.float64).reshape(-1, 2)
    if pts.shape[0] == 0:
        return 0.0
    w = np.ones(pts.shape[0]) if weights is None else np.asarray(weights, dtype=np.float64)
    total = float(w.sum())
    if not total > 0.0:
        return 0.0
    d = np.hypot(pts[:, 0] - center[0], pts[:, 1] - center[1])
    order = np.argsort(d, kind="stable")
    acc = np.cumsum(w[order]) / total
    k = int(np.searchsorted(acc, 1.0 - eps, side="right"))
    k = min(k, pts.shape[0] - 1)
    return float(min(d[order][k], cap))
