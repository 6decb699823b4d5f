"""Plugin base classes (one per kind) and the Gazebo-filename registry.

A plugin is built from a URDF ``<gazebo><plugin>`` tag (``PluginSpec``), and, for sensors, the
enclosing ``<sensor>`` (``SensorSpec``). Parameters keep the gazebo_ros names and defaults and
are declared once per plugin in a frozen dataclass (``fleetsim.runtime.param``); the XML text is
converted to the declared type here, so a wrong type is reported naming the parameter and the
model. Plugins are pure simulation objects: they read and drive the ``Engine`` and return
*readings* (plain dataclasses with NumPy arrays); the ``Simulator`` node turns readings into
messages. Kinds:

- ``DrivePlugin``: ``command(vx, wz, t)``, ``control(engine, t)`` before each physics step,
  ``measure(engine, t) -> OdometryReading``.
- ``SensorPlugin``: ``measure(engine, t) -> reading`` at ``update_rate``.
- ``ActuatorPlugin``: joint commands applied in ``control``.

A class may also measure many of its plugins in one call (``sim.schedule`` says when and in
what order): the classmethod ``measure_each(engine, plugins, t)`` returns, for each plugin,
what ``measure`` would (drives, joint states); ``measure_batch(engine, plugins, t)`` does the
same with its readings placed after the others (p3d).
"""

from __future__ import annotations

import dataclasses
import logging
import typing
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from fleetsim.errors import ParameterError, SimulationError, did_you_mean
from fleetsim.runtime.params import describe_params, load_params

_log = logging.getLogger("fleetsim.sim.plugins")

REGISTRY: dict[str, type[Plugin]] = {}


def register(*filenames: str):
    """Class decorator: map Gazebo plugin filenames (``libgazebo_ros_*.so``) to a class."""

    def deco(cls):
        for f in filenames:
            REGISTRY[f] = cls
        cls.filenames = filenames
        return cls

    return deco


@dataclass
class PluginContext:
    """What a plugin knows about the model it belongs to."""

    model: str  # model name (body prefix ``<model>/``)
    namespace: str  # ROS namespace of the robot's topics ("/lizi1" or "/")
    tf_prefix: str  # tf_prefix applied to frame names ("lizi1" or "")
    robot: Any  # fleetsim.description Robot
    source: str = ""  # file:line of the plugin tag, for messages

    def frame(self, name: str) -> str:
        """tf::resolve(tf_prefix, name): ``/map`` -> ``map``; ``odom`` -> ``lizi1/odom``."""
        if name.startswith("/"):
            return name.lstrip("/")
        return f"{self.tf_prefix}/{name}" if self.tf_prefix else name


def _from_text(text: Any, tp: Any, key: str, where: str) -> Any:
    if not isinstance(text, str):
        return text
    s = text.strip()
    try:
        if tp is bool:
            if s.lower() in ("1", "true"):
                return True
            if s.lower() in ("0", "false"):
                return False
            raise ValueError
        if tp is float:
            return float(s)
        if tp is int:
            return int(s)
        if typing.get_origin(tp) is tuple:
            return tuple(float(v) for v in s.split())
    except ValueError:
        raise ParameterError(
            f"{where}: parameter '{key}' must be {getattr(tp, '__name__', 'numbers')}, got '{s}'"
        ) from None
    return s


def plugin_params(cls: type, raw: dict[str, Any], where: str, ignore=()) -> Any:
    """Typed, validated parameters from a plugin tag's child elements (strings)."""
    types = {i.name: i.type for i in describe_params(cls)}
    aliases = {a: i.name for i in describe_params(cls) for a in i.aliases}
    values = {}
    for key, text in raw.items():
        name = aliases.get(key, key)
        if name in types:
            values[key] = _from_text(text, types[name], key, where)
        elif key not in ignore:
            _log.warning("%s: unknown parameter '%s'%s", where, key, did_you_mean(key, types))
    return load_params(cls, values, where, logger=_log)


def require_joint(ctx: PluginContext, joint: str, param: str, plugin: str) -> str:
    """Check the model has a movable joint ``joint`` (named by ``param``); error otherwise."""
    joints = ctx.robot.joints if ctx.robot is not None else {}
    if joint not in joints or joints[joint].type == "fixed":
        names = [n for n, j in joints.items() if j.type != "fixed"]
        what = "a fixed joint" if joint in joints else "a joint the model lacks"
        raise SimulationError(
            f"{ctx.source}: plugin '{plugin}' of model '{ctx.model}': {param} names '{joint}', "
            f"{what}{did_you_mean(joint, names)}"
        )
    return joint


def require_link(ctx: PluginContext, link: str | None, what: str, plugin: str) -> str:
    """Check the model has a link ``link``; error otherwise."""
    links = ctx.robot.links if ctx.robot is not None else {}
    if link not in links:
        raise SimulationError(
            f"{ctx.source}: plugin '{plugin}' of model '{ctx.model}': {what} names link "
            f"'{link}', which the model lacks{did_you_mean(str(link), links)}"
        )
    return link


