"""Collision checking for planning, in MuJoCo.

A separate small model holds, as free bodies, copies of the robot's collision geoms (posed
from ``Kinematics``), the world's and the other robots' collision geoms near the robot (copied
from the simulator at each planning request, in the robot's root frame; meshes as their
bounding boxes), and the planning scene's collision objects. Contact filters: the group's moving
links against everything; the robot's other links, the world and scene objects never against
each other; link pairs the SRDF disables are excluded, as MoveIt's allowed collision matrix.
"""

from __future__ import annotations

import mujoco
import numpy as np

from fleetsim.errors import PlanningError
from fleetsim.moveit.kinematics import MODEL, Kinematics

MOVING, STATIC_ROBOT, WORLD = (1, 3), (1, 0), (2, 0)  # (contype, conaffinity)
NEAR = 2.0  # m: world geoms farther than this from the robot's root are not copied


def _quat_wxyz(R: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).reshape(9))
    return q


class CollisionScene:
    """Planning-scene collision checks for one planning group.

    Parameters
    ----------
    kin : the group's ``Kinematics``.
    moving_links : links the group moves (``RobotModel.links``).
    disabled : link pairs never checked (SRDF ``disable_collisions``).
    """

    def __init__(self, kin: Kinematics, moving_links: list[str], disabled) -> None:
        self.kin = kin
        self.moving = set(moving_links)
        self.disabled = {frozenset(p[:2]) for p in disabled}
        self.objects: dict[str, list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]] = {}
        self.world: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]] = []
        self._build()

    # ------------------------------------------------------------------ model
    def _robot_geoms(self):
        m = self.kin.model
        for b in range(m.nbody):
            name = m.body(b).name
            if not name.startswith(f"{MODEL}/"):
                continue
            link = name.removeprefix(f"{MODEL}/")
            geoms = [
                g
                for g in range(m.ngeom)
                if m.geom_bodyid[g] == b and (m.geom_contype[g] or m.geom_conaffinity[g])
            ]
            if geoms:
                yield b, link, geoms

    def _build(self) -> None:
        src = self.kin.model
        spec = mujoco.MjSpec()
        spec.option.gravity = [0, 0, 0]
        self.links: list[tuple[int, str]] = []  # (kinematics body id, link)
        for b, link, geoms in self._robot_geoms():
            # a free body, not mocap: MuJoCo never collides two world-welded (static) bodies
            body = spec.worldbody.add_body(name=link)
            body.add_freejoint()
            ct, ca = MOVING if link in self.moving else STATIC_ROBOT
            for g in geoms:
                self._add_geom(
                    body,
                    src.geom_type[g],
                    src.geom_size[g],
                    src.geom_pos[g],
                    src.geom_quat[g],
                    ct,
                    ca,
                    src,
                    g,
                )
            self.links.append((b, link))
        names = [link for _, link in self.links]
        for pair in self.disabled:
            a, b = tuple(pair)
            if a in names and b in names:
                spec.add_exclude(bodyname1=a, bodyname2=b)
        for k, (t, size, pos, quat) in enumerate(self.world):
            body = spec.worldbody.add_body(name=f"world#{k}")
            self._add_geom(body, t, size, pos, quat, *WORLD)
        for oid, geoms in self.objects.items():
            body = spec.worldbody.add_body(name=f"object:{oid}")
            for t, size, pos, quat in geoms:
                self._add_geom(body, t, size, pos, quat, *WORLD)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self.qadr = [7 * i for i in range(len(self.links))]
        self._pose_links(self.links)  # the static links once; the moving ones at each check
        self.moving_links = [
            (lk, a) for lk, a in zip(self.links, self.qadr, strict=True) if lk[1] in self.moving
        ]

    @staticmethod
    def _add_geom(body, t, size, pos, quat, ct, ca, src=None, g=None) -> None:
        t = int(t)
        if t == int(mujoco.mjtGeom.mjGEOM_MESH):
            # a mesh as its bounding box (conservative; meshes are not copied)
            aabb = src.geom_aabb[g]
            pos = np.asarray(pos) + _rotate(np.asarray(quat), aabb[:3])
            t, size = int(mujoco.mjtGeom.mjGEOM_BOX), aabb[3:]
        body.add_geom(
            type=mujoco.mjtGeom(t),
            size=np.asarray(size, float),
            pos=np.asarray(pos, float),
            quat=np.asarray(quat, float),
            contype=ct,
            conaffinity=ca,
        )

    def _pose_links(self, links) -> None:
        self.kin.set(self.kin.qpos0[self.kin.qadr])
        kd = self.kin.data
        for (b, _), a in zip(links, self.qadr, strict=True):
            self.data.qpos[a : a + 3] = kd.xpos[b]
            mujoco.mju_mat2Quat(self.data.qpos[a + 3 : a + 7], kd.xmat[b])

    # ------------------------------------------------------------------ world and objects
    def set_world_from(self, engine, model_name: str) -> None:
        """Copy the simulator's collision geoms near robot ``model_name`` (not its own)."""
        m, d = engine.model, engine.data
        root = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{model_name}/{self.kin_root}")
        R = d.xmat[root].reshape(3, 3)
        p = d.xpos[root]
        world = []
        for g in range(m.ngeom):
            if not (m.geom_contype[g] or m.geom_conaffinity[g]):
                continue
            if m.body(m.geom_bodyid[g]).name.startswith(f"{model_name}/"):
                continue
            gp = R.T @ (d.geom_xpos[g] - p)
            if m.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE and (
                np.linalg.norm(gp) - m.geom_rbound[g] > NEAR
            ):
                continue
            gR = R.T @ d.geom_xmat[g].reshape(3, 3)
            t, size = m.geom_type[g], m.geom_size[g].copy()
            if t == mujoco.mjtGeom.mjGEOM_MESH:
                aabb = m.geom_aabb[g]
                gp = gp + gR @ aabb[:3]
                t, size = mujoco.mjtGeom.mjGEOM_BOX, aabb[3:].copy()
            if t == mujoco.mjtGeom.mjGEOM_PLANE:
                size = np.array([0.0, 0.0, 1.0])
            world.append((int(t), size, gp, _quat_wxyz(gR)))
        self.world = world
        self._build()

    @property
    def kin_root(self) -> str:
        return self.kin.model.body(self.kin.root).name.removeprefix(f"{MODEL}/")

    def add_object(self, oid: str, geoms: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]):
        """Add (or replace) a collision object: geoms as (mjtGeom type, size, pos, quat wxyz)."""
        self.objects[oid] = geoms
        self._build()

    def remove_object(self, oid: str) -> None:
        if oid not in self.objects:
            raise PlanningError(f"no collision object '{oid}' in the planning scene")
        del self.objects[oid]
        self._build()

    # ------------------------------------------------------------------ checks
    def _collide(self, q: np.ndarray) -> None:
        """Pose the group's moving links at q and run MuJoCo's collision detection."""
        self.kin.set(q)
        kd, qpos = self.kin.data, self.data.qpos
        for (b, _), a in self.moving_links:
            # the root stays at the origin of the kinematics model (spawned there)
            qpos[a : a + 3] = kd.xpos[b]
            mujoco.mju_mat2Quat(qpos[a + 3 : a + 7], kd.xmat[b])
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_collision(self.model, self.data)

    def contacts(self, q: np.ndarray) -> list[tuple[str, str]]:
        """Pairs of names (links, ``world#k``, ``object:id``) in contact with the group at q."""
        self._collide(q)
        out = []
        m = self.model
        for c in self.data.contact[: self.data.ncon]:
            if c.dist > 0:
                continue
            a, b = m.body(m.geom_bodyid[c.geom[0]]).name, m.body(m.geom_bodyid[c.geom[1]]).name
            out.append((a, b))
        return out

    def is_valid(self, q: np.ndarray) -> bool:
        """No contact at q (the fast path of ``contacts``: no per-contact Python objects)."""
        self._collide(q)
        n = self.data.ncon
        return n == 0 or not bool(np.any(self.data.contact.dist[:n] <= 0))


def _rotate(quat_wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    out = np.zeros(3)
    mujoco.mju_rotVecQuat(out, np.asarray(v, float), np.asarray(quat_wxyz, float))
    return out
