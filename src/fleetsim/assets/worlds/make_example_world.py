"""Write fleetsim's copy of the visual servoing tutorial's example world, and its map.

grobot's ``example.world`` is a 12 x 12 m walled building (``model://building``: four 12.0 x
0.15 x 2.5 m brick walls) with a few obstacles from Gazebo's model database: a 1 x 1 x 0.5 m box,
an oak tree, a cinder block, two cardboard boxes and two jersey barriers, at the poses the
tutorial's world file gives them. The database models are not shipped with fleetsim, so the
obstacles here are plain shapes of about their size at the same poses (all static: nothing in
the tutorial pushes them). The walls are ``Gazebo/Bricks`` as in the tutorial, from fleetsim's
stand-in for Gazebo's media folder (``worlds/media``, a brick texture drawn here), stretched
over each wall as Gazebo stretches it.

One description (``BUILDING``, ``OBSTACLES``) gives both outputs, so the world and the map
agree by construction:

- ``worlds/example.world`` with ``worlds/models/example_building/`` (model.config, model.sdf);
- ``worlds/media/materials/`` (``gazebo.material`` with ``Gazebo/Bricks``, ``bricks.png``);
- ``maps/example_world.pgm`` + ``.yaml`` with the tutorial map's layout (0.05 m cells, 384 x
  384, origin (-10, -10)): inside the building free (254), walls and the obstacles' footprints
  at laser height occupied (0), outside unknown (205), as map_saver writes a gmapping map.

Run ``python make_example_world.py [ASSETS_DIR]`` (default: the ``assets`` folder this file is
in) to rewrite them; the output is deterministic.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ASSETS = Path(__file__).resolve().parent.parent

# -- the world ----------------------------------------------------------------------------------
BUILDING_POSE = (0.941157, -0.334956)  # the tutorial's building model pose (x, y)
WALL_LENGTH, WALL_THICKNESS, WALL_HEIGHT = 12.0, 0.15, 2.5
#: name, (x, y, yaw) in the building frame, as the tutorial's building model places its walls
WALLS = (
    ("Wall_1", (0.0, 6.0, 0.0)),
    ("Wall_2", (6.0, 0.0, -1.5707)),
    ("Wall_3", (0.0, -6.0, 3.14159)),
    ("Wall_4", (-6.0, 0.0, 1.5707)),
)


@dataclass(frozen=True)
class Shape:
    """One collision+visual shape of an obstacle, in its model frame."""

    kind: str  # "box" | "cylinder" | "sphere"
    size: tuple[float, ...]  # box (x, y, z); cylinder (radius, length); sphere (radius,)
    z: float  # height of the shape's centre above the model origin, m
    rgba: tuple[float, float, float, float]
    collide: bool = True


GREY = (0.7, 0.7, 0.7, 1.0)
CARDBOARD = (0.62, 0.47, 0.3, 1.0)
CONCRETE = (0.8, 0.78, 0.74, 1.0)
BARK = (0.36, 0.25, 0.16, 1.0)
LEAVES = (0.2, 0.45, 0.15, 1.0)

#: name, (x, y, yaw) in the world as the tutorial's world places them, shapes of about the size
#: of the Gazebo database model of that name
OBSTACLES = (
    ("box_z_0_5m", (-3.26157, 4.02790, 0.0), (Shape("box", (1.0, 1.0, 0.5), 0.25, GREY),)),
    (
        "oak_tree",
        (-2.61035, -4.32355, 0.0),
        (
            Shape("cylinder", (0.15, 2.2), 1.1, BARK),
            Shape("sphere", (1.1,), 3.0, LEAVES, collide=False),
        ),
    ),
    ("cinder_block", (-1.98915, 4.41578, 0.0), (Shape("box", (0.39, 0.19, 0.19), 0.095, GREY),)),
    (
        "cardboard_box_0",
        (0.61689, -4.93546, 0.0),
        (Shape("box", (0.5, 0.4, 0.3), 0.15, CARDBOARD),),
    ),
    (
        "cardboard_box_1",
        (2.00053, -4.93546, 0.0),
        (Shape("box", (0.5, 0.4, 0.3), 0.15, CARDBOARD),),
    ),
    (
        "jersey_barrier_0",
        (4.10862, -1.10365, 0.0),
        (
            Shape("box", (4.0, 0.6, 0.25), 0.125, CONCRETE),
            Shape("box", (4.0, 0.3, 0.55), 0.525, CONCRETE),
        ),
    ),
    (
        "jersey_barrier_1",
        (2.67185, 2.63868, 1.5707),
        (
            Shape("box", (4.0, 0.6, 0.25), 0.125, CONCRETE),
            Shape("box", (4.0, 0.3, 0.55), 0.525, CONCRETE),
        ),
    ),
)

# -- the map ------------------------------------------------------------------------------------
RESOLUTION = 0.05  # m per cell
SIZE = 384  # cells per side
ORIGIN = (-10.0, -10.0)  # m, the lower-left corner of the map
SCAN_HEIGHTS = (0.1, 0.3)  # m: a shape reaching into this band shows in the map
FREE, OCCUPIED, UNKNOWN = 254, 0, 205
SUBSAMPLES = 4  # per cell side: a cell is occupied when any subsample is inside a shape


def _f(v: float) -> str:
    return f"{v:.6g}"


def _pose(x, y, z, yaw) -> str:
    return f"{_f(x)} {_f(y)} {_f(z)} 0 0 {_f(yaw)}"


def _geometry(shape: Shape) -> str:
    if shape.kind == "box":
        return f"<box><size>{' '.join(_f(v) for v in shape.size)}</size></box>"
    if shape.kind == "cylinder":
        r, length = shape.size
        return f"<cylinder><radius>{_f(r)}</radius><length>{_f(length)}</length></cylinder>"
    return f"<sphere><radius>{_f(shape.size[0])}</radius></sphere>"


def _colour(rgba) -> str:
    c = " ".join(_f(v) for v in rgba)
    return f"<material><ambient>{c}</ambient><diffuse>{c}</diffuse></material>"


def obstacle_sdf(name: str, pose, shapes) -> str:
    parts = []
    for i, s in enumerate(shapes):
        geo = _geometry(s)
        where = f"<pose>0 0 {_f(s.z)} 0 0 0</pose>"
        if s.collide:
            parts.append(
                f'        <collision name="collision_{i}">{where}<geometry>{geo}</geometry>'
                "</collision>"
            )
        parts.append(
            f'        <visual name="visual_{i}">{where}<geometry>{geo}</geometry>'
            f"{_colour(s.rgba)}</visual>"
        )
    body = "\n".join(parts)
    x, y, yaw = pose
    return (
        f'    <model name="{name}">\n      <static>true</static>\n'
        f"      <pose>{_pose(x, y, 0.0, yaw)}</pose>\n"
        f'      <link name="link">\n{body}\n      </link>\n    </model>'
    )


def world_sdf() -> str:
    obstacles = "\n".join(obstacle_sdf(*o) for o in OBSTACLES)
    bx, by = BUILDING_POSE
    return f"""<?xml version="1.0"?>
