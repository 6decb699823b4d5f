"""The physics and sensing core: one MuJoCo model of the world and every spawned model.

``Engine`` has no runtime dependency: build it, spawn robots, ``advance(dt)`` and read the
sensor readings it returns, query poses and contacts. Spawning and deleting recompile the spec
with ``MjSpec.recompile``, which carries the state of everything else over by name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from fleetsim.errors import SimulationError, did_you_mean
from fleetsim.sim import sdf
from fleetsim.sim.build import add_sdf_model, quat_from_rpy, spec_from_world
from fleetsim.sim.lasers import LaserBatch
from fleetsim.sim.plugins import base
from fleetsim.sim.plugins.link_attacher import LinkAttacher
from fleetsim.sim.robot_build import add_robot
from fleetsim.sim.world import ModelDesc, Pose, WorldDesc, world_from_map


@dataclass
class ModelEntry:
    """A model in the world: the world's own (SDF) models, spawned SDF models and robots."""

    name: str
    kind: str  # "world" | "sdf" | "robot"
    static: bool
    bodies: list[str]  # top-level body names
    pose0: Pose
    robot: Any = None
    desc: ModelDesc | None = None
    namespace: str = "/"
    tf_prefix: str = ""
    plugins: list[base.Plugin] = field(default_factory=list)
    actuators: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Contact:
    """A contact between a robot and something else (not the floor)."""

    model1: str
    link1: str
    model2: str
    link2: str
    position: tuple[float, float, float]
    depth: float  # penetration, m (positive when overlapping)


def load_world(source: str | Path | WorldDesc | None, wall_height: float = 1.0) -> WorldDesc:
    """A ``WorldDesc`` from an SDF ``.world`` file, a map ``.yaml`` file, or None (empty)."""
    if source is None:
        from fleetsim.sim.world import ground_plane, sun

        return WorldDesc("empty", [ground_plane()], [sun()], source="<empty>")
    if isinstance(source, WorldDesc):
        return source
    path = Path(source)
    if not path.exists():
        raise SimulationError(f"world file '{path}' not found")
    if path.suffix in (".yaml", ".yml"):
        return world_from_map(path, wall_height)
    return sdf.load_sdf_world(path)


