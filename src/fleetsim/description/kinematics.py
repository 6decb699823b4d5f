"""Joint transforms of a URDF tree: the kernel robot_state_publisher runs on each joint state.

Pure NumPy over arrays of joints; quaternions are ``(x, y, z, w)``.
"""

from __future__ import annotations

import numpy as np

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
    q = np.where(kinds == FIXED, 0.0, np.asarray(positions, dtype=np.float64))
    angle = np.where(kinds == REVOLUTE, q, 0.0)
    shift = np.where(kinds == PRISMATIC, q, 0.0)
    half = 0.5 * angle
    motion = np.concatenate([axes * np.sin(half)[:, None], np.cos(half)[:, None]], axis=1)
    # translation: origin + R_origin * (axis * shift)
    v = axes * shift[:, None]
    u, w = origin_quat[:, :3], origin_quat[:, 3:4]
    t = 2.0 * np.cross(u, v)
    rotated = v + w * t + np.cross(u, t)
    trans = origin_xyz + rotated
    # rotation: q_origin * q_motion (Hamilton product)
    x1, y1, z1, w1 = origin_quat.T
    x2, y2, z2, w2 = motion.T
    rot = np.stack(
        [
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        ],
        axis=1,
    )
    return trans, rot
