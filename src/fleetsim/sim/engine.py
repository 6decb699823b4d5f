"""The physics and sensing core: one MuJoCo model of the world and every spawned model.

``Engine`` has no runtime dependency: build it, spawn robots, ``advance(dt)`` and read the
sensor readings it returns, query poses and contacts. Spawning and deleting recompile the spec
with ``MjSpec.recompile``, which carries the state of everything else over by name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.sim import sdf
from fleetsim.sim.build import add_sdf_model, spec_from_world
from fleetsim.sim.contacts import sync_floor_pairs
from fleetsim.sim.drives import DriveBatch
from fleetsim.sim.health import SolverGuard, WarningWatch, physics_error, route_mujoco_warnings
from fleetsim.sim.lasers import LaserBatch
from fleetsim.sim.plugins import base
from fleetsim.sim.plugins.diff_drive import WheeledDrive
from fleetsim.sim.plugins.link_attacher import LinkAttacher
from fleetsim.sim.queries import StateQueries
from fleetsim.sim.robot_build import add_robot
from fleetsim.sim.schedule import SensorSchedule
from fleetsim.sim.world import WALL_HEIGHT, ModelDesc, Pose, WorldDesc, world_from_map


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


def load_world(
    source: str | Path | WorldDesc | None, wall_height: float = WALL_HEIGHT
) -> WorldDesc:
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


class Engine(StateQueries):
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
        timestep: float = 0.004,
        rng: np.random.Generator | None = None,
        wall_height: float = WALL_HEIGHT,
    ) -> None:
        route_mujoco_warnings()
        self.world = load_world(world, wall_height)
        self.wall_height = wall_height
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.spec, bodies = spec_from_world(self.world, timestep)
        self.models: dict[str, ModelEntry] = {
            m.name: ModelEntry(m.name, "world", m.static, bodies[m.name], m.pose, desc=m)
            for m in self.world.models
        }
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None
        self.attacher = LinkAttacher()
        self.lasers = LaserBatch(noise_key=int(self.rng.integers(2**63)))
        self.drives = DriveBatch()
        self.paused = False
        self.schedule = SensorSchedule()
        #: constants of batched measurements (body ids, offsets, noise) per set of plugins,
        #: keyed by (kind, plugin ids); body ids change with every compile, which clears it
        self.layouts: dict[tuple, Any] = {}
        self._renderers: dict[tuple[int, int], mujoco.Renderer] = {}
        self._compile()
        self._qpos0 = self.data.qpos.copy()

    # -------------------------------------------------------------------- building
    def _compile(self) -> None:
        sync_floor_pairs(self.spec)  # floor contacts of the models added or removed (sim.contacts)
        try:
            if self.model is None:
                self.model = self.spec.compile()
                self.data = mujoco.MjData(self.model)
            else:
                self.model, self.data = self.spec.recompile(self.model, self.data)
        except ValueError as exc:
            raise SimulationError(f"MuJoCo cannot compile the world: {exc}") from exc
        self.drives.sync_back()
        self._warnings = WarningWatch(self.data)
        self.solver_guard = SolverGuard(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        self.layouts.clear()
        self._index()
        for r in self._renderers.values():
            r.close()
        self._renderers.clear()
        for entry in self.models.values():
            for p in entry.plugins:
                p.bind(self)
        self.lasers.bind(self)
        self._schedule()

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
        # geoms of static models sit in the world body (planes in bodies of their own), named
        # "<model>/<link>/..."
        self._model_is_robot = np.array([e.kind == "robot" for e in self.models.values()], bool)
        index = {name: i for i, name in enumerate(self._model_names)}
        for g in np.flatnonzero(self.geom_model < 0):
            self.geom_model[g] = index.get(m.geom(int(g)).name.split("/", 1)[0], -1)

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
        return self.spawn_robots([(name, robot, pose, namespace, tf_prefix)])[0]

    def spawn_robots(self, robots: list[tuple]) -> list[ModelEntry]:
        """Spawn many robots with one recompile: ``[(name, robot, pose[, ns[, tf_prefix]])]``.

        All or nothing: when one fails, none is added.
        """
        added: list[tuple[ModelEntry, int]] = []
        try:
            for item in robots:
                added.append(self._add_robot(*item))
            self._compile()
        except Exception:
            for entry, n_act in reversed(added):
                self.models.pop(entry.name, None)
                self._remove_from_spec(entry, n_act)
            if added:
                self._compile()
            raise
        return [entry for entry, _ in added]

    def _check_on_map(self, name: str, pose) -> None:
        """A map world is walls extruded over its map and an empty floor beyond: a robot placed
        off the map (a start meant for another world) would drive, map and explore an endless
        empty floor, so it is refused, naming the pose and the map's extent."""
        grid = self.world.occupancy
        if grid is None:
            return
        ox, oy, oyaw = grid.origin
        dx, dy = pose[0] - ox, pose[1] - oy
        u = math.cos(oyaw) * dx + math.sin(oyaw) * dy  # in the map's own frame
        v = -math.sin(oyaw) * dx + math.cos(oyaw) * dy
        h, w = grid.occupied.shape
        width, height = w * grid.resolution, h * grid.resolution
        if 0.0 <= u <= width and 0.0 <= v <= height:
            return
        where = f"x {ox:g}..{ox + width:g}, y {oy:g}..{oy + height:g}"
        if oyaw:
            where += f" before the origin's yaw {oyaw:g} rad"
        raise SimulationError(
            f"model '{name}': its spawn pose ({pose[0]:g}, {pose[1]:g}) is outside the map of "
            f"world {grid.source} ({where}); a map world has nothing there but an empty floor"
        )

    def _add_robot(self, name, robot, pose=(0, 0, 0, 0, 0, 0), namespace=None, tf_prefix=None):
        self._check_new_name(name)
        if isinstance(robot, str | Path):
            from fleetsim.description import load_robot

            robot = load_robot(robot)
        ns = namespace if namespace is not None else f"/{name}"
        prefix = tf_prefix if tf_prefix is not None else ns.strip("/")
        pose0 = tuple(float(v) for v in pose)
        self._check_on_map(name, pose0)
        entry = ModelEntry(
            name, "robot", False, [], pose0, robot=robot, namespace=ns, tf_prefix=prefix
        )
        entry.plugins = self._make_plugins(entry)
        n_act = len(self.spec.actuators)
        entry.bodies = [add_robot(self.spec, robot, name, pose0)]
        try:
            for p in entry.plugins:
                p.build(self.spec, self)
        except Exception:
            self._remove_from_spec(entry, n_act)
            raise
        entry.actuators = [a.name for a in self.spec.actuators[n_act:]]
        self.models[name] = entry
        return entry, n_act

    def _make_plugins(self, entry: ModelEntry) -> list[base.Plugin]:
        out: list[base.Plugin] = []
        robot = entry.robot

        def make(spec, *sensor) -> None:
            cls = base.plugin_class(spec.filename, f"model '{entry.name}'")
            if cls is not None:
                where = f"{robot.source}:{spec.source_line or '?'}"
                ctx = base.PluginContext(entry.name, entry.namespace, entry.tf_prefix, robot, where)
                plugin = cls(ctx, spec, *sensor)
                out.extend([plugin, *plugin.companions()])

        for block in robot.gazebo:
            for spec in block.plugins:
                make(spec)
            for sensor in block.sensors:
                for spec in sensor.plugins:
                    make(spec, sensor)
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
        prefix = f"{entry.name}/"
        for g in [g for g in self.spec.worldbody.geoms if g.name.startswith(prefix)]:
            self.spec.delete(g)
        for b in self.spec.worldbody.bodies:
            if b.name.startswith(prefix) and b.name.endswith(":plane"):
                self.spec.delete(b)
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
        self._compile()

    # -------------------------------------------------------------------- queries
    # -------------------------------------------------------------------- stepping
    def plugins(self) -> list[base.Plugin]:
        return [p for e in self.models.values() for p in e.plugins]

    def _schedule(self) -> None:
        """Refresh the plugin lists and the sensor schedule after the set of models changed."""
        self._plugins = self.plugins()
        self._controllers = [p for p in self._plugins if type(p).control is not base.Plugin.control]
        self.drives.bind([p for p in self._plugins if isinstance(p, WheeledDrive)], self)
        self.schedule.bind(self._plugins)

    def step(self) -> None:
        """One physics step: plugin controls, link attacher, ``mj_step``.

        A step on which the Newton solver stalled is redone with CG (``health.SolverGuard``).
        Raises `PhysicsInstability` (or `PhysicsBufferFull`) when MuJoCo flags the step
        (``sim.health``); the world is not reset and stays as the failed step left it.
        """
        t = self.time
        self.drives.control(self, t)
        for p in self._controllers:
            p.control(self, t)
        if self.attacher.pending:
            self.attacher.control(self, t)
        self.solver_guard.save(self.model, self.data)
        mujoco.mj_step(self.model, self.data)
        self.solver_guard.check(self.model, self.data)
        if self._warnings.tripped():
            raise physics_error(self, t)

    def advance(self, duration: float) -> list[Any]:
        """Step physics for ``duration`` seconds; returns the readings that fell due.

        While paused, neither time nor sensors advance (as in Gazebo).
        """
        if self.paused:
            return []
        readings: list[Any] = []
        n = round(duration / self.model.opt.timestep)
        for _ in range(n):
            self.step()
            if self.time + 1e-9 >= self.schedule.next:
                readings += self.due_readings()
        mujoco.mj_kinematics(self.model, self.data)  # poses of the current state for queries
        return readings

    def due_readings(self) -> list[Any]:
        """Readings of every sensor/drive whose update time has come (``sim.schedule``)."""
        return self.schedule.readings(self, self.time)

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