class Engine:
    """MuJoCo world plus models, plugins and sensor scheduling.

    Parameters
    ----------
    world : an SDF world file, a map_server YAML (extruded walls), a ``WorldDesc`` or None.
    timestep : physics step, s.
    rng : the seeded generator sensor noise draws from (required for reproducible noise).
    """

    def __init__(
        self,
        world=None,
        timestep: float = 0.002,
        rng: np.random.Generator | None = None,
        wall_height: float = 1.0,
    ) -> None:
        self.world = load_world(world, wall_height)
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.spec, bodies = spec_from_world(self.world, timestep)
        self.models: dict[str, ModelEntry] = {
            m.name: ModelEntry(m.name, "world", m.static, bodies[m.name], m.pose, desc=m)
            for m in self.world.models
        }
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None
        self.attacher = LinkAttacher()
        self.lasers = LaserBatch()
        self.paused = False
        self._next_due: dict[int, float] = {}
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}
        self._compile()
        self._qpos0 = self.data.qpos.copy()

    # -------------------------------------------------------------------- building
    def _compile(self) -> None:
        try:
            if self.model is None:
                self.model = self.spec.compile()
                self.data = mujoco.MjData(self.model)
            else:
                self.model, self.data = self.spec.recompile(self.model, self.data)
        except ValueError as exc:
            raise SimulationError(f"MuJoCo cannot compile the world: {exc}") from exc
        mujoco.mj_forward(self.model, self.data)
        self._index()
        for r in self._renderers.values():
            r.close()
        self._renderers.clear()
        for entry in self.models.values():
            for p in entry.plugins:
                p.bind(self)
        self.attacher.bind(self)
        self.lasers.bind(self)

    def _index(self) -> None:
        m = self.model
        self._body_model = np.full(m.nbody, -1, np.int64)
        self._model_names = list(self.models)
        top = {}
        for i, entry in enumerate(self.models.values()):
            for b in entry.bodies:
                top[m.body(b).id] = i
        for b in range(1, m.nbody):
            self._body_model[b] = top.get(int(m.body_rootid[b]), -1)
        self.geom_model = self._body_model[m.geom_bodyid]

    def _check_new_name(self, name: str) -> None:
        if not name or "/" in name:
            raise SimulationError(f"model name '{name}' must be non-empty and without '/'")
        if name in self.models:
            raise SimulationError(
                f"a model named '{name}' already exists; delete it or choose another name"
            )

    def spawn_robot(
        self,
        name: str,
        robot: Any,
        pose: Pose = (0, 0, 0, 0, 0, 0),
        namespace: str | None = None,
        tf_prefix: str | None = None,
    ) -> ModelEntry:
        """Spawn a URDF robot (a ``fleetsim.description`` Robot, or a .urdf/.xacro path).

        Topics go under ``namespace`` (default ``/<name>``) and frames under ``tf_prefix``
        (default: the namespace without its leading slash).
        """
        self._check_new_name(name)
        if isinstance(robot, str | Path):
            from fleetsim.description import load_robot

            robot = load_robot(robot)
        ns = namespace if namespace is not None else f"/{name}"
        prefix = tf_prefix if tf_prefix is not None else ns.strip("/")
        entry = ModelEntry(
            name,
            "robot",
            False,
            [],
            tuple(float(v) for v in pose),
            robot=robot,
            namespace=ns,
            tf_prefix=prefix,
        )
        entry.plugins = self._make_plugins(entry)
        root = add_robot(self.spec, robot, name, entry.pose0)
        entry.bodies = [root]
        n_act = len(self.spec.actuators)
        try:
            for p in entry.plugins:
                p.build(self.spec, self)
        except Exception:
            self._remove_from_spec(entry, n_act)
            raise
        entry.actuators = [a.name for a in self.spec.actuators[n_act:]]
        self.models[name] = entry
        try:
            self._compile()
        except SimulationError:
            del self.models[name]
            self._remove_from_spec(entry, n_act)
            self._compile()
            raise
        return entry

    def _make_plugins(self, entry: ModelEntry) -> list[base.Plugin]:
        out: list[base.Plugin] = []
        robot = entry.robot
        for block in robot.gazebo:
            for spec in block.plugins:
                cls = base.plugin_class(spec.filename)
                if cls is not None:
                    ctx = base.PluginContext(
                        entry.name,
                        entry.namespace,
                        entry.tf_prefix,
                        robot,
                        f"{robot.source}:{spec.source_line or '?'}",
                    )
                    out.append(cls(ctx, spec))
            for sensor in block.sensors:
                for spec in sensor.plugins:
                    cls = base.plugin_class(spec.filename)
                    if cls is not None:
                        ctx = base.PluginContext(
                            entry.name,
                            entry.namespace,
                            entry.tf_prefix,
                            robot,
                            f"{robot.source}:{spec.source_line or '?'}",
                        )
                        out.append(cls(ctx, spec, sensor))
        return out

    def spawn_sdf(self, name: str, model: ModelDesc | str, pose: Pose | None = None) -> ModelEntry:
        """Spawn an SDF model (a ``ModelDesc`` or SDF text holding one ``<model>``)."""
        self._check_new_name(name)
        desc = sdf.load_sdf_model(model) if isinstance(model, str) else model
        desc.name = name
        pose = tuple(float(v) for v in (pose if pose is not None else desc.pose))
        bodies = add_sdf_model(self.spec, desc, pose)
        entry = ModelEntry(name, "sdf", desc.static, bodies, pose, desc=desc)
        self.models[name] = entry
        self._compile()
        return entry

    def _remove_from_spec(self, entry: ModelEntry, n_act: int | None = None) -> None:
        for b in entry.bodies:
            body = self.spec.body(b)
            if body is not None:
                self.spec.delete(body)
        acts = (
            self.spec.actuators[n_act:]
            if n_act is not None
            else [self.spec.actuator(a) for a in entry.actuators]
        )
        for a in list(acts):
            if a is not None:
                self.spec.delete(a)

    def delete_model(self, name: str) -> None:
        """Remove a model; the state of everything else is kept."""
        entry = self.entry(name)
        self.attacher.forget_model(self, name)
        self._remove_from_spec(entry)
        del self.models[name]
        for p in entry.plugins:
            self._next_due.pop(id(p), None)
        self._compile()

    # -------------------------------------------------------------------- queries
    def entry(self, name: str) -> ModelEntry:
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
        return self.model.body(self.entry(name).bodies[0]).id

    def model_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """World position (3,) m and orientation quaternion (w, x, y, z) of the model root."""
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
        if self.model.body_jntnum[b] == 0:
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
        out = []
        m, d = self.model, self.data
        names = self._model_names
        plane = mujoco.mjtGeom.mjGEOM_PLANE
        for c in d.contact[: d.ncon] if d.ncon else []:
            g1, g2 = int(c.geom1), int(c.geom2)
            if m.geom_type[g1] == plane or m.geom_type[g2] == plane:
                continue
            i1, i2 = self.geom_model[g1], self.geom_model[g2]
            if i1 == i2:
                continue
            e1 = self.models[names[i1]] if i1 >= 0 else None
            e2 = self.models[names[i2]] if i2 >= 0 else None
            if not ((e1 and e1.kind == "robot") or (e2 and e2.kind == "robot")):
                continue
            b1, b2 = m.body(int(m.geom_bodyid[g1])).name, m.body(int(m.geom_bodyid[g2])).name
            out.append(
                Contact(
                    names[i1] if i1 >= 0 else "world",
                    b1.split("/", 1)[-1],
                    names[i2] if i2 >= 0 else "world",
                    b2.split("/", 1)[-1],
                    tuple(float(v) for v in c.pos),
                    float(-c.dist),
                )
            )
        return out

    # -------------------------------------------------------------------- stepping
    def plugins(self) -> list[base.Plugin]:
        return [p for e in self.models.values() for p in e.plugins]

    def step(self) -> None:
        """One physics step: plugin controls, link attacher, ``mj_step``."""
        t = self.time
        for e in self.models.values():
            for p in e.plugins:
                p.control(self, t)
        self.attacher.control(self, t)
        mujoco.mj_step(self.model, self.data)

    def advance(self, duration: float) -> list[Any]:
        """Step physics for ``duration`` seconds; returns the readings that fell due."""
        readings: list[Any] = []
        n = round(duration / self.model.opt.timestep)
        for _ in range(n):
            if not self.paused:
                self.step()
            readings += self.due_readings()
        mujoco.mj_kinematics(self.model, self.data)  # poses of the current state for queries
        return readings

    def due_readings(self) -> list[Any]:
        """Readings of every sensor/drive whose update time has come (lasers batched)."""
        t = self.time
        out: list[Any] = []
        lasers = []
        for p in self.plugins():
            rate = p.update_rate
            key = id(p)
            due = self._next_due.get(key, 0.0)
            if t + 1e-9 < due:
                continue
            self._next_due[key] = t + (1.0 / rate if rate > 0 else 0.0)
            if getattr(p, "is_laser", False):
                lasers.append(p)
            else:
                r = p.measure(self, t)
                if r is not None:
                    out.append(r)
        if lasers:
            out += self.lasers.measure(self, lasers, t)
        return out

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
        self._next_due.clear()

    def world_properties(self) -> dict[str, Any]:
        return {"sim_time": self.time, "model_names": list(self.models), "rendering_enabled": True}

    # -------------------------------------------------------------------- rendering
    def renderer(self, width: int, height: int) -> mujoco.Renderer:
        key = (width, height)
        if key not in self._renderers:
            self._renderers[key] = mujoco.Renderer(self.model, height, width)
        return self._renderers[key]

    def close(self) -> None:
        for r in self._renderers.values():
            r.close()
        self._renderers.clear()
