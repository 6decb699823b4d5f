"""Exact ray/triangle reference for the ray-casting tests and benchmarks/mesh_world.py."""

from __future__ import annotations

import numpy as np


def first_hit(corners, origin, direction, rmin=0.0, rmax=np.inf):
    """Distance to the first triangle a ray meets at ``t >= rmin`` (Moller-Trumbore).

    Parameters
    ----------
    corners : (T, 3, 3) array
        Triangle corners, m, in the frame of ``origin``.
    origin : (3,) array
        Ray origin, m.
    direction : (3,) array
        Unit ray direction.
    rmin, rmax : float
        Range limits, m.

    Returns
    -------
    float
        The distance, m; ``inf`` if no triangle is hit within ``rmax``.
    """
    a = corners[:, 0]
    e1, e2 = corners[:, 1] - a, corners[:, 2] - a
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = origin - a
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    w = (q @ direction) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    hit = ok & (u >= 0) & (w >= 0) & (u + w <= 1) & (t >= rmin)
    best = t[hit].min() if hit.any() else np.inf
    return best if best <= rmax else np.inf


def horizontal(angle):
    """(3,) unit direction of a horizontal ray at ``angle`` (rad) from +x."""
    return np.array([np.cos(angle), np.sin(angle), 0.0])
