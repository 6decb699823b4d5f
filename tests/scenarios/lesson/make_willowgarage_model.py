"""Write the ``willowgarage`` Gazebo model the lesson's world includes, from the lesson's map.

Gazebo's own ``model://willowgarage`` (a COLLADA mesh of the building) is not ours to ship, so
the lesson test builds a stand-in of its own: the occupied cells of ``maps/willow-full.png``
(0.1 m per pixel) as one non-convex triangle mesh of 2 m walls, laid out in the model's frame so
that the lesson's ``<include>`` pose ``-3 54 0 0 0 30`` (radians, as Gazebo reads it) puts the
walls exactly on the map. Gazebo's model layout: ``model.config``, ``model.sdf`` and
``meshes/willowgarage.stl``.

Run as a script to write the model beside the package (``models/willowgarage``), or call
``write_model(package_dir)``.
"""

from __future__ import annotations

import math
import struct
import sys
from pathlib import Path

import numpy as np

from fleetsim.nav.map_io import load_map_image
from fleetsim.sim.mapworld import OccupancyMap, wall_boxes

#: the lesson's <pose> of the included model: x, y, z (m), roll, pitch, yaw (rad)
LESSON_POSE = (-3.0, 54.0, 0.0, 0.0, 0.0, 30.0)
RESOLUTION = 0.1  # m per pixel, map_server's second argument in the lesson
WALL_HEIGHT = 2.0  # m

_BOX_FACES = np.array(  # 12 triangles of a unit box's corners (index bits: x, y, z), outward
    [
        [0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
        [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5],
    ]
)  # fmt: skip


def map_grid(png: Path) -> OccupancyMap:
    """The lesson's map image as map_server reads ``willow-full.png 0.1``, as walls to extrude."""
    grid = load_map_image(png, RESOLUTION)
    return OccupancyMap(grid.data == 100, grid.resolution, grid.origin, str(png))


def wall_triangles(grid: OccupancyMap, height: float = WALL_HEIGHT) -> np.ndarray:
    """(T, 3, 3) triangles (m) of the map's walls in the map frame."""
    boxes = wall_boxes(grid, height)
    bits = np.array([[(i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)]) * 2 - 1
    corners = boxes[:, None, :3] + bits[None] * boxes[:, None, 3:6]  # (K, 8, 3), yaw 0 maps
    return corners[:, _BOX_FACES].reshape(-1, 3, 3)


def to_model_frame(tri: np.ndarray, pose=LESSON_POSE) -> np.ndarray:
    """Map-frame points into the frame of a model placed at ``pose`` (yaw only)."""
    x, y, z, _, _, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    p = tri - np.array([x, y, z])
    out = p.copy()
    out[..., 0] = c * p[..., 0] + s * p[..., 1]
    out[..., 1] = -s * p[..., 0] + c * p[..., 1]
    return out


def write_stl(path: Path, tri: np.ndarray, name: bytes = b"willowgarage") -> None:
    """Binary STL of (T, 3, 3) triangles."""
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    n = np.cross(e1, e2)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    rec = np.zeros(len(tri), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"], rec["v"] = n, tri
    with path.open("wb") as f:
        f.write(name.ljust(80, b" ") + struct.pack("<I", len(tri)))
        f.write(rec.tobytes())


def write_model(package: Path) -> Path:
    """Write ``<package>/models/willowgarage`` from ``<package>/maps/willow-full.png``."""
    model = package / "models" / "willowgarage"
    (model / "meshes").mkdir(parents=True, exist_ok=True)
    tri = to_model_frame(wall_triangles(map_grid(package / "maps" / "willow-full.png")))
    write_stl(model / "meshes" / "willowgarage.stl", tri)
    (model / "model.config").write_text(
        '<?xml version="1.0"?>\n<model>\n  <name>Willow Garage</name>\n  <version>1.0</version>\n'
        '  <sdf version="1.4">model.sdf</sdf>\n  <description>The lesson map\'s walls as one '
        "mesh (a stand-in for Gazebo's model).</description>\n</model>\n"
    )
    mesh = "<mesh><uri>model://willowgarage/meshes/willowgarage.stl</uri></mesh>"
    (model / "model.sdf").write_text(
        '<?xml version="1.0" ?>\n<sdf version="1.4">\n  <model name="willowgarage">\n'
        '    <static>true</static>\n    <pose>0 0 0 0 0 0</pose>\n    <link name="walls">\n'
        f'      <collision name="collision"><geometry>{mesh}</geometry></collision>\n'
        f'      <visual name="visual"><geometry>{mesh}</geometry></visual>\n'
        "    </link>\n  </model>\n</sdf>\n"
    )
    return model


if __name__ == "__main__":
    pkg = (
        Path(sys.argv[1])
        if len(sys.argv) > 1
        else Path(__file__).parent / "gazebo_navigation_multi"
    )
    print(write_model(pkg))
