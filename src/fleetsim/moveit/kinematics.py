"""Forward and inverse kinematics of one robot on its own MuJoCo model.

The robot is built by the simulator's own robot builder into a private ``Engine`` at the
origin, so every pose here is in the robot's root link frame (``base_link``, MoveIt's planning
frame) and the link bodies are the simulator's. IK is damped least squares on ``mj_jacBody``:
position-only (``position_ik``), or position and orientation (``pose_ik``, the rotation error
as an axis-angle vector weighted as metres at ``ROTATION_WEIGHT`` m/rad). A 4-joint arm as the
hunter's reaches a full 6-D pose only where the orientation is one its joints can make, so
``pose_ik`` simply finds no solution elsewhere. mink would add a QP solver dependency for tasks
these arms do not have.
"""

from __future__ import annotations

import mujoco
import numpy as np

from fleetsim.errors import PlanningError, did_you_mean

MODEL = "robot"
ROTATION_WEIGHT = 0.1  # m per rad: a 0.01 rad orientation error weighs as 1 mm


class Kinematics:
    """FK/IK of ``joints`` (a planning group's active joints) of ``robot``."""

    def __init__(self, robot, joints: list[str], lower: np.ndarray, upper: np.ndarray) -> None:
        from fleetsim.sim import Engine

        self.engine = Engine(None)
        self.entry = self.engine.spawn_robot(MODEL, robot, (0, 0, 0, 0, 0, 0))
        self.model, self.data = self.engine.model, mujoco.MjData(self.engine.model)
        m = self.model
        ids = [self.engine.joint_id(MODEL, j) for j in joints]
        self.qadr = np.array([m.jnt_qposadr[i] for i in ids], np.int64)
        self.dadr = np.array([m.jnt_dofadr[i] for i in ids], np.int64)
        self.joints = list(joints)
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)
        self.root = self.body_id(robot.root_link())
        self.qpos0 = self.data.qpos.copy()

    def body_id(self, link: str) -> int:
        bid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"{MODEL}/{link}")
        if bid < 0:
            names = [
                self.model.body(i).name.removeprefix(f"{MODEL}/") for i in range(self.model.nbody)
            ]
            raise PlanningError(f"no link '{link}' in the robot model{did_you_mean(link, names)}")
        return bid

    def set(self, q: np.ndarray) -> None:
        """Put the group at ``q`` (J,) rad and update every body's pose."""
        self.data.qpos[:] = self.qpos0
        self.data.qpos[self.qadr] = q
        mujoco.mj_kinematics(self.model, self.data)

    def _root_inverse(self) -> tuple[np.ndarray, np.ndarray]:
        R = self.data.xmat[self.root].reshape(3, 3)
        return R.T, -R.T @ self.data.xpos[self.root]

    def link_pose(self, q: np.ndarray, link: str) -> tuple[np.ndarray, np.ndarray]:
        """``(position (3,) m, quaternion (4,) x y z w)`` of ``link`` in the root frame."""
        self.set(q)
        bid = self.body_id(link)
        Rinv, tinv = self._root_inverse()
        pos = Rinv @ self.data.xpos[bid] + tinv
        R = Rinv @ self.data.xmat[bid].reshape(3, 3)
        wxyz = np.zeros(4)
        mujoco.mju_mat2Quat(wxyz, R.reshape(9))
        return pos, np.array([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])

    def position_ik(
        self,
        link: str,
        target: np.ndarray,
        seeds: list[np.ndarray],
        tolerance: float = 1e-3,
        iterations: int = 100,
        damping: float = 1e-3,
        valid=None,
    ) -> np.ndarray | None:
        """Joint values (J,) putting ``link``'s origin at ``target`` (3,) m (root frame) within
        ``tolerance``, from the first seed that converges (and passes ``valid(q)``), else None."""
        return self.pose_ik(link, target, None, seeds, tolerance, 0.0, iterations, damping, valid)

    def pose_ik(
        self,
        link: str,
        position: np.ndarray,
        orientation: np.ndarray | None,
        seeds: list[np.ndarray],
        tolerance: float = 1e-3,
        angle_tolerance: float = 1e-3,
        iterations: int = 100,
        damping: float = 1e-3,
        valid=None,
    ) -> np.ndarray | None:
        """Joint values (J,) putting ``link`` at ``position`` (3,) m within ``tolerance`` and,
        unless ``orientation`` is None, turned to ``orientation`` (4,) x y z w (root frame)
        within ``angle_tolerance`` rad; from the first seed that converges (and passes
        ``valid(q)``), else None."""
        bid = self.body_id(link)
        jacp = np.zeros((3, self.model.nv))
        jacr = np.zeros((3, self.model.nv)) if orientation is not None else None
        R_goal = None
        if orientation is not None:
            x, y, z, w = np.asarray(orientation, float) / np.linalg.norm(orientation)
            R_goal = np.zeros(9)
            mujoco.mju_quat2Mat(R_goal, np.array([w, x, y, z]))
            R_goal = R_goal.reshape(3, 3)
        Rinv, tinv = None, None
        n = 3 if orientation is None else 6
        for seed in seeds:
            q = np.clip(np.asarray(seed, float), self.lower, self.upper)
            for _ in range(iterations):
                self.set(q)
                if Rinv is None:
                    Rinv, tinv = self._root_inverse()
                err = position - (Rinv @ self.data.xpos[bid] + tinv)
                done = np.linalg.norm(err) < tolerance
                if R_goal is not None:
                    R = Rinv @ self.data.xmat[bid].reshape(3, 3)
                    rot = _rotation_vector(R_goal @ R.T)  # root frame
                    done = done and np.linalg.norm(rot) < angle_tolerance
                    err = np.concatenate([err, ROTATION_WEIGHT * rot])
                if done:
                    if valid is None or valid(q):
                        return q
                    break
                mujoco.mj_comPos(self.model, self.data)  # the Jacobian needs cdof
                mujoco.mj_jacBody(self.model, self.data, jacp, jacr, bid)
                J = Rinv @ jacp[:, self.dadr]
                if jacr is not None:
                    J = np.vstack([J, ROTATION_WEIGHT * (Rinv @ jacr[:, self.dadr])])
                dq = J.T @ np.linalg.solve(J @ J.T + damping * np.eye(n), err)
                q = np.clip(q + dq, self.lower, self.upper)
        return None


def _rotation_vector(R: np.ndarray) -> np.ndarray:
    """(3,) axis * angle (rad) of the rotation matrix ``R`` (3, 3)."""
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, R.reshape(9))
    vel = np.zeros(3)
    mujoco.mju_quat2Vel(vel, quat, 1.0)
    return vel