def joint_addresses(engine, model: str, joints: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """qpos and dof addresses of a model's hinge/slide joints."""
    ids = [engine.joint_id(model, j) for j in joints]
    m = engine.model
    return (
        np.array([m.jnt_qposadr[i] for i in ids], np.int64),
        np.array([m.jnt_dofadr[i] for i in ids], np.int64),
    )


class Plugin:
    """Base of every simulator plugin."""

    Params: ClassVar[type]
    filenames: ClassVar[tuple[str, ...]] = ()
    kind: ClassVar[str] = "plugin"

    def __init__(self, ctx: PluginContext, spec: Any, sensor: Any = None) -> None:
        self.ctx = ctx
        self.spec = spec
        self.sensor = sensor
        self.name = spec.name
        self.where = f"{ctx.source or ctx.model}: model '{ctx.model}' plugin '{spec.name}'"
        self.params = plugin_params(
            self.Params,
            dict(spec.params),
            self.where,
            ignore=("robotNamespace", "alwaysOn", "always_on"),
        )

    def companions(self) -> list[Plugin]:
        """Plugins this one brings along (a diff drive's wheel joint states), made with it."""
        return []

    def build(self, spec, engine) -> None:
        """Add what the plugin needs to the MuJoCo spec (actuators, cameras) before compiling."""

    def bind(self, engine) -> None:
        """Resolve model indices (joints, bodies) after each (re)compile of the world."""

    def reset(self) -> None:
        """Forget internal state (reset_simulation / reset_world)."""

    def control(self, engine, t: float) -> None:
        """Apply commands before a physics step (drives and actuators)."""

    @property
    def update_rate(self) -> float:
        return 0.0

    def measure(self, engine, t: float) -> Any:
        """A reading at sim time ``t`` (sensors and drives), or None."""
        return None


class DrivePlugin(Plugin, ABC):
    kind = "drive"

    @abstractmethod
    def command(self, vx: float, wz: float, t: float) -> None:
        """Take a velocity command (cmd_vel's linear.x m/s, angular.z rad/s) at sim time t."""


class SensorPlugin(Plugin):
    kind = "sensor"


class ActuatorPlugin(Plugin):
    kind = "actuator"


# ------------------------------------------------------------------------------------------
# readings: plain data the node layer converts into messages


@dataclass
class OdometryReading:
    stamp: float
    topic: str
    frame_id: str
    child_frame_id: str
    position: np.ndarray  # (3,) m
    orientation: np.ndarray  # (4,) quaternion x, y, z, w
    linear: np.ndarray  # (3,) m/s in child frame
    angular: np.ndarray  # (3,) rad/s in child frame
    publish_tf: bool = True
    covariance: float = 0.0  # diagonal pose/twist covariance
    namespace: str = "/"  # ROS namespace the topic resolves in (set by the engine)


@dataclass
class ScanReading:
    stamp: float
    topic: str
    frame_id: str
    angle_min: float
    angle_max: float
    angle_increment: float
    time_increment: float
    scan_time: float
    range_min: float
    range_max: float
    # (N,) float32 m, inf where nothing is hit; or a function giving them, called when the
    # ranges are first read (the laser batch casts a reading only when someone reads it)
    source: np.ndarray | Callable[[], np.ndarray]
    intensities: np.ndarray = field(default_factory=lambda: np.zeros(0, np.float32))
    namespace: str = "/"  # ROS namespace the topic resolves in (set by the engine)

    @property
    def ranges(self) -> np.ndarray:
        if callable(self.source):
            self.source = self.source()
        return self.source

    @property
    def cast(self) -> bool:
        """Whether the ranges exist yet (read, or given as an array)."""
        return not callable(self.source)


@dataclass
class ImageReading:
    stamp: float
    topic: str
    info_topic: str
    frame_id: str
    encoding: str  # "rgb8" | "32FC1"
    image: np.ndarray  # (H, W, 3) uint8 or (H, W) float32 m
    K: np.ndarray  # (3, 3) intrinsics
    depth_topic: str = ""
    depth_info_topic: str = ""
    depth: np.ndarray | None = None  # (H, W) float32 m, for depth cameras
    cloud_topic: str = ""  # depth cameras: the XYZRGB point cloud topic
    namespace: str = "/"  # ROS namespace the topic resolves in (set by the engine)


@dataclass
class TransformsReading:
    """Transforms for ``/tf`` (a diff drive's ``publishWheelTF``): (parent frame, child frame,
    position (3,) m, quaternion (x, y, z, w)) each, frames with the tf_prefix applied."""

    stamp: float
    transforms: list[tuple[str, str, np.ndarray, np.ndarray]]
    namespace: str = "/"


@dataclass
class JointStateReading:
    stamp: float
    topic: str
    names: list[str]
    position: np.ndarray
    velocity: np.ndarray
    effort: np.ndarray
    namespace: str = "/"  # ROS namespace the topic resolves in (set by the engine)


def plugin_class(filename: str, where: str = "") -> type[Plugin] | None:
    """The class registered for a Gazebo filename; None (with a logged warning) when unknown.

    The warning goes to the log only: it also went through `warnings.warn`, so the command
    line printed it twice (once by its log handler, once as a Python warning)."""
    cls = REGISTRY.get(filename)
    if cls is None:
        _log.warning(
            "%sunknown plugin filename '%s'%s; ignored, the model spawns without it",
            where + ": " if where else "",
            filename,
            did_you_mean(filename, REGISTRY),
        )
    return cls


def all_param_docs() -> dict[str, list]:
    """Declared parameters of every registered plugin (for docs)."""
    return {
        f: describe_params(c.Params)
        for f, c in REGISTRY.items()
        if dataclasses.is_dataclass(c.Params)
    }
