"""How good a SLAM run is, against the simulator's ground truth (issue 17's metrics).

- `ate`: the absolute trajectory error, RMS of the position error after the rigid alignment
  (Horn / Umeyama, rotation and translation, no scale) of the estimate onto the truth, as the
  TUM RGB-D benchmark defines it. Written out in NumPy in a few lines rather than adding
  ``evo`` for one function.
"""

from __future__ import annotations

import numpy as np


def ate(est: np.ndarray, truth: np.ndarray) -> float:
    """RMS position error (m) of (N, 2) ``est`` after its rigid alignment onto (N, 2) ``truth``."""
    est, truth = np.asarray(est, float), np.asarray(truth, float)
    me, mt = est.mean(0), truth.mean(0)
    u, _, vt = np.linalg.svd((truth - mt).T @ (est - me))
    d = np.diag([1.0, np.sign(np.linalg.det(u @ vt))])
    rot = u @ d @ vt
    aligned = (est - me) @ rot.T + mt
    return float(np.sqrt(np.mean(np.sum((aligned - truth) ** 2, axis=1))))
