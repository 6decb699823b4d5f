"""Cartesian paths: the end effector along straight lines through waypoints (MoveIt's
``computeCartesianPath``, served as ``compute_cartesian_path``).

Each segment from the previous pose to the next waypoint is cut into steps of at most
``eef_step`` metres; IK is solved for every step seeded with the previous step's joints, so the
arm follows the line continuously. A group with six joints or more follows the waypoints'
orientations too (interpolated by slerp); a group with fewer (the hunter's four) follows their
positions only, since it cannot keep an arbitrary orientation along a line. The path stops at
the first step with no IK solution, in collision (``avoid_collisions``), or where the joints
jump (``jump_threshold`` times the mean step in joint space, MoveIt's relative test); the
fraction of the steps reached is returned with it.
"""

from __future__ import annotations

import mujoco
import numpy as np

from fleetsim.moveit.planner import motion_is_valid

#: IK tolerance of each step (m, rad)
STEP_TOLERANCE = 1e-4


def _slerp(q0: np.ndarray, q1: np.ndarray, s: float) -> np.ndarray:
    """Quaternion (x y z w) a fraction ``s`` of the way from ``q0`` to ``q1``."""
    a = np.array([q0[3], *q0[:3]])
    b = np.array([q1[3], *q1[:3]])
    if a @ b < 0:
        b = -b
    diff = np.zeros(4)
    neg = np.zeros(4)
    mujoco.mju_negQuat(neg, a)
    mujoco.mju_mulQuat(diff, neg, b)
    vel = np.zeros(3)
    mujoco.mju_quat2Vel(vel, diff, 1.0)
    out = a.copy()
    mujoco.mju_quatIntegrate(out, vel, s)
    return np.array([*out[1:], out[0]])


def cartesian_path(
    ctx,
    start: np.ndarray,
    waypoints: list[tuple[np.ndarray, np.ndarray]],
    eef_step: float,
    jump_threshold: float = 0.0,
    avoid_collisions: bool = True,
    link: str = "",
) -> tuple[np.ndarray, float]:
    """``(path (N, J) rad, fraction)`` of ``link`` (default: the group's tip) from ``start``
    (J,) through ``waypoints`` [(position (3,) m, orientation (4,) x y z w)] in the planning
    frame; ``path[0]`` is ``start``, fraction in [0, 1]."""
    link = link or ctx.tip
    kin = ctx.kin
    follow_orientation = len(ctx.joints) >= 6
    valid = ctx.scene.is_valid if avoid_collisions else None
    p_prev, o_prev = kin.link_pose(start, link)
    targets: list[tuple[np.ndarray, np.ndarray | None]] = []
    for p, o in waypoints:
        p, o = np.asarray(p, float), np.asarray(o, float)
        o = o / np.linalg.norm(o) if np.linalg.norm(o) > 0 else o_prev  # no orientation: keep
        n = max(1, int(np.ceil(np.linalg.norm(p - p_prev) / eef_step)))
        for k in range(1, n + 1):
            s = k / n
            targets.append(
                (p_prev + s * (p - p_prev), _slerp(o_prev, o, s) if follow_orientation else None)
            )
        p_prev, o_prev = p, o
    path = [np.asarray(start, float)]
    lim = ctx.limits
    for p, o in targets:
        q = kin.pose_ik(link, p, o, [path[-1]], STEP_TOLERANCE, STEP_TOLERANCE, valid=valid)
        if q is None or (
            avoid_collisions and not motion_is_valid(path[-1], q, lim.lower, lim.upper, valid)
        ):
            break
        path.append(q)
    path = np.array(path)
    if jump_threshold > 0 and len(path) > 2:
        steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
        jumps = np.nonzero(steps > jump_threshold * steps.mean())[0]
        if jumps.size:
            path = path[: jumps[0] + 1]
    return path, (len(path) - 1) / len(targets) if targets else 1.0
