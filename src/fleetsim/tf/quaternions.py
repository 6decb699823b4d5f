"""Rotation math over NumPy arrays: quaternions in ROS order ``(x, y, z, w)``, Euler angles, slerp.

Every function broadcasts over leading dimensions, so one call handles one rotation or a batch.
Euler angles follow ``tf.transformations`` with its default static axes ``'sxyz'``: roll about
the fixed x axis, then pitch about the fixed y axis, then yaw about the fixed z axis, i.e.
``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (the same as SciPy's ``Rotation.from_euler("xyz", ...)``).
The rigid-transform functions built on these are in :mod:`fleetsim.tf.transforms`, which also
re-exports every name here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "euler_from_quaternion",
    "eulers_from_quaternions",
    "identity_quaternion",
    "matrix_from_quaternion",
    "quaternion_conjugate",
    "quaternion_from_euler",
    "quaternion_from_matrix",
    "quaternion_from_yaw",
    "quaternion_inverse",
    "quaternion_multiply",
    "quaternion_normalize",
    "quaternions_from_eulers",
    "quaternions_from_yaws",
    "rotate_vector",
    "slerp",
    "yaw_from_quaternion",
    "yaws_from_quaternions",
]

FloatArray = NDArray[np.float64]

#: Below this |cos(pitch)| the Euler decomposition is in gimbal lock and yaw is set to 0.
_GIMBAL_EPS = 4.0 * np.finfo(float).eps
#: Below this angle (radians) between two quaternions slerp uses linear weights; the weights
#: then differ from slerp's by a relative ``angle**2 / 6 ~ 2e-13``, and no ``0 / 0`` occurs.
_SLERP_PARALLEL_ANGLE = 1e-6


def _f(a: ArrayLike) -> FloatArray:
    return np.asarray(a, dtype=np.float64)


def identity_quaternion() -> FloatArray:
    """Return the identity rotation ``[0, 0, 0, 1]``, shape ``(4,)``."""
    return np.array([0.0, 0.0, 0.0, 1.0])


def quaternion_normalize(q: ArrayLike) -> FloatArray:
    """Return ``q`` scaled to unit norm.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)``, any non-zero norm.

    Returns
    -------
    ndarray, shape (..., 4)
    """
    q = _f(q)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quaternion_multiply(q1: ArrayLike, q0: ArrayLike) -> FloatArray:
    """Return the Hamilton product ``q1 * q0`` (apply ``q0`` first, then ``q1``).

    Same argument order and meaning as ``tf.transformations.quaternion_multiply``.

    Parameters
    ----------
    q1, q0 : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)``; leading dimensions broadcast.

    Returns
    -------
    ndarray, shape (..., 4)
    """
    q1 = _f(q1)
    q0 = _f(q0)
    x1, y1, z1, w1 = q1[..., 0], q1[..., 1], q1[..., 2], q1[..., 3]
    x0, y0, z0, w0 = q0[..., 0], q0[..., 1], q0[..., 2], q0[..., 3]
    return np.stack(
        [
            w1 * x0 + x1 * w0 + y1 * z0 - z1 * y0,
            w1 * y0 - x1 * z0 + y1 * w0 + z1 * x0,
            w1 * z0 + x1 * y0 - y1 * x0 + z1 * w0,
            w1 * w0 - x1 * x0 - y1 * y0 - z1 * z0,
        ],
        axis=-1,
    )


def quaternion_conjugate(q: ArrayLike) -> FloatArray:
    """Return the conjugate ``(-x, -y, -z, w)`` of ``q``, shape ``(..., 4)``."""
    q = _f(q)
    return np.concatenate([-q[..., :3], q[..., 3:]], axis=-1)


def quaternion_inverse(q: ArrayLike) -> FloatArray:
    """Return the multiplicative inverse ``conj(q) / |q|^2``, shape ``(..., 4)``.

    For unit quaternions this equals :func:`quaternion_conjugate`.
    """
    q = _f(q)
    return quaternion_conjugate(q) / np.sum(q * q, axis=-1, keepdims=True)


def quaternion_from_euler(roll: float, pitch: float, yaw: float) -> FloatArray:
    """Return the unit quaternion for static-axes ``'sxyz'`` Euler angles.

    Parameters
    ----------
    roll, pitch, yaw : float
        Rotations in radians about the fixed x, y and z axes, applied in that order.

    Returns
    -------
    ndarray, shape (4,)
        ``(x, y, z, w)``, equal to ``tf.transformations.quaternion_from_euler(roll, pitch, yaw)``.
    """
    return quaternions_from_eulers(np.array([roll, pitch, yaw], dtype=np.float64))


def quaternions_from_eulers(rpy: ArrayLike) -> FloatArray:
    """Batch :func:`quaternion_from_euler`.

    Parameters
    ----------
    rpy : array_like, shape (..., 3)
        ``(roll, pitch, yaw)`` in radians, static axes ``'sxyz'``.

    Returns
    -------
    ndarray, shape (..., 4)
    """
    half = 0.5 * _f(rpy)
    cr, cp, cy = np.moveaxis(np.cos(half), -1, 0)
    sr, sp, sy = np.moveaxis(np.sin(half), -1, 0)
    return np.stack(
        [
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy,
        ],
        axis=-1,
    )


def quaternion_from_yaw(yaw: float) -> FloatArray:
    """Return the quaternion ``(0, 0, sin(yaw/2), cos(yaw/2))`` for a rotation about z, ``(4,)``."""
    return quaternions_from_yaws(np.float64(yaw))


def quaternions_from_yaws(yaws: ArrayLike) -> FloatArray:
    """Return rotations about z, shape ``(..., 4)``, for yaws of shape ``(...)`` in radians."""
    half = 0.5 * _f(yaws)
    zeros = np.zeros_like(half)
    return np.stack([zeros, zeros, np.sin(half), np.cos(half)], axis=-1)


def matrix_from_quaternion(q: ArrayLike) -> FloatArray:
    """Return the rotation matrix of ``q`` (normalised first), shape ``(..., 3, 3)``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)`` of any non-zero norm.
    """
    q = _f(q)
    x, y, z, w = np.moveaxis(q, -1, 0)
    s = 2.0 / np.sum(q * q, axis=-1)
    xx, yy, zz = s * x * x, s * y * y, s * z * z
    xy, xz, yz = s * x * y, s * x * z, s * y * z
    wx, wy, wz = s * w * x, s * w * y, s * w * z
    rows = [
        [1.0 - (yy + zz), xy - wz, xz + wy],
        [xy + wz, 1.0 - (xx + zz), yz - wx],
        [xz - wy, yz + wx, 1.0 - (xx + yy)],
    ]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def quaternion_from_matrix(m: ArrayLike) -> FloatArray:
    """Return the unit quaternion (with ``w >= 0``) of rotation matrices.

    Uses Shepperd's method: the largest of ``w, x, y, z`` is computed from the diagonal, which
    keeps the result accurate for every rotation angle.

    Parameters
    ----------
    m : array_like, shape (..., 3, 3) or (..., 4, 4)
        Rotation matrices; for 4x4 homogeneous matrices the upper-left block is used.

    Returns
    -------
    ndarray, shape (..., 4)
    """
    m = _f(m)[..., :3, :3]
    m00, m11, m22 = m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]
    trace = m00 + m11 + m22
    # Four candidate solutions; each is exact when its pivot component is the largest.
    cand = np.stack(
        [
            np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                      m[..., 1, 0] - m[..., 0, 1], 1.0 + trace], axis=-1),
            np.stack([1.0 + m00 - m11 - m22, m[..., 0, 1] + m[..., 1, 0],
                      m[..., 0, 2] + m[..., 2, 0], m[..., 2, 1] - m[..., 1, 2]], axis=-1),
            np.stack([m[..., 0, 1] + m[..., 1, 0], 1.0 - m00 + m11 - m22,
                      m[..., 1, 2] + m[..., 2, 1], m[..., 0, 2] - m[..., 2, 0]], axis=-1),
            np.stack([m[..., 0, 2] + m[..., 2, 0], m[..., 1, 2] + m[..., 2, 1],
                      1.0 - m00 - m11 + m22, m[..., 1, 0] - m[..., 0, 1]], axis=-1),
        ],
        axis=-2,
    )  # fmt: skip
    pivot = np.argmax(np.stack([trace, m00, m11, m22], axis=-1), axis=-1)
    q = np.take_along_axis(cand, pivot[..., None, None], axis=-2)[..., 0, :]
    q = quaternion_normalize(q)
    return np.where(q[..., 3:] < 0.0, -q, q)


def euler_from_quaternion(q: ArrayLike) -> tuple[float, float, float]:
    """Return ``(roll, pitch, yaw)`` in radians, static axes ``'sxyz'``.

    Roll and yaw lie in ``[-pi, pi]``, pitch in ``[-pi/2, pi/2]``. In gimbal lock
    (``|pitch| = pi/2``) yaw is set to 0 and the whole heading goes into roll, as
    ``tf.transformations.euler_from_quaternion`` does.

    Parameters
    ----------
    q : array_like, shape (4,)
    """
    r, p, y = eulers_from_quaternions(q)
    return float(r), float(p), float(y)


def eulers_from_quaternions(q: ArrayLike) -> FloatArray:
    """Batch :func:`euler_from_quaternion`: shape ``(..., 4)`` to ``(..., 3)`` radians."""
    m = matrix_from_quaternion(q)
    cy = np.hypot(m[..., 0, 0], m[..., 1, 0])
    locked = cy <= _GIMBAL_EPS
    roll = np.where(
        locked,
        np.arctan2(-m[..., 1, 2], m[..., 1, 1]),
        np.arctan2(m[..., 2, 1], m[..., 2, 2]),
    )
    pitch = np.arctan2(-m[..., 2, 0], cy)
    yaw = np.where(locked, 0.0, np.arctan2(m[..., 1, 0], m[..., 0, 0]))
    return np.stack([roll, pitch, yaw], axis=-1)


def yaw_from_quaternion(q: ArrayLike) -> float:
    """Return the yaw (heading about z) of ``q``, radians in ``[-pi, pi]`` (``tf.getYaw``)."""
    return float(yaws_from_quaternions(q))


def yaws_from_quaternions(q: ArrayLike) -> FloatArray:
    """Batch :func:`yaw_from_quaternion`: shape ``(..., 4)`` to ``(...)`` radians."""
    x, y, z, w = np.moveaxis(_f(q), -1, 0)
    return np.arctan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)


def rotate_vector(q: ArrayLike, v: ArrayLike) -> FloatArray:
    """Return ``v`` rotated by the unit quaternion ``q``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit quaternions.
    v : array_like, shape (..., 3)
        Vectors; leading dimensions broadcast against ``q``'s.

    Returns
    -------
    ndarray, shape (..., 3)
    """
    q = _f(q)
    v = _f(v)
    qx, qy, qz, qw = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    # v + 2w (u x v) + 2 u x (u x v), written out (np.cross is slow for small inputs)
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return np.stack(
        [
            vx + qw * tx + qy * tz - qz * ty,
            vy + qw * ty + qz * tx - qx * tz,
            vz + qw * tz + qx * ty - qy * tx,
        ],
        axis=-1,
    )


def slerp(q0: ArrayLike, q1: ArrayLike, fraction: ArrayLike) -> FloatArray:
    """Spherical linear interpolation along the shortest arc.

    ``fraction = 0`` gives ``q0``, ``1`` gives ``q1`` (or ``-q1``, the same rotation, when that
    is nearer to ``q0``). Nearly parallel inputs use linear weights, which avoids dividing by
    ``sin(angle) ~ 0``.

    Parameters
    ----------
    q0, q1 : array_like, shape (..., 4)
        Unit quaternions.
    fraction : array_like, shape (...)
        Interpolation parameter, usually in ``[0, 1]``; broadcasts with the quaternions.

    Returns
    -------
    ndarray, shape (..., 4)
        Unit quaternions.
    """
    q0 = _f(q0)
    q1 = _f(q1)
    t = _f(fraction)[..., None]
    dot = np.sum(q0 * q1, axis=-1, keepdims=True)
    q1 = np.where(dot < 0.0, -q1, q1)
    # angle between the 4-vectors, accurate also when they are nearly parallel
    angle = 2.0 * np.arctan2(
        np.linalg.norm(q0 - q1, axis=-1, keepdims=True),
        np.linalg.norm(q0 + q1, axis=-1, keepdims=True),
    )
    parallel = angle < _SLERP_PARALLEL_ANGLE
    safe_sin = np.where(parallel, 1.0, np.sin(angle))
    w0 = np.where(parallel, 1.0 - t, np.sin((1.0 - t) * angle) / safe_sin)
    w1 = np.where(parallel, t, np.sin(t * angle) / safe_sin)
    return quaternion_normalize(w0 * q0 + w1 * q1)
