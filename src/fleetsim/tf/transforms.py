"""Rigid-transform math over NumPy arrays, quaternions in ROS order ``(x, y, z, w)``.

A transform is a pair ``(translation, rotation)``: translation ``(..., 3)`` in metres and a unit
quaternion ``(..., 4)``. The transform ``T_ab`` (frame ``b`` expressed in frame ``a``, as tf's
``lookup_transform(a, b)`` returns it) maps a point given in ``b`` into ``a``:
``p_a = R(q_ab) p_b + t_ab``. Every function broadcasts over leading dimensions, so one call
handles one transform or a batch of them.

The rotation functions (Euler angles in ``tf.transformations``' static ``'sxyz'`` convention,
quaternion products, slerp) live in :mod:`fleetsim.tf.quaternions` and are re-exported here, so
``from fleetsim.tf.transforms import quaternion_from_euler`` works as in ROS.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from fleetsim.tf.quaternions import (
    FloatArray,
    _f,
    euler_from_quaternion,
    eulers_from_quaternions,
    identity_quaternion,
    matrix_from_quaternion,
    quaternion_conjugate,
    quaternion_from_euler,
    quaternion_from_matrix,
    quaternion_from_yaw,
    quaternion_inverse,
    quaternion_multiply,
    quaternion_normalize,
    quaternions_from_eulers,
    quaternions_from_yaws,
    rotate_vector,
    slerp,
    yaw_from_quaternion,
    yaws_from_quaternions,
)

__all__ = [
    "compose_transforms",
    "euler_from_quaternion",
    "eulers_from_quaternions",
    "identity_quaternion",
    "inverse_transform",
    "matrix_from_quaternion",
    "matrix_from_transform",
    "pose2d_from_transform",
    "poses2d_from_transforms",
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
    "transform_from_matrix",
    "transform_from_pose2d",
    "transform_points",
    "transforms_from_poses2d",
    "yaw_from_quaternion",
    "yaws_from_quaternions",
]


def matrix_from_transform(translation: ArrayLike, rotation: ArrayLike) -> FloatArray:
    """Return homogeneous matrices, shape ``(..., 4, 4)``.

    Parameters
    ----------
    translation : array_like, shape (..., 3)
        Metres.
    rotation : array_like, shape (..., 4)
        Quaternions ``(x, y, z, w)``.
    """
    t = _f(translation)
    r = matrix_from_quaternion(rotation)
    shape = np.broadcast_shapes(t.shape[:-1], r.shape[:-2])
    out = np.zeros((*shape, 4, 4))
    out[..., :3, :3] = r
    out[..., :3, 3] = t
    out[..., 3, 3] = 1.0
    return out


def transform_from_matrix(m: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Return ``(translation (..., 3), rotation (..., 4))`` of 4x4 matrices ``(..., 4, 4)``."""
    m = _f(m)
    return m[..., :3, 3].copy(), quaternion_from_matrix(m)


def compose_transforms(
    t_ab: ArrayLike, q_ab: ArrayLike, t_bc: ArrayLike, q_bc: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Return ``T_ac = T_ab * T_bc`` as ``(translation (..., 3), rotation (..., 4))``.

    ``T_ac`` maps points in frame ``c`` into frame ``a``: first ``T_bc`` then ``T_ab``.
    """
    return _f(t_ab) + rotate_vector(q_ab, t_bc), quaternion_multiply(q_ab, q_bc)


def inverse_transform(t_ab: ArrayLike, q_ab: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Return ``T_ba = T_ab^-1`` as ``(translation (..., 3), rotation (..., 4))``.

    ``q_ab`` must be a unit quaternion.
    """
    q_ba = quaternion_conjugate(q_ab)
    return -rotate_vector(q_ba, t_ab), q_ba


def transform_points(translation: ArrayLike, rotation: ArrayLike, points: ArrayLike) -> FloatArray:
    """Map points from the source frame into the target frame: ``R p + t``.

    Parameters
    ----------
    translation : array_like, shape (3,)
        Metres, in the target frame.
    rotation : array_like, shape (4,)
        Unit quaternion, source frame orientation in the target frame.
    points : array_like, shape (N, 3) or (N, 2)
        Points in the source frame, metres. 2D points are taken at ``z = 0`` and returned 2D.

    Returns
    -------
    ndarray, same shape as ``points``
    """
    p = _f(points)
    if p.shape[-1] not in (2, 3):
        raise ValueError(f"points must have shape (N, 2) or (N, 3), got {p.shape}")
    r = matrix_from_quaternion(rotation)
    t = _f(translation)
    if p.shape[-1] == 2:
        return p @ r[:2, :2].T + t[:2]
    return p @ r.T + t


def transform_from_pose2d(x: float, y: float, theta: float) -> tuple[FloatArray, FloatArray]:
    """Return ``(translation (3,), rotation (4,))`` of a planar pose (metres, radians about z)."""
    return np.array([x, y, 0.0]), quaternion_from_yaw(theta)


def transforms_from_poses2d(poses: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Batch :func:`transform_from_pose2d`.

    Parameters
    ----------
    poses : array_like, shape (..., 3)
        ``(x, y, theta)`` in metres and radians.

    Returns
    -------
    translation : ndarray, shape (..., 3)
    rotation : ndarray, shape (..., 4)
    """
    p = _f(poses)
    t = np.zeros((*p.shape[:-1], 3))
    t[..., :2] = p[..., :2]
    return t, quaternions_from_yaws(p[..., 2])


def pose2d_from_transform(
    translation: ArrayLike, rotation: ArrayLike
) -> tuple[float, float, float]:
    """Return the planar pose ``(x, y, yaw)`` of a transform (z, roll and pitch are dropped)."""
    t = _f(translation)
    return float(t[0]), float(t[1]), yaw_from_quaternion(rotation)


def poses2d_from_transforms(translation: ArrayLike, rotation: ArrayLike) -> FloatArray:
    """Batch :func:`pose2d_from_transform`: ``(..., 3)``, ``(..., 4)`` to ``(..., 3)``."""
    t = _f(translation)
    yaw = yaws_from_quaternions(rotation)
    return np.concatenate([t[..., :2], yaw[..., None]], axis=-1)


def compose_pose2d(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Return the planar pose ``a (+) b``: ``b`` given in ``a``'s frame, expressed where ``a`` is.

    Poses are ``(x, y, yaw)`` in metres and radians, shape ``(3,)``; yaw is not wrapped.
    """
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array([a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]])


def inverse_pose2d(a: ArrayLike) -> FloatArray:
    """Return the planar pose ``a^-1`` (``(3,)``: m, m, rad), so that ``a (+) a^-1`` is zero."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array([-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2]])
