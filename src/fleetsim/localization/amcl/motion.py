"""Odometry motion models (amcl's ``AMCLOdom::UpdateAction``), vectorised over particles.

Four models, as ``odom_model_type``:

- ``diff``: sample_motion_model_odometry (Probabilistic Robotics, p. 136) for differential
  drive, with amcl's historical quirk that the noise terms ``alpha * delta^2`` are used as
  standard deviations (not variances).
- ``diff-corrected``: the same with ``sqrt`` of those terms (a proper variance), which needs
  much smaller alphas (amcl's advice: start around 0.005..0.01).
- ``omni`` / ``omni-corrected``: holonomic bases, translation along the odometry bearing plus a
  strafe term scaled by ``odom_alpha5``; uncorrected and corrected as above.

Backward and forward motion get the same noise (amcl's ``delta_rot*_noise``).
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.errors import ParameterError

from .params import ODOM_MODEL_TYPES


def wrapped_angles(a: np.ndarray | float) -> np.ndarray | float:
    """Angles (rad) wrapped to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def angle_diff(a: float, b: float) -> float:
    """Smallest signed difference ``a - b`` in rad, in [-pi, pi] (amcl's ``angle_diff``)."""
    # Python floats: the same floor-modulo as NumPy's remainder, without a 0-d array per call
    # (every scan of every robot asks whether it moved enough)
    return (float(a) - float(b) + math.pi) % (2.0 * math.pi) - math.pi


def odometry_delta(old_pose: np.ndarray, new_pose: np.ndarray) -> np.ndarray:
    """(3,) ``(dx, dy, dyaw)`` from ``old_pose`` to ``new_pose`` in the odom frame (m, m, rad)."""
    ox, oy, oth = (float(v) for v in old_pose)
    nx, ny, nth = (float(v) for v in new_pose)
    return np.array([nx - ox, ny - oy, angle_diff(nth, oth)])


def particles_after_odometry(
    particles: np.ndarray,
    old_pose: np.ndarray,
    new_pose: np.ndarray,
    model: str,
    alphas: tuple[float, float, float, float, float],
    rng: np.random.Generator,
) -> np.ndarray:
    """Particles moved by a noisy copy of the odometry step ``old_pose -> new_pose``.

    Parameters
    ----------
    particles : (P, 3) float64
        Poses ``(x, y, yaw)`` in the global frame, m and rad.
    old_pose, new_pose : (3,) float64
        Odometry poses ``(x, y, yaw)`` in the odom frame at the last and the current update.
    model : str
        One of ``diff``, ``omni``, ``diff-corrected``, ``omni-corrected``.
    alphas : 5 floats
        ``odom_alpha1`` .. ``odom_alpha5``.
    rng : numpy.random.Generator
        Source of the noise.

    Returns
    -------
    (P, 3) float64
        New poses, yaw wrapped to [-pi, pi).
    """
    if model not in ODOM_MODEL_TYPES:
        raise ParameterError(
            f"amcl: unknown odom_model_type {model!r}; "
            f"expected one of {', '.join(ODOM_MODEL_TYPES)}"
        )
    p = np.asarray(particles, dtype=float)
    n = len(p)
    a1, a2, a3, a4, a5 = (float(a) for a in alphas)
    old = np.asarray(old_pose, dtype=float)
    dx, dy, dth = odometry_delta(old_pose, new_pose)
    trans = float(np.hypot(dx, dy))
    out = np.empty_like(p)
    corrected = model.endswith("-corrected")

    def spread(var_like: float) -> float:
        return float(np.sqrt(var_like)) if corrected else var_like

    if model.startswith("omni"):
        rot = dth
        trans_sd = spread(a3 * trans * trans + a1 * rot * rot)
        rot_sd = spread(a4 * rot * rot + a2 * trans * trans)
        strafe_sd = spread(a1 * rot * rot + a5 * trans * trans)
        bearing = angle_diff(np.arctan2(dy, dx), old[2]) + p[:, 2]
        noise = rng.standard_normal((3, n))
        trans_hat = trans + trans_sd * noise[0]
        rot_hat = rot + rot_sd * noise[1]
        strafe_hat = strafe_sd * noise[2]
        cb, sb = np.cos(bearing), np.sin(bearing)
        out[:, 0] = p[:, 0] + trans_hat * cb + strafe_hat * sb
        out[:, 1] = p[:, 1] + trans_hat * sb - strafe_hat * cb
        out[:, 2] = wrapped_angles(p[:, 2] + rot_hat)
        return out

    # differential drive: rotate, translate, rotate
    rot1 = 0.0 if trans < 0.01 else angle_diff(np.arctan2(dy, dx), old[2])
    rot2 = angle_diff(dth, rot1)
    rot1_noise = min(abs(angle_diff(rot1, 0.0)), abs(angle_diff(rot1, np.pi)))
    rot2_noise = min(abs(angle_diff(rot2, 0.0)), abs(angle_diff(rot2, np.pi)))
    rot1_sd = spread(a1 * rot1_noise**2 + a2 * trans**2)
    trans_sd = spread(a3 * trans**2 + a4 * rot1_noise**2 + a4 * rot2_noise**2)
    rot2_sd = spread(a1 * rot2_noise**2 + a2 * trans**2)
    noise = rng.standard_normal((3, n))
    rot1_hat = wrapped_angles(rot1 - rot1_sd * noise[0])
    trans_hat = trans - trans_sd * noise[1]
    rot2_hat = wrapped_angles(rot2 - rot2_sd * noise[2])
    heading = p[:, 2] + rot1_hat
    out[:, 0] = p[:, 0] + trans_hat * np.cos(heading)
    out[:, 1] = p[:, 1] + trans_hat * np.sin(heading)
    out[:, 2] = wrapped_angles(p[:, 2] + rot1_hat + rot2_hat)
    return out
