"""Queries and teleports on an ``Engine``: poses, twists, contacts, model state, resets.

A mixin of ``Engine`` (the seam between building/stepping the world and reading/setting its
state); every method works on ``self.model`` / ``self.data`` and the model index.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from fleetsim.errors import SimulationError, did_you_mean
from fleetsim.sim.build import quat_from_rpy


@dataclass(frozen=True)
class Contact:
    """A contact between a robot and something else (not the floor)."""

    model1: str
    link1: str
    model2: str
    link2: str
    position: tuple[float, float, float]
    depth: float  # penetration, m (positive when overlapping)


def contacts_kept(
    geom: np.ndarray, geom_type: np.ndarray, geom_model: np.ndarray, model_is_robot: np.ndarray
) -> np.ndarray:
    """Which contacts are robot contacts worth reporting.

    Parameters
    ----------
    geom : (C, 2) geom ids of each contact. geom_type : (G,) MuJoCo geom types.
    geom_model : (G,) index of each geom's model (-1: none). model_is_robot : (M,) bool.

    Returns
    -------
    (C,) bool: neither geom is a plane (the floor), the geoms belong to different models, and
    at least one of them to a robot.
    """
    plane = int(mujoco.mjtGeom.mjGEOM_PLANE)  # an int: numpy compares enum objects one by one
    i = geom_model[geom]
    robot = np.append(model_is_robot, False)[i]  # index -1 (no model) reads the False
    return (geom_type[geom] != plane).all(axis=1) & (i[:, 0] != i[:, 1]) & robot.any(axis=1)


class StateQueries:
    """Pose, twist, contact and reset methods of ``Engine``."""

    def entry(self, name: str) -> Any:
        if name not in self.models:
            raise SimulationError(f"no model named '{name}'{did_you_mean(name, self.models)}")
        return self.models[name]

    @property
    def time(self) -> float:
        return float(self.data.time)

    def joint_id(self, model: str, joint: str) -> int:
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, f"{model}/{joint}")

    def body_id(self, model: str, link: str) -> int:
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"{model}/{link}")

    def link_id(self, model: str, link: str) -> int:
        """Body id of ``model``'s link; error naming the model's links when missing."""
        bid = self.body_id(model, link)
        if bid < 0 and self.entry(model).static:
            raise SimulationError(
                f"model '{model}' is static: its links are part of the world and cannot be "
                "moved, attached or measured"
            )
        if bid < 0:
            links = [
                self.model.body(b).name.split("/", 1)[1]
                for b in range(1, self.model.nbody)
                if self._model_names[self._body_model[b]] == model
            ]
            raise SimulationError(
                f"model '{model}' has no link '{link}'{did_you_mean(link, links)}"
            )
        return bid

    def root_body(self, name: str) -> int:
        """Body id of the model's root link (0, the world body, for static models)."""
        entry = self.entry(name)
        return self.model.body(entry.bodies[0]).id if entry.bodies else 0

    def model_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """World position (3,) m and orientation quaternion (w, x, y, z) of the model root."""
        entry = self.entry(name)
        if not entry.bodies:  # static: where it was placed
            return np.array(entry.pose0[:3], float), quat_from_rpy(*entry.pose0[3:])
        b = self.root_body(name)
        return self.data.xpos[b].copy(), self.data.xquat[b].copy()

    def model_twist(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Linear (3,) m/s and angular (3,) rad/s velocity of the model root, world frame."""
        j = self._free_joint(name)
        if j < 0:
            return np.zeros(3), np.zeros(3)
        qa, va = self.model.jnt_qposadr[j], self.model.jnt_dofadr[j]
        ang = np.zeros(3)
        mujoco.mju_rotVecQuat(ang, self.data.qvel[va + 3 : va + 6], self.data.qpos[qa + 3 : qa + 7])
        return self.data.qvel[va : va + 3].copy(), ang

    def link_pose(self, model: str, link: str) -> tuple[np.ndarray, np.ndarray]:
        b = self.link_id(model, link)
        return self.data.xpos[b].copy(), self.data.xquat[b].copy()

    def _free_joint(self, name: str) -> int:
        b = self.root_body(name)
        if b == 0 or self.model.body_jntnum[b] == 0:
            return -1
        j = int(self.model.body_jntadr[b])
        return j if self.model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE else -1

    def set_model_state(
        self, name: str, position=None, orientation=None, linear=None, angular=None
    ) -> None:
        """Teleport a movable model: position (3,), quaternion (w, x, y, z), world twist."""
        j = self._free_joint(name)
        if j < 0:
            raise SimulationError(f"model '{name}' is static; its state cannot be set")
        qa, va = self.model.jnt_qposadr[j], self.model.jnt_dofadr[j]
        fields = dict(position=position, orientation=orientation, linear=linear, angular=angular)
        for field, value in fields.items():
            if value is None:
                continue
            v = np.asarray(value, float)
            size = 4 if field == "orientation" else 3
            if v.shape != (size,):
                raise SimulationError(
                    f"set_model_state '{name}': {field} must have {size} values, "
                    f"got {list(v.ravel())}"
                )
            if not np.all(np.isfinite(v)):
                raise SimulationError(
                    f"set_model_state '{name}': {field} is not finite: {v.tolist()}"
                )
            if field == "orientation" and not np.linalg.norm(v) > 0:
                raise SimulationError(f"set_model_state '{name}': orientation is a zero quaternion")
        if position is not None:
            self.data.qpos[qa : qa + 3] = position
        if orientation is not None:
            q = np.asarray(orientation, float)
            self.data.qpos[qa + 3 : qa + 7] = q / np.linalg.norm(q)
        quat = self.data.qpos[qa + 3 : qa + 7]
        if linear is not None:
            self.data.qvel[va : va + 3] = linear
        if angular is not None:  # free-joint angular velocity is in the body frame
            w = np.zeros(3)
            qi = np.zeros(4)
            mujoco.mju_negQuat(qi, quat)
            mujoco.mju_rotVecQuat(w, np.asarray(angular, float), qi)
            self.data.qvel[va + 3 : va + 6] = w
        mujoco.mj_forward(self.model, self.data)

    def contacts(self) -> list[Contact]:
        """Current contacts between a robot and anything else except the floor (planes)."""
        d = self.data
        n = d.ncon
        if not n:
            return []
        con = d.contact
        geom = con.geom[:n]
        keep = np.flatnonzero(
            contacts_kept(geom, self.model.geom_type, self.geom_model, self._model_is_robot)
        )
        if not len(keep):
            return []
        names = self._model_names
        out = []
        for (g1, g2), pos, dist in zip(
            geom[keep].tolist(), con.pos[:n][keep].tolist(), con.dist[:n][keep].tolist()
        ):
            i1, i2 = self.geom_model[g1], self.geom_model[g2]
            out.append(
                Contact(
                    names[i1] if i1 >= 0 else "world",
                    self._link_of(g1),
                    names[i2] if i2 >= 0 else "world",
                    self._link_of(g2),
                    tuple(pos),
                    -dist,
                )
            )
        return out

    def _link_of(self, geom: int) -> str:
        """Link name of a geom (``<model>/<link>/...`` for static geoms in the world body)."""
        m = self.model
        body = int(m.geom_bodyid[geom])
        name = m.geom(geom).name if body == 0 else m.body(body).name
        parts = name.split("/")
        return parts[1] if len(parts) > 1 else name

    # -------------------------------------------------------------------- resets
    def reset_world(self) -> None:
        """Put every model back at its initial pose with zero velocity (time keeps running)."""
        for name, e in self.models.items():
            if not e.static and self._free_joint(name) >= 0:
                self.set_model_state(
                    name, e.pose0[:3], quat_from_rpy(*e.pose0[3:]), np.zeros(3), np.zeros(3)
                )
        self._reset_joints()
        for p in self.plugins():
            p.reset()
        self.drives.reload()
        # a world put back after a blow-up (sim.health) steps again: MuJoCo's warning counters
        # cleared as mj_resetData clears them, and no NaN left to warm-start the solver with
        self.data.warning.number[:] = 0
        if not np.isfinite(self.data.qacc_warmstart).all():
            self.data.qacc_warmstart[:] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def _reset_joints(self) -> None:
        m, d = self.model, self.data
        for j in range(m.njnt):
            if m.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE:
                d.qpos[m.jnt_qposadr[j]] = m.qpos0[m.jnt_qposadr[j]]
                d.qvel[m.jnt_dofadr[j]] = 0.0
        d.ctrl[:] = 0.0

    def reset_simulation(self) -> None:
        """reset_world plus sim time back to zero and sensor schedules restarted."""
        self.reset_world()
        self.data.time = 0.0
        self.schedule.restart()

    def world_properties(self) -> dict[str, Any]:
        return {"sim_time": self.time, "model_names": list(self.models), "rendering_enabled": True}
