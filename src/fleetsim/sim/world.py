"""World descriptions: what an SDF file or an extruded map says, before MuJoCo sees it.

``WorldDesc`` is the neutral form both world sources produce (``sdf.load_sdf_world``,
``world_from_map``) and ``build.spec_from_world`` turns into an ``MjSpec``. Poses are
``(x, y, z, roll, pitch, yaw)`` in metres and radians, relative to the parent (SDF convention).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fleetsim.sim.mapworld import OccupancyMap, boundary_boxes, load_map, wall_boxes
from fleetsim.sim.sdf_poses import ZERO_POSE, Pose

#: walls extruded from a map are building walls: taller than any robot's sensors (the lesson
#: mounts lizi's laser 1 m up)
WALL_HEIGHT = 2.0


@dataclass
class GeomDesc:
    """One collision or visual shape. ``size`` by kind: box (sx, sy, sz) full lengths;
    cylinder (radius, length); sphere (radius,); plane (sx, sy) with normal +z; mesh scale."""

    kind: str  # "box" | "cylinder" | "sphere" | "plane" | "mesh"
    size: tuple[float, ...]
    pose: Pose = ZERO_POSE
    name: str = ""
    collide: bool = True  # False: visual only
    rgba: tuple[float, float, float, float] | None = None
    texture: str | None = None  # image file applied to the shape's faces
    mesh: str | None = None  # mesh file for kind "mesh"
    friction: tuple[float, float] | None = None  # mu, mu2


@dataclass
class LinkDesc:
    name: str
    pose: Pose = ZERO_POSE
    mass: float = 1.0
    inertia: tuple[float, float, float] | None = None  # ixx, iyy, izz (kg m^2)
    geoms: list[GeomDesc] = field(default_factory=list)


@dataclass
class ModelDesc:
    name: str
    pose: Pose = ZERO_POSE
    static: bool = False
    links: list[LinkDesc] = field(default_factory=list)
    source: str = ""
    relative_to: str = ""  # frame the pose is expressed in until resolved ("": the parent's)
    #: poses of the model's links and SDF ``<frame>``s in the model frame (by name)
    frames: dict[str, Pose] = field(default_factory=dict)


@dataclass
class LightDesc:
    name: str
    pose: Pose = (0.0, 0.0, 10.0, 0.0, 0.0, 0.0)
    directional: bool = True
    direction: tuple[float, float, float] = (-0.5, 0.1, -0.9)
    diffuse: tuple[float, float, float] = (0.8, 0.8, 0.8)


@dataclass
class WorldPluginDesc:
    name: str
    filename: str
    params: dict[str, str] = field(default_factory=dict)


@dataclass
class WorldDesc:
    name: str = "default"
    models: list[ModelDesc] = field(default_factory=list)
    lights: list[LightDesc] = field(default_factory=list)
    plugins: list[WorldPluginDesc] = field(default_factory=list)
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.8)
    source: str = ""
    occupancy: OccupancyMap | None = None  # set for map worlds


def ground_plane(size: float = 100.0, centre: tuple[float, float] = (0.0, 0.0)) -> ModelDesc:
    """Gazebo's ``model://ground_plane``: a static 100 x 100 m plane (mu 100, mu2 50)."""
    geom = GeomDesc(
        "plane", (size, size), name="collision", rgba=(0.7, 0.7, 0.7, 1.0), friction=(100.0, 50.0)
    )
    return ModelDesc(
        "ground_plane",
        (centre[0], centre[1], 0.0, 0.0, 0.0, 0.0),
        static=True,
        links=[LinkDesc("link", geoms=[geom])],
        source="model://ground_plane",
    )


def sun() -> LightDesc:
    """Gazebo's ``model://sun``: a directional light 10 m up."""
    return LightDesc("sun", direction=(-0.5, 0.1, -0.9))


WALL_TILE = 4.0  # m, side of the square tiles map walls are grouped into


def world_from_map(
    yaml_path: str | Path, wall_height: float = WALL_HEIGHT, boundary: bool = True
) -> WorldDesc:
    """A world whose walls are the occupied cells of a map_server map (world frame = map frame).

    Occupied cells are merged into few boxes (``mapworld.rectangles_from_occupancy``), all in
    one static model ``map_walls`` whose links are square tiles of ``WALL_TILE`` metres (many
    small static bodies let MuJoCo's broad phase skip the walls far from a robot); with
    ``boundary`` (the default, as Stage's ``boundary 1``) a one-cell wall surrounds the map just
    outside its edges (``boundary_boxes``); a ground plane covering the map and a sun are added.
    """
    grid = load_map(yaml_path)
    boxes = wall_boxes(grid, wall_height)
    if boundary:
        boxes = np.concatenate([boxes, boundary_boxes(grid, wall_height, WALL_TILE)])
    geoms = [
        GeomDesc(
            "box",
            (2 * b[3], 2 * b[4], 2 * b[5]),
            (b[0], b[1], b[2], 0.0, 0.0, b[6]),
            name=f"wall_{i}",
            rgba=(0.55, 0.55, 0.6, 1.0),
        )
        for i, b in enumerate(boxes)
    ]
    h, w = grid.occupied.shape
    extent = float(max(h, w) * grid.resolution) + 20.0
    if len(boxes):
        lo, hi = boxes[:, :2].min(axis=0), boxes[:, :2].max(axis=0)
        centre = (float((lo[0] + hi[0]) / 2), float((lo[1] + hi[1]) / 2))
    else:  # no occupied cell: the plane under the map's middle
        ox, oy, yaw = grid.origin
        half_x, half_y = w * grid.resolution / 2, h * grid.resolution / 2
        centre = (
            ox + math.cos(yaw) * half_x - math.sin(yaw) * half_y,
            oy + math.sin(yaw) * half_x + math.cos(yaw) * half_y,
        )
    tiles: dict[tuple[int, int], list[GeomDesc]] = {}
    for g in geoms:
        key = (int(g.pose[0] // WALL_TILE), int(g.pose[1] // WALL_TILE))
        tiles.setdefault(key, []).append(g)
    links = [
        LinkDesc(f"tile_{i}_{j}".replace("-", "m"), geoms=v) for (i, j), v in sorted(tiles.items())
    ]
    walls = ModelDesc("map_walls", static=True, links=links, source=str(yaml_path))
    return WorldDesc(
        name=Path(yaml_path).stem,
        models=[ground_plane(extent, centre), walls],
        lights=[sun()],
        source=str(yaml_path),
        occupancy=grid,
    )
