"""Goal constraints as MoveIt's ``kinematic_constraints::constructGoalConstraints`` builds them:
one joint constraint per joint, or a position constraint (a sphere of the tolerance's radius
around the target) with an optional orientation constraint on the same link."""

from __future__ import annotations

import numpy as np

from fleetsim.msgs import geometry_msgs, moveit_msgs, shape_msgs, std_msgs


def joint_goal(joints: list[str], values, tolerance: float) -> moveit_msgs.Constraints:
    """Each of ``joints`` at its value (rad) within ``tolerance`` (rad)."""
    return moveit_msgs.Constraints(
        joint_constraints=[
            moveit_msgs.JointConstraint(
                joint_name=j, position=float(v), tolerance_above=tolerance,
                tolerance_below=tolerance, weight=1.0,
            )
            for j, v in zip(joints, values, strict=True)
        ]
    )  # fmt: skip


def pose_goal(
    link: str,
    position,
    orientation=None,
    position_tolerance: float = 1e-4,
    orientation_tolerance: float = 1e-3,
    frame_id: str = "",
) -> moveit_msgs.Constraints:
    """``link`` at ``position`` (3,) m within ``position_tolerance`` m and, unless
    ``orientation`` (4,) x y z w is None, turned to it within ``orientation_tolerance`` rad;
    both in ``frame_id`` (empty: move_group's planning frame)."""
    sphere = shape_msgs.SolidPrimitive(
        type=shape_msgs.SolidPrimitive.SPHERE, dimensions=np.array([position_tolerance])
    )
    at = geometry_msgs.Pose(position=geometry_msgs.Point(*np.asarray(position, float)))
    region = moveit_msgs.BoundingVolume(primitives=[sphere], primitive_poses=[at])
    c = moveit_msgs.Constraints(
        position_constraints=[
            moveit_msgs.PositionConstraint(
                header=std_msgs.Header(frame_id=frame_id),
                link_name=link,
                constraint_region=region,
                weight=1.0,
            )
        ]
    )
    if orientation is not None:
        tol = orientation_tolerance
        c.orientation_constraints = [
            moveit_msgs.OrientationConstraint(
                header=std_msgs.Header(frame_id=frame_id), link_name=link,
                orientation=geometry_msgs.Quaternion(*orientation),
                absolute_x_axis_tolerance=tol, absolute_y_axis_tolerance=tol,
                absolute_z_axis_tolerance=tol, weight=1.0,
            )
        ]  # fmt: skip
    return c
