"""Single-transform math on plain float tuples, for the tf buffer's lookup hot path.

For one small transform, plain float arithmetic in Python is several times faster than NumPy,
whose per-call overhead (array creation, dispatch) dominates at this size; see
``benchmarks/tf_lookup.py``. The array versions in :mod:`fleetsim.tf.transforms` are the
reference these functions are tested against.

A transform is a 7-tuple ``(tx, ty, tz, qx, qy, qz, qw)``: translation in metres and a unit
quaternion in ROS order. ``T_ab`` maps points given in frame ``b`` into frame ``a``.
"""

from __future__ import annotations

from math import atan2, sin, sqrt

__all__ = [
    "IDENTITY",
    "compose",
    "interpolate",
    "invert",
    "matrix_rows",
    "slerp_angle_threshold",
]

Transform7 = tuple[float, float, float, float, float, float, float]

IDENTITY: Transform7 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)

#: Below this angle (radians, between the two quaternions as 4-vectors) slerp's weights are
#: replaced by linear ones; their relative difference is below ``angle**2 / 6 ~ 2e-13``.
slerp_angle_threshold = 1e-6


def compose(a: Transform7, b: Transform7) -> Transform7:
    """Return ``T_ac = T_ab * T_bc`` for ``a = T_ab``, ``b = T_bc``."""
    ax, ay, az, aqx, aqy, aqz, aqw = a
    bx, by, bz, bqx, bqy, bqz, bqw = b
    # rotate (bx, by, bz) by a's quaternion: v + 2w (u x v) + 2 u x (u x v)
    tx = 2.0 * (aqy * bz - aqz * by)
    ty = 2.0 * (aqz * bx - aqx * bz)
    tz = 2.0 * (aqx * by - aqy * bx)
    return (
        ax + bx + aqw * tx + aqy * tz - aqz * ty,
        ay + by + aqw * ty + aqz * tx - aqx * tz,
        az + bz + aqw * tz + aqx * ty - aqy * tx,
        aqw * bqx + aqx * bqw + aqy * bqz - aqz * bqy,
        aqw * bqy - aqx * bqz + aqy * bqw + aqz * bqx,
        aqw * bqz + aqx * bqy - aqy * bqx + aqz * bqw,
        aqw * bqw - aqx * bqx - aqy * bqy - aqz * bqz,
    )


def invert(a: Transform7) -> Transform7:
    """Return ``T_ba = T_ab^-1`` (unit quaternion assumed)."""
    x, y, z, qx, qy, qz, qw = a
    # rotate -(x, y, z) by the conjugate quaternion (-qx, -qy, -qz, qw)
    tx = 2.0 * (-qy * z + qz * y)
    ty = 2.0 * (-qz * x + qx * z)
    tz = 2.0 * (-qx * y + qy * x)
    return (
        -(x + qw * tx - qy * tz + qz * ty),
        -(y + qw * ty - qz * tx + qx * tz),
        -(z + qw * tz - qx * ty + qy * tx),
        -qx,
        -qy,
        -qz,
        qw,
    )


def interpolate(a: Transform7, b: Transform7, fraction: float) -> Transform7:
    """Return the transform ``fraction`` of the way from ``a`` to ``b``.

    Translation is interpolated linearly, rotation by slerp along the shortest arc (tf2's
    ``TimeCache`` interpolation). ``fraction`` is in ``[0, 1]``.
    """
    ax, ay, az, x0, y0, z0, w0 = a
    bx, by, bz, x1, y1, z1, w1 = b
    if x0 * x1 + y0 * y1 + z0 * z1 + w0 * w1 < 0.0:
        x1, y1, z1, w1 = -x1, -y1, -z1, -w1
    dx, dy, dz, dw = x0 - x1, y0 - y1, z0 - z1, w0 - w1
    sx, sy, sz, sw = x0 + x1, y0 + y1, z0 + z1, w0 + w1
    # angle between the 4-vectors, accurate also when they are nearly parallel
    angle = 2.0 * atan2(sqrt(dx * dx + dy * dy + dz * dz + dw * dw),
                        sqrt(sx * sx + sy * sy + sz * sz + sw * sw))  # fmt: skip
    if angle < slerp_angle_threshold:
        k0 = 1.0 - fraction
        k1 = fraction
    else:
        s = sin(angle)
        k0 = sin((1.0 - fraction) * angle) / s
        k1 = sin(fraction * angle) / s
    qx = k0 * x0 + k1 * x1
    qy = k0 * y0 + k1 * y1
    qz = k0 * z0 + k1 * z1
    qw = k0 * w0 + k1 * w1
    n = 1.0 / sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    return (
        ax + fraction * (bx - ax),
        ay + fraction * (by - ay),
        az + fraction * (bz - az),
        qx * n,
        qy * n,
        qz * n,
        qw * n,
    )


def matrix_rows(a: Transform7) -> tuple[tuple[float, float, float, float], ...]:
    """Return the 4x4 homogeneous matrix of ``a`` as four row tuples (``np.array`` them)."""
    x, y, z, qx, qy, qz, qw = a
    xx, yy, zz = qx * qx, qy * qy, qz * qz
    xy, xz, yz = qx * qy, qx * qz, qy * qz
    wx, wy, wz = qw * qx, qw * qy, qw * qz
    return (
        (1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy), x),
        (2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx), y),
        (2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy), z),
        (0.0, 0.0, 0.0, 1.0),
    )
