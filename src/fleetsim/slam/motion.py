"""gmapping's odometry motion model (``motionmodel.cpp``, ``drawFromMotion``), over particles."""

from __future__ import annotations

import numpy as np


def relative_pose(new: np.ndarray, old: np.ndarray) -> np.ndarray:
    """(3,) ``new`` seen from ``old`` (gmapping's ``absoluteDifference``): m, m, rad."""
    c, s = np.cos(old[2]), np.sin(old[2])
    dx, dy = new[0] - old[0], new[1] - old[1]
    dt = (new[2] - old[2] + np.pi) % (2 * np.pi) - np.pi
    return np.array([c * dx + s * dy, -s * dx + c * dy, dt])


def composed_poses(poses: np.ndarray, deltas: np.ndarray) -> np.ndarray:
    """(P, 3) ``poses (+) deltas`` (gmapping's ``absoluteSum``), yaw wrapped to [-pi, pi)."""
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    out = np.empty_like(poses)
    out[:, 0] = poses[:, 0] + c * deltas[:, 0] - s * deltas[:, 1]
    out[:, 1] = poses[:, 1] + s * deltas[:, 0] + c * deltas[:, 1]
    out[:, 2] = (poses[:, 2] + deltas[:, 2] + np.pi) % (2 * np.pi) - np.pi
    return out


def poses_after_motion(
    poses: np.ndarray,
    odom_new: np.ndarray,
    odom_old: np.ndarray,
    srr: float,
    srt: float,
    str_: float,
    stt: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """(P, 3) particles moved by a noisy copy of the odometry step ``odom_old -> odom_new``.

    With ``(dx, dy, dth)`` the step in the old pose's frame, the noise standard deviations are
    ``srr|dx| + str|dth| + 0.3 srr|dy|`` (x), ``srr|dy| + str|dth| + 0.3 srr|dx|`` (y) and
    ``stt|dth| + srt sqrt(dx^2 + dy^2)`` (yaw), as gmapping draws them.
    """
    d = relative_pose(np.asarray(odom_new, float), np.asarray(odom_old, float))
    ax, ay, at = abs(d[0]), abs(d[1]), abs(d[2])
    sd = np.array(
        [
            srr * ax + str_ * at + 0.3 * srr * ay,
            srr * ay + str_ * at + 0.3 * srr * ax,
            stt * at + srt * np.hypot(d[0], d[1]),
        ]
    )
    n = len(poses)
    noisy = d[None, :] + rng.standard_normal((n, 3)) * sd[None, :]
    return composed_poses(poses, noisy)