<!-- Written by make_example_world.py: fleetsim's copy of grobot's example.world (the visual
     servoing tutorial): a 12 m walled building with a few obstacles. Map: example_world.yaml -->
<sdf version="1.6">
  <world name="default">
    <include><uri>model://sun</uri></include>
    <include><uri>model://ground_plane</uri></include>
    <include>
      <uri>model://example_building</uri>
      <name>building</name>
      <pose>{_pose(bx, by, 0.0, 0.0)}</pose>
    </include>
{obstacles}
    <plugin name="ros_link_attacher_plugin" filename="libgazebo_ros_link_attacher.so"/>
  </world>
</sdf>
"""


def building_sdf() -> str:
    size = f"{_f(WALL_LENGTH)} {_f(WALL_THICKNESS)} {_f(WALL_HEIGHT)}"
    material = (
        "<material><script><uri>file://media/materials/scripts/gazebo.material</uri>"
        "<name>Gazebo/Bricks</name></script></material>"
    )
    links = []
    for name, (x, y, yaw) in WALLS:
        geo = f"<geometry><box><size>{size}</size></box></geometry>"
        links.append(
            f'    <link name="{name}">\n      <pose>{_pose(x, y, WALL_HEIGHT / 2, yaw)}</pose>\n'
            f'      <collision name="{name}_Collision">{geo}</collision>\n'
            f'      <visual name="{name}_Visual">{geo}{material}</visual>\n    </link>'
        )
    body = "\n".join(links)
    return f"""<?xml version="1.0"?>
<!-- Written by ../../make_example_world.py: the tutorial's building, four brick walls -->
<sdf version="1.6">
  <model name="example_building">
    <static>true</static>
{body}
  </model>
</sdf>
"""


BUILDING_CONFIG = """<?xml version="1.0"?>
<model>
  <name>Example building</name>
  <version>1.0</version>
  <sdf version="1.6">model.sdf</sdf>
  <author><name>fleetsim</name></author>
  <description>12 x 12 m, four 2.5 m brick walls (written by make_example_world.py)</description>
