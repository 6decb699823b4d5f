"""A URDF ``Robot`` (``fleetsim.description``) as a MuJoCo body tree under the prefix ``<name>/``.

The root link gets a free joint (``<name>/free``); each URDF joint becomes a MuJoCo joint of the
same name with the prefix (revolute: limited hinge, continuous: hinge, prismatic: slide, fixed:
none, planar: two slides and a hinge). Collision shapes collide (friction ``mu1`` from the link's
``<gazebo>`` block, Gazebo's default 1.0 otherwise); visual shapes are drawn only.
"""

from __future__ import annotations

import warnings
from typing import Any

import mujoco
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.sim.build import MIN_INERTIA, MIN_MASS, add_geom, gazebo_colour, quat_from_rpy
from fleetsim.sim.world import GeomDesc, Pose

JOINT_ARMATURE = 1e-4  # kg m^2, small rotor inertia on every joint (numerical stability)


def _geom_desc(geometry: Any, origin: Any, name: str, collide: bool) -> GeomDesc:
    pose = (*origin.xyz, *origin.rpy)
    kind = type(geometry).__name__
    if kind == "Box":
        return GeomDesc("box", tuple(geometry.size), pose, name, collide)
    if kind == "Cylinder":
        return GeomDesc("cylinder", (geometry.radius, geometry.length), pose, name, collide)
    if kind == "Sphere":
        return GeomDesc("sphere", (geometry.radius,), pose, name, collide)
    if kind == "Mesh":
        return GeomDesc("mesh", tuple(geometry.scale), pose, name, collide, mesh=geometry.filename)
    raise SimulationError(f"unsupported URDF geometry {kind} in '{name}'")


def _gazebo_props(robot: Any, link: str) -> dict[str, str]:
    props: dict[str, str] = {}
    for block in robot.gazebo:
        if block.reference == link:
            props.update(block.properties)
    return props


def _friction(props: dict[str, str], robot: Any, link: str) -> tuple[float, float]:
    try:
        mu1 = float(props.get("mu1", props.get("mu", "1.0")))
        mu2 = float(props.get("mu2", mu1))
    except ValueError as exc:
        raise SimulationError(
            f"{robot.source}: <gazebo reference='{link}'> mu1/mu2 must be numbers ({exc})"
        ) from exc
    return mu1, mu2


def _add_link_geoms(spec, body, robot: Any, link: Any, prefix: str) -> None:
    props = _gazebo_props(robot, link.name)
    mu = _friction(props, robot, link.name)
    colour = gazebo_colour(props.get("material"))
    idx = 0
    for c in link.collisions:
        g = _geom_desc(c.geometry, c.origin, c.name or "collision", True)
        g.friction = mu
        add_geom(spec, body, g, False, prefix, idx)
        idx += 1
    for v in link.visuals:
        g = _geom_desc(v.geometry, v.origin, v.name or "visual", False)
        mat = v.material
        if mat is not None and mat.rgba is None and mat.name in robot.materials:
            mat = robot.materials[mat.name]
        g.rgba = colour or (tuple(mat.rgba) if mat is not None and mat.rgba else None)
        if mat is not None and mat.texture:
            g.texture = mat.texture
        add_geom(spec, body, g, False, prefix, idx)
        idx += 1


def _set_inertial(body, link: Any) -> None:
    ine = link.inertial
    if ine is None or ine.mass <= 0:
        body.mass = MIN_MASS
        body.inertia = [MIN_INERTIA] * 3
        body.ipos = [0.0, 0.0, 0.0]  # unset, MuJoCo 4 compiles it to the body's offset
    else:
        body.mass = ine.mass
        body.ipos = list(ine.origin.xyz)
        body.iquat = quat_from_rpy(*ine.origin.rpy)
        full = [ine.ixx, ine.iyy, ine.izz, ine.ixy, ine.ixz, ine.iyz]
        if abs(ine.ixy) + abs(ine.ixz) + abs(ine.iyz) > 0:
            body.fullinertia = full
        else:
            body.inertia = [max(v, MIN_INERTIA) for v in full[:3]]
    body.explicitinertial = True


