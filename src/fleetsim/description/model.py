"""The robot model: dataclasses for a URDF robot (links, joints, materials, Gazebo extensions).

Everything here is plain data. Parsing lives in :mod:`fleetsim.description.urdf`, writing back to
URDF text in :mod:`fleetsim.description.urdf_writer`. Lengths are metres, angles radians, masses
kilograms, inertias kg·m², all expressed in the frame given by the element's ``origin``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from fleetsim.errors import DescriptionError

Vec3 = tuple[float, float, float]
Vec4 = tuple[float, float, float, float]

JOINT_TYPES = ("fixed", "revolute", "continuous", "prismatic", "floating", "planar")


@dataclass(frozen=True)
class Origin:
    """A pose relative to a parent frame: translation ``xyz`` (m) and fixed-axis ``rpy`` (rad)."""

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Box:
    size: Vec3


@dataclass(frozen=True)
class Cylinder:
    """A cylinder along the local z axis."""

    radius: float
    length: float


@dataclass(frozen=True)
class Sphere:
    radius: float


@dataclass(frozen=True)
class Mesh:
    """A mesh file; ``filename`` is an absolute path once ``package://`` has been resolved."""

    filename: str
    scale: Vec3 = (1.0, 1.0, 1.0)


Geometry = Box | Cylinder | Sphere | Mesh


@dataclass(frozen=True)
class Material:
    name: str
    rgba: Vec4 | None = None
    texture: str | None = None


@dataclass(frozen=True)
class Inertial:
    """Mass (kg) and the inertia tensor (kg·m²) about the centre of mass at ``origin``."""

    mass: float
    origin: Origin = Origin()
    ixx: float = 0.0
    ixy: float = 0.0
    ixz: float = 0.0
    iyy: float = 0.0
    iyz: float = 0.0
    izz: float = 0.0


@dataclass(frozen=True)
class Visual:
    origin: Origin
    geometry: Geometry
    material: Material | None = None
    name: str | None = None


@dataclass(frozen=True)
class Collision:
    origin: Origin
    geometry: Geometry
    name: str | None = None


@dataclass
class Link:
    name: str
    inertial: Inertial | None = None
    visuals: list[Visual] = field(default_factory=list)
    collisions: list[Collision] = field(default_factory=list)
    source_line: int | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Limit:
    """Joint limits: position (rad or m), effort (N·m or N), velocity (rad/s or m/s)."""

    lower: float = 0.0
    upper: float = 0.0
    effort: float = 0.0
    velocity: float = 0.0


@dataclass(frozen=True)
class Dynamics:
    damping: float = 0.0
    friction: float = 0.0


@dataclass(frozen=True)
class Mimic:
    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: Origin = Origin()
    axis: Vec3 = (1.0, 0.0, 0.0)
    limit: Limit | None = None
    dynamics: Dynamics | None = None
    mimic: Mimic | None = None
    source_line: int | None = field(default=None, compare=False)


@dataclass
class PluginSpec:
    """A Gazebo ``<plugin>``: child elements as params, nested elements as dicts.

    A tag repeated inside one element becomes a list of its values.
    """

    name: str
    filename: str
    params: dict[str, str | dict | list] = field(default_factory=dict)
    source_line: int | None = field(default=None, compare=False)


@dataclass
class SensorSpec:
    """A Gazebo ``<sensor>`` inside ``<gazebo reference="link">``.

    ``ray`` and ``camera`` hold the raw nested dicts of the ``<ray>`` and ``<camera>`` elements
    (e.g. ``{'scan': {'horizontal': {'samples': '720', ...}}, 'range': {...}}``); ``extra`` holds
    every other child element (``imu``, ``noise`` ...) the same way.
    """

    name: str
    type: str
    reference: str | None
    update_rate: float = 0.0
    always_on: bool = False
    visualize: bool = False
    pose: Origin = Origin()
    ray: dict | None = None
    camera: dict | None = None
    extra: dict = field(default_factory=dict)
    plugins: list[PluginSpec] = field(default_factory=list)
    source_line: int | None = field(default=None, compare=False)


@dataclass
class GazeboBlock:
    """A ``<gazebo>`` element; ``xml`` keeps its original text so export is lossless."""

    reference: str | None
    properties: dict[str, str] = field(default_factory=dict)
    plugins: list[PluginSpec] = field(default_factory=list)
    sensors: list[SensorSpec] = field(default_factory=list)
    xml: str = field(default="", compare=False)
    source_line: int | None = field(default=None, compare=False)


@dataclass
class Transmission:
    """A ros_control ``<transmission>``.

    ``joints`` are ``(joint_name, hardware_interface)``; ``actuators`` are
    ``(actuator_name, mechanical_reduction)``.
    """

    name: str
    type: str
    joints: list[tuple[str, str]] = field(default_factory=list)
    actuators: list[tuple[str, float]] = field(default_factory=list)
    xml: str = field(default="", compare=False)
    source_line: int | None = field(default=None, compare=False)


@dataclass
class Robot:
    """A whole robot description. ``source`` names the file (or ``<string>``) it came from."""

    name: str
    links: dict[str, Link] = field(default_factory=dict)
    joints: dict[str, Joint] = field(default_factory=dict)
    materials: dict[str, Material] = field(default_factory=dict)
    gazebo: list[GazeboBlock] = field(default_factory=list)
    transmissions: list[Transmission] = field(default_factory=list)
    source: str = "<string>"

    def root_link(self) -> str:
        """The name of the one link that is no joint's child."""
        children = {j.child for j in self.joints.values()}
        roots = [name for name in self.links if name not in children]
        if len(roots) != 1:
            raise DescriptionError(
                f"{self.source}: robot '{self.name}' has {len(roots)} root links {roots}; "
                "a URDF tree needs exactly one"
            )
        return roots[0]

    def children(self, link: str) -> list[Joint]:
        """Joints whose parent is ``link``, in document order."""
        self._require_link(link)
        return [j for j in self.joints.values() if j.parent == link]

    def parent_joint(self, link: str) -> Joint | None:
        """The joint whose child is ``link``, or ``None`` for the root."""
        self._require_link(link)
        for j in self.joints.values():
            if j.child == link:
                return j
        return None

    def gazebo_for(self, reference: str | None) -> list[GazeboBlock]:
        """Gazebo blocks with this ``reference`` (``None``: the robot-level blocks)."""
        return [g for g in self.gazebo if g.reference == reference]

    def plugins(self) -> list[PluginSpec]:
        """Every model-level plugin (not the ones inside sensors), in document order."""
        return [p for g in self.gazebo for p in g.plugins]

    def sensors(self) -> list[SensorSpec]:
        """Every Gazebo sensor, in document order."""
        return [s for g in self.gazebo for s in g.sensors]

    def to_urdf(self) -> str:
        """URDF XML text for this robot (Gazebo and transmission blocks kept verbatim)."""
        from fleetsim.description.urdf_writer import urdf_from_robot

        return urdf_from_robot(self)

    def _require_link(self, link: str) -> None:
        if link not in self.links:
            from fleetsim.errors import did_you_mean

            raise DescriptionError(
                f"{self.source}: robot '{self.name}' has no link '{link}'"
                f"{did_you_mean(link, self.links)}"
            )