</model>
"""

BRICKS_MATERIAL = """// fleetsim's stand-in for Gazebo's textured media materials (written by
// ../../../make_example_world.py); plain Gazebo/* colours are built into fleetsim
material Gazebo/Bricks
{
  technique
  {
    pass
    {
      texture_unit
      {
        texture bricks.png
      }
    }
  }
}
"""


def bricks_image() -> np.ndarray:
    """A brick wall texture: (256, 512, 3) uint8 RGB, 8 courses of bricks in running bond."""
    h, w, courses, per_course, mortar = 256, 512, 8, 4, 4
    rng = np.random.default_rng(15)  # fixed: the texture is an asset, drawn the same each time
    img = np.empty((h, w, 3), np.uint8)
    img[:] = (196, 190, 178)  # mortar
    ch, bw = h // courses, w // per_course
    for row in range(courses):
        shift = (bw // 2) * (row % 2)
        for k in range(-1, per_course + 1):
            x0, x1 = k * bw + shift + mortar // 2, (k + 1) * bw + shift - mortar // 2
            y0, y1 = row * ch + mortar // 2, (row + 1) * ch - mortar // 2
            tone = np.array([148, 62, 44]) + rng.integers(-18, 19, 3)
            img[y0:y1, max(x0, 0) : max(min(x1, w), 0)] = np.clip(tone, 0, 255)
    return img


# -- the map ------------------------------------------------------------------------------------
def _footprints() -> list[np.ndarray]:
    """The (4, 2) corners (or (N, 2) polygon) of every shape reaching the scan band, world xy."""
    out = []

    def rect(cx, cy, yaw, sx, sy):
        c, s = np.cos(yaw), np.sin(yaw)
        local = np.array([[-sx, -sy], [sx, -sy], [sx, sy], [-sx, sy]]) / 2
        return local @ np.array([[c, s], [-s, c]]) + [cx, cy]

    bx, by = BUILDING_POSE
    for _, (x, y, yaw) in WALLS:
        out.append(rect(bx + x, by + y, yaw, WALL_LENGTH, WALL_THICKNESS))
    lo, hi = SCAN_HEIGHTS
    for _, (x, y, yaw), shapes in OBSTACLES:
        for s in shapes:
            half = {"box": lambda s: s.size[2] / 2, "cylinder": lambda s: s.size[1] / 2}.get(
                s.kind, lambda s: s.size[0]
            )(s)
            if not s.collide or s.z - half > hi or s.z + half < lo:
                continue
            if s.kind == "box":
                out.append(rect(x, y, yaw, s.size[0], s.size[1]))
            else:
                r = s.size[0]
                a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
                out.append(np.stack([x + r * np.cos(a), y + r * np.sin(a)], axis=1))
    return out


def _inside(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(P,) bool: points (P, 2) inside a convex polygon (N, 2) given counter-clockwise."""
    inside = np.ones(len(points), bool)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        edge, rel = b - a, points - a
        inside &= edge[0] * rel[:, 1] - edge[1] * rel[:, 0] >= 0
    return inside


def map_image() -> np.ndarray:
    """The map as a (384, 384) uint8 image, row 0 at the top (as map_server reads it)."""
    n = SIZE * SUBSAMPLES
    centres = ORIGIN[0] + (np.arange(n) + 0.5) * RESOLUTION / SUBSAMPLES
    xs, ys = np.meshgrid(centres, ORIGIN[1] + (np.arange(n) + 0.5) * RESOLUTION / SUBSAMPLES)
    pts = np.stack([xs.ravel(), ys.ravel()], axis=1)
    occupied = np.zeros(len(pts), bool)
    for poly in _footprints():
        occupied |= _inside(pts, poly)
    bx, by = BUILDING_POSE
    half = WALL_LENGTH / 2
    interior = (np.abs(pts[:, 0] - bx) < half) & (np.abs(pts[:, 1] - by) < half)

    def cells(mask):  # any subsample of a cell, rows flipped so that row 0 is the top
        return mask.reshape(SIZE, SUBSAMPLES, SIZE, SUBSAMPLES).any(axis=(1, 3))[::-1]

    img = np.full((SIZE, SIZE), UNKNOWN, np.uint8)
    img[cells(interior)] = FREE
    img[cells(occupied)] = OCCUPIED
    return img


def write(assets: Path = ASSETS) -> list[Path]:
    """Write the world, the building model and the map under ``assets``; returns the files."""
    from PIL import Image

    model = assets / "worlds/models/example_building"
    media = assets / "worlds/media/materials"
    for folder in (model, media / "scripts", media / "textures"):
        folder.mkdir(parents=True, exist_ok=True)
    (assets / "maps").mkdir(parents=True, exist_ok=True)
    files = {
        assets / "worlds/example.world": world_sdf(),
        model / "model.sdf": building_sdf(),
        model / "model.config": BUILDING_CONFIG,
        media / "scripts/gazebo.material": BRICKS_MATERIAL,
        assets / "maps/example_world.yaml": (
            "# fleetsim's copy of the tutorial's example_world map, drawn by "
            "../worlds/make_example_world.py\n"
            f"image: example_world.pgm\nresolution: {RESOLUTION}\n"
            f"origin: [{ORIGIN[0]}, {ORIGIN[1]}, 0.0]\n"
            "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
        ),
    }
    for path, text in files.items():
        path.write_text(text)
    bricks = media / "textures/bricks.png"
    Image.fromarray(bricks_image()).save(bricks)
    img = map_image()
    pgm = assets / "maps/example_world.pgm"
    with open(pgm, "wb") as f:
        f.write(f"P5\n# CREATOR: make_example_world.py {RESOLUTION:.3f} m/pix\n".encode())
        f.write(f"{SIZE} {SIZE}\n255\n".encode())
        f.write(img.tobytes())
    return [*files, bricks, pgm]


if __name__ == "__main__":
    for p in write(Path(sys.argv[1]) if len(sys.argv) > 1 else ASSETS):
        print(p)