def _add_joint(body, joint: Any, prefix: str, robot: Any) -> None:
    name = prefix + joint.name
    axis = np.asarray(joint.axis, float)
    if joint.type in ("revolute", "continuous", "prismatic"):
        if np.linalg.norm(axis) < 1e-9:
            raise SimulationError(f"{robot.source}: joint '{joint.name}' has a zero axis")
        jt = (
            mujoco.mjtJoint.mjJNT_SLIDE
            if joint.type == "prismatic"
            else mujoco.mjtJoint.mjJNT_HINGE
        )
        j = body.add_joint(name=name, type=jt, axis=axis / np.linalg.norm(axis))
        j.armature = JOINT_ARMATURE
        lim = joint.limit
        if joint.type != "continuous" and lim is not None and lim.upper > lim.lower:
            j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            j.range = [lim.lower, lim.upper]
        if joint.dynamics is not None:
            # MuJoCo 4 damping is (linear, quadratic, cubic); URDF gives the linear term
            j.damping = [joint.dynamics.damping, 0.0, 0.0]
            j.frictionloss = joint.dynamics.friction
    elif joint.type == "planar":
        for k, ax in enumerate(([1, 0, 0], [0, 1, 0])):
            body.add_joint(name=f"{name}/{'xy'[k]}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=ax)
        body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
    elif joint.type == "floating":
        raise SimulationError(
            f"{robot.source}: floating joint '{joint.name}' below the root is not supported; "
            "make it the robot's root or use a fixed joint"
        )


def add_robot(spec: mujoco.MjSpec, robot: Any, name: str, pose: Pose) -> str:
    """Add ``robot`` under the prefix ``<name>/`` at ``pose``; returns the root body name."""
    prefix = f"{name}/"
    root = robot.root_link()
    body = spec.worldbody.add_body(
        name=prefix + root, pos=list(pose[:3]), quat=quat_from_rpy(*pose[3:])
    )
    body.add_freejoint(name=f"{name}/free")
    stack = [(root, body)]
    while stack:
        link_name, b = stack.pop()
        link = robot.links[link_name]
        _set_inertial(b, link)
        _add_link_geoms(spec, b, robot, link, prefix + link_name + "/")
        for joint in reversed(robot.children(link_name)):
            child = b.add_body(
                name=prefix + joint.child,
                pos=list(joint.origin.xyz),
                quat=quat_from_rpy(*joint.origin.rpy),
            )
            _add_joint(child, joint, prefix, robot)
            stack.append((joint.child, child))
    _warn_massless(robot)
    for j in robot.joints.values():
        if j.mimic is not None:
            warnings.warn(
                f"{robot.source}: mimic joint '{j.name}' moves freely in simulation", stacklevel=2
            )
    return prefix + root


def _welded_mass(robot: Any, link: str) -> float:
    """The mass of ``link`` and of the links fixed to it, down the tree (kg)."""
    ine = robot.links[link].inertial
    mass = max(ine.mass, 0.0) if ine is not None else 0.0
    for j in robot.children(link):
        if j.type == "fixed":
            mass += _welded_mass(robot, j.child)
    return mass


def _warn_massless(robot: Any) -> None:
    """Warn about each link a moving joint carries with no mass (no ``<inertial>`` or mass 0,
    and no link fixed to it has any: Gazebo lumps a fixed child's inertial into its parent, and
    fleetsim's welded child keeps its own) or with a mass and no inertia. fleetsim gives it
    `MIN_MASS` or `MIN_INERTIA` and drives on, while Gazebo drops a link without an inertial,
    with its joint, and ODE refuses a zero mass or inertia, so the model would not drive there
    (a wheel without an inertial is the usual slip)."""
    for j in robot.joints.values():
        if j.type == "fixed":
            continue
        ine = robot.links[j.child].inertial
        if _welded_mass(robot, j.child) <= 0:
            what = "has no <inertial>" if ine is None else f"has mass {ine.mass:g}"
            what += f", nor has any link fixed to it: simulated with {MIN_MASS * 1000:g} g"
        elif ine is not None and ine.mass > 0 and min(ine.ixx, ine.iyy, ine.izz) <= 0:
            what = f"has inertia ixx {ine.ixx:g} iyy {ine.iyy:g} izz {ine.izz:g}: simulated "
            what += "with a tiny one"
        else:
            continue
        warnings.warn(
            f"{robot.source}: link '{j.child}' (moved by {j.type} joint '{j.name}') {what}; "
            "Gazebo would drop or refuse it: give it a positive mass and inertia",
            stacklevel=3,
        )
