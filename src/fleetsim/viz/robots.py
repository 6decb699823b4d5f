"""Robots as viewers see them: found from tf frames, drawn with their costmap footprint.

A robot is a tf prefix with a ``<prefix>/base_footprint`` or ``<prefix>/base_link`` frame
(the seeds' convention: robot ``lizi1`` in namespace ``/lizi1`` with ``tf_prefix`` ``lizi1``).
Its footprint comes, in this order, from its costmap's ``footprint`` topic (if recorded), the
``footprint`` parameter of ``<ns>/move_base/local_costmap`` (or ``global_costmap``, or
``move_base``), the ``robot_radius`` parameter there, the rectangle around the collision
shapes of its ``robot_description``, else a circle of costmap_2d's default ``robot_radius``
(0.46 m).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import yaml

#: costmap_2d's default ``robot_radius`` (m), used when a robot declares no footprint
DEFAULT_ROBOT_RADIUS = 0.46
#: base frames that mark a robot, most specific first
BASE_FRAMES = ("base_footprint", "base_link")
#: where a robot's footprint parameters are looked for, below its namespace
FOOTPRINT_PARAM_PLACES = (
    ("move_base", "local_costmap"),
    ("move_base", "global_costmap"),
    ("move_base",),
    (),
)
#: tab10, so a robot keeps its colour in every render and in the live view
PALETTE = (
    (0.122, 0.467, 0.706),
    (1.000, 0.498, 0.055),
    (0.173, 0.627, 0.173),
    (0.839, 0.153, 0.157),
    (0.580, 0.404, 0.741),
    (0.549, 0.337, 0.294),
    (0.890, 0.467, 0.761),
    (0.498, 0.498, 0.498),
    (0.737, 0.741, 0.133),
    (0.090, 0.745, 0.812),
)


def robot_of_frame(frame: str) -> str | None:
    """The robot (tf prefix) whose base frame ``frame`` is, or None (``lizi1/base_link`` ->
    ``lizi1``; a bare ``base_link`` -> ``""``)."""
    frame = frame.lstrip("/")
    prefix, _, base = frame.rpartition("/")
    return prefix if base in BASE_FRAMES else None


def robot_of_topic(topic: str) -> str:
    """The first namespace of a topic (``/lizi1/scan`` -> ``lizi1``), ``""`` for a global one."""
    parts = topic.strip("/").split("/")
    return parts[0] if len(parts) > 1 else ""


def circle_footprint(radius: float, n: int = 24) -> np.ndarray:
    """A polygon of ``n`` points approximating a circle, shape (n, 2), metres."""
    a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.column_stack([radius * np.cos(a), radius * np.sin(a)])


def _polygon(value: Any) -> np.ndarray | None:
    if isinstance(value, str):  # costmap_2d accepts "[[x, y], [x, y], ...]" strings
        try:
            value = yaml.safe_load(value)
        except yaml.YAMLError:
            return None
    try:
        pts = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 3 or not np.isfinite(pts).all():
        return None
    return pts


def footprint_from_params(params: dict, robot: str) -> np.ndarray:
    """The footprint polygon (K, 2) in the robot's base frame, metres, from a parameter tree.

    ``params`` is the nested parameter dict (``{"lizi1": {"move_base": {...}}}``).
    """
    ns = params.get(robot, {}) if robot else params
    if not isinstance(ns, dict):
        ns = {}
    for place in FOOTPRINT_PARAM_PLACES:
        node: Any = ns
        for key in place:
            node = node.get(key, {}) if isinstance(node, dict) else {}
        if not isinstance(node, dict):
            continue
        if "footprint" in node and (pts := _polygon(node["footprint"])) is not None:
            return pts
        radius = node.get("robot_radius")
        if isinstance(radius, int | float) and radius > 0:
            return circle_footprint(float(radius))
    description = ns.get("robot_description")
    if isinstance(description, str) and description.strip():
        found = urdf_footprint(description)
        if found is not None:
            return found
    return circle_footprint(DEFAULT_ROBOT_RADIUS)


def urdf_footprint(text: str) -> np.ndarray | None:
    """The rectangle (4, 2) in the root link's frame that holds the robot's collision boxes,
    cylinders and spheres seen from above, every joint at zero (meshes are left out); None
    when the URDF does not parse or has none. For a robot without move_base (a leader driven
    by cmd_vel), which costmap_2d's 0.46 m default drew as a 0.92 m disc."""
    from fleetsim.description.urdf import parse_urdf
    from fleetsim.errors import FleetsimError
    from fleetsim.tf.quaternions import matrix_from_quaternion, quaternion_from_euler

    try:
        robot = parse_urdf(text)
    except FleetsimError:
        return None

    def pose(origin) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = matrix_from_quaternion(quaternion_from_euler(*origin.rpy))
        m[:3, 3] = origin.xyz
        return m

    points = []
    stack = [(robot.root_link(), np.eye(4))]
    while stack:
        name, at = stack.pop()
        for c in robot.links[name].collisions:
            g, m = c.geometry, at @ pose(c.origin)
            if hasattr(g, "size"):  # a box: its eight corners
                h = np.asarray(g.size, float) / 2
                local = np.array([[x, y, z] for x in (-h[0], h[0]) for y in (-h[1], h[1])
                                  for z in (-h[2], h[2])])  # fmt: skip
            elif hasattr(g, "length"):  # a cylinder along its z: two rims
                a = np.linspace(0, 2 * np.pi, 16, endpoint=False)
                rim = np.column_stack([g.radius * np.cos(a), g.radius * np.sin(a)])
                local = np.vstack([np.column_stack([rim, np.full(16, z)])
                                   for z in (-g.length / 2, g.length / 2)])  # fmt: skip
            elif hasattr(g, "radius"):  # a sphere: its axis extremes
                local = np.vstack([np.eye(3) * g.radius, -np.eye(3) * g.radius])
            else:
                continue
            points.append(local @ m[:3, :3].T + m[:3, 3])
        for j in robot.children(name):
            stack.append((j.child, at @ pose(j.origin)))
    if not points:
        return None
    xy = np.vstack(points)[:, :2]
    (x0, y0), (x1, y1) = xy.min(axis=0), xy.max(axis=0)
    return np.array([[x1, y1], [x0, y1], [x0, y0], [x1, y0]])


def colour_of(index: int) -> tuple[float, float, float]:
    """The RGB colour (0..1) of the ``index``-th robot found."""
    return PALETTE[index % len(PALETTE)]
