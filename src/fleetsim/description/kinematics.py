"""Joint transforms of a URDF tree: the kernel robot_state_publisher runs on each joint state.

Over arrays of joints (compiled); quaternions are ``(x, y, z, w)``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fleetsim.description.model import Joint
from fleetsim.tf.quaternions import quaternions_from_eulers

#: joint kinds for `child_transforms_from_joint_positions`
FIXED, REVOLUTE, PRISMATIC = 0, 1, 2
_KIND = {"fixed": FIXED, "revolute": REVOLUTE, "continuous": REVOLUTE, "prismatic": PRISMATIC}


def joint_arrays(joints: list[Joint]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Origins ``(J, 3)`` m, origin quaternions ``(J, 4)``, unit axes ``(J, 3)``, kinds ``(J,)``.

    Floating and planar joints count as fixed (robot_state_publisher does not move them).
    """
    xyz = np.array([j.origin.xyz for j in joints], dtype=np.float64).reshape(-1, 3)
    rpy = np.array([j.origin.rpy for j in joints], dtype=np.float64).reshape(-1, 3)
    axes = np.array([j.axis for j in joints], dtype=np.float64).reshape(-1, 3)
    kinds = np.array([_KIND.get(j.type, FIXED) for j in joints], dtype=np.int8)
    return xyz, quaternions_from_eulers(rpy).reshape(-1, 4), axes, kinds


def child_transforms_from_joint_positions(
    origin_xyz: np.ndarray,
    origin_quat: np.ndarray,
    axes: np.ndarray,
    kinds: np.ndarray,
    positions: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Pose of each joint's child link in its parent link frame.

    Parameters
    ----------
    origin_xyz : (J, 3) joint origin translations in the parent frame, m.
    origin_quat : (J, 4) joint origin rotations ``(x, y, z, w)``.
    axes : (J, 3) unit joint axes in the joint frame.
    kinds : (J,) `FIXED`, `REVOLUTE` or `PRISMATIC`.
    positions : (J,) joint positions, rad (revolute) or m (prismatic); ignored when fixed.

    Returns
    -------
    translations : (J, 3) m, and rotations : (J, 4) ``(x, y, z, w)``: ``T_origin * T_motion``.
    """
    return _child_transforms(
        np.ascontiguousarray(origin_xyz, dtype=np.float64),
        np.ascontiguousarray(origin_quat, dtype=np.float64),
        np.ascontiguousarray(axes, dtype=np.float64),
        np.ascontiguousarray(kinds, dtype=np.int8),
        np.ascontiguousarray(positions, dtype=np.float64),
    )


@njit(cache=True)
def _child_transforms(origin_xyz, origin_quat, axes, kinds, positions):
    """Compiled body of `child_transforms_from_joint_positions`: robot_state_publisher runs it
    on every joint_states message of every robot, and as a dozen NumPy calls on a few joints it
    cost ~0.15 ms in array overhead alone."""
    n = origin_xyz.shape[0]
    trans = np.empty((n, 3))
    rot = np.empty((n, 4))
    for j in range(n):
        q = 0.0 if kinds[j] == FIXED else positions[j]
        angle = q if kinds[j] == REVOLUTE else 0.0
        shift = q if kinds[j] == PRISMATIC else 0.0
        sh, ch = math.sin(0.5 * angle), math.cos(0.5 * angle)
        ax, ay, az = axes[j, 0], axes[j, 1], axes[j, 2]
        x2, y2, z2, w2 = ax * sh, ay * sh, az * sh, ch
        # translation: origin + R_origin * (axis * shift), as v + w t + u x t with t = 2 u x v
        vx, vy, vz = ax * shift, ay * shift, az * shift
        x1, y1, z1, w1 = origin_quat[j, 0], origin_quat[j, 1], origin_quat[j, 2], origin_quat[j, 3]
        tx = 2.0 * (y1 * vz - z1 * vy)
        ty = 2.0 * (z1 * vx - x1 * vz)
        tz = 2.0 * (x1 * vy - y1 * vx)
        trans[j, 0] = origin_xyz[j, 0] + (vx + w1 * tx + (y1 * tz - z1 * ty))
        trans[j, 1] = origin_xyz[j, 1] + (vy + w1 * ty + (z1 * tx - x1 * tz))
        trans[j, 2] = origin_xyz[j, 2] + (vz + w1 * tz + (x1 * ty - y1 * tx))
        # rotation: q_origin * q_motion (Hamilton product)
        rot[j, 0] = w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2
        rot[j, 1] = w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2
        rot[j, 2] = w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2
        rot[j, 3] = w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2
    return trans, rot
