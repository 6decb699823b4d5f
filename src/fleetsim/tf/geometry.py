"""Applying a ``TransformStamped`` to geometry messages (tf2_geometry_msgs's ``do_transform_*``).

Each function returns a new message in ``transform.header.frame_id``, stamped with
``transform.header.stamp``, as tf2_geometry_msgs does; inputs are never modified.
`TRANSFORMERS` maps a stamped type name to its function, for `Buffer.transform`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from fleetsim.msgs.geometry_msgs import (
    Point,
    PointStamped,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    PoseWithCovarianceStamped,
    Quaternion,
    TransformStamped,
    Vector3,
    Vector3Stamped,
)
from fleetsim.msgs.std_msgs import Header
from fleetsim.tf.fastmath import compose, matrix_rows

__all__ = [
    "TRANSFORMERS",
    "do_transform_point",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_pose_with_covariance_stamped",
    "do_transform_vector3",
]


def _value(t: TransformStamped) -> tuple[float, ...]:
    tr, q = t.transform.translation, t.transform.rotation
    return (tr.x, tr.y, tr.z, q.x, q.y, q.z, q.w)


def _header(t: TransformStamped) -> Header:
    return Header(stamp=t.header.stamp, frame_id=t.header.frame_id)


def do_transform_point(point: PointStamped, transform: TransformStamped) -> PointStamped:
    """The point mapped into the transform's target frame (rotation and translation)."""
    p = point.point
    x, y, z, *_ = compose(_value(transform), (p.x, p.y, p.z, 0.0, 0.0, 0.0, 1.0))
    return PointStamped(header=_header(transform), point=Point(x=x, y=y, z=z))


def do_transform_vector3(vector: Vector3Stamped, transform: TransformStamped) -> Vector3Stamped:
    """The vector rotated into the transform's target frame (no translation: a direction)."""
    v = vector.vector
    tx, ty, tz, *q = _value(transform)
    x, y, z, *_ = compose((0.0, 0.0, 0.0, *q), (v.x, v.y, v.z, 0.0, 0.0, 0.0, 1.0))
    return Vector3Stamped(header=_header(transform), vector=Vector3(x=x, y=y, z=z))


def do_transform_pose(pose: Pose, transform: TransformStamped) -> Pose:
    """The pose (position and orientation) expressed in the transform's target frame."""
    p, o = pose.position, pose.orientation
    x, y, z, qx, qy, qz, qw = compose(_value(transform), (p.x, p.y, p.z, o.x, o.y, o.z, o.w))
    return Pose(position=Point(x=x, y=y, z=z), orientation=Quaternion(x=qx, y=qy, z=qz, w=qw))


def do_transform_pose_stamped(pose: PoseStamped, transform: TransformStamped) -> PoseStamped:
    """:func:`do_transform_pose` with the header of the transform."""
    return PoseStamped(header=_header(transform), pose=do_transform_pose(pose.pose, transform))


def do_transform_pose_with_covariance_stamped(
    pose: PoseWithCovarianceStamped, transform: TransformStamped
) -> PoseWithCovarianceStamped:
    """The pose transformed and its 6x6 covariance rotated: ``C' = R6 C R6^T``.

    ``R6`` is the block diagonal of the transform's rotation for (x, y, z) and (rx, ry, rz).
    """
    r = np.array(matrix_rows(_value(transform)))[:3, :3]
    r6 = np.zeros((6, 6))
    r6[:3, :3] = r6[3:, 3:] = r
    cov = np.asarray(pose.pose.covariance, dtype=np.float64).reshape(6, 6)
    rotated = (r6 @ cov @ r6.T).reshape(36)
    return PoseWithCovarianceStamped(
        header=_header(transform),
        pose=PoseWithCovariance(
            pose=do_transform_pose(pose.pose.pose, transform), covariance=rotated
        ),
    )


#: Stamped message type name -> function applying a TransformStamped to it.
TRANSFORMERS: dict[str, Callable[[Any, TransformStamped], Any]] = {
    PointStamped.__msgtype__: do_transform_point,
    Vector3Stamped.__msgtype__: do_transform_vector3,
    PoseStamped.__msgtype__: do_transform_pose_stamped,
    PoseWithCovarianceStamped.__msgtype__: do_transform_pose_with_covariance_stamped,
}
