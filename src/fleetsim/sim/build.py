"""``MjSpec`` construction: the world, SDF models and URDF robots as MuJoCo bodies.

Every model becomes a top-level body tree whose names carry the prefix ``<model>/`` (bodies
``<model>/<link>``, joints ``<model>/<joint>``), so many copies of one robot coexist. Collision
filtering: static geoms have ``contype=2, conaffinity=1`` and movable ones ``contype=1,
conaffinity=3``, so walls never test against walls. Collision geoms sit in geom group 3 (hidden
in renders), visual geoms in group 1 (no contacts, no mass). Movable geoms get ``priority=1`` so
their friction, not the ground's, sets the contact friction (Gazebo/ODE takes the smaller mu;
MuJoCo would otherwise take the larger).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.sim import textures
from fleetsim.sim.mesh_assets import (
    HULL_GROUP,
    MESH_FORMATS,
    RAY_GROUP,
    add_decomposed_mesh,
    add_mesh_asset,
    add_part_mesh_assets,
)
from fleetsim.sim.sdf import GAZEBO_COLOURS
from fleetsim.sim.world import GeomDesc, ModelDesc, Pose, WorldDesc

G = mujoco.mjtGeom
COLLISION_GROUP = 3
VISUAL_GROUP = 1
MIN_MASS = 1e-3
MIN_INERTIA = 1e-6
__all__ = ["COLLISION_GROUP", "HULL_GROUP", "MESH_FORMATS", "RAY_GROUP", "VISUAL_GROUP"]


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` of fixed-axis roll, pitch, yaw (URDF/SDF convention)."""
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    return np.array(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]
    )


def rpy_from_quat(q) -> tuple[float, float, float]:
    """Roll, pitch, yaw (rad) of a unit quaternion ``(w, x, y, z)``."""
    w, x, y, z = q
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return float(roll), float(pitch), float(yaw)


def new_world_spec(timestep: float = 0.002) -> mujoco.MjSpec:
    """An empty spec with fleetsim's physics options (implicit integrator, no gravity
    compensation tricks, no auto-reset) and a large offscreen buffer for cameras."""
    spec = mujoco.MjSpec()
    spec.option.timestep = timestep
    # a blow-up is an error the engine reports (sim.health), never a silent reset of the world
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
    # implicit, not implicitfast: implicitfast drops the Coriolis (gyroscopic) derivatives, and a
    # robot tumbling through the air after a pile-up (the 10-lizi soak, t = 2940 s: two lizis
    # thrown up at 5 m/s) gained spin each step, 40 -> 170 rad/s in 0.6 s of free flight and
    # then NaN; with those terms integrated implicitly a tossed lizi keeps its spin bounded and
    # lands (tests/sim/test_physics_health.py). It costs ~10 % of mj_step on 10 lizis.
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICIT
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC  # pyramidal + early stop jitters at rest
    # one contact per convex pair (MuJoCo 4 enables multi-point CCD by default): robots that
    # rub wheel against wheel or body got a pile of near-duplicate elliptic friction contacts
    # on which the Newton solver did not converge (it hit its iteration cap), and the
    # unconverged forces flung a lizi at 800 rad/s into a NaN (the willow10_amcl repro).
    # Wheels on the ground plane use the analytic plane colliders and are not affected.
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_MULTICCD
    spec.option.tolerance = 1e-6  # solver stops early; ample for wheeled robots
    spec.option.ls_iterations = 20
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    spec.compiler.degree = False  # joint ranges in radians, as URDF gives them
    spec.visual.global_.offwidth = 1920
    spec.visual.global_.offheight = 1080
    spec.visual.map.zfar = 200.0
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.5, 0.5, 0.5]
    spec.stat.extent = 20.0
    spec.add_texture(
        name="__sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        width=64,
        height=64,
        rgb1=[0.75, 0.82, 0.9],
        rgb2=[0.95, 0.95, 0.95],
    )
    return spec


def _material_for(spec: mujoco.MjSpec, g: GeomDesc, prefix: str) -> str:
    if not g.texture:
        return ""
    return textures.add_texture_material(spec, g.texture, f"'{prefix}{g.name}'")


def add_geom(
    spec,
    body,
    g: GeomDesc,
    static: bool,
    prefix: str,
    index: int,
    shown: bool = False,
    frame: tuple[np.ndarray, np.ndarray] | None = None,
) -> None:
    """Add one ``GeomDesc`` to ``body`` (collision or visual, per ``g.collide``); ``shown``
    puts a collision geom in the visual group (for links without visuals).

    Meshes: STL, OBJ and MSH load through MuJoCo, COLLADA (``.dae``) through
    ``fleetsim.sim.meshes`` (node transforms and ``<unit>`` applied, ``up_axis`` ignored as
    Gazebo classic does); other formats are skipped with a warning. The URDF/SDF ``scale``
    applies to all. A movable model's collision mesh collides as its convex hull (MuJoCo's
    and Gazebo-ODE's rule); a static model's non-convex collision mesh (a building) collides
    as its convex parts, with its true triangles kept for rays
    (``mesh_assets.add_decomposed_mesh``).

    A visual ``.dae`` without a colour or texture of its own (``g.rgba`` None, no
    ``g.texture``) takes the file's materials, as Gazebo draws it: one mesh geom per material
    part (``fleetsim.sim.meshes.collada_parts``), named ``<prefix><name>#<index>:<part>``, all
    at the same pose and scale, each in its material's colour. A file without materials, an
    explicit colour, and collision geoms keep one mesh geom named ``<prefix><name>#<index>``.
    """
    pos, quat = np.array(g.pose[:3], float), quat_from_rpy(*g.pose[3:])
    if frame is not None:  # express the geom in ``body`` when it sits in another frame
        fpos, fquat = frame
        p, q = np.zeros(3), np.zeros(4)
        mujoco.mju_rotVecQuat(p, pos, fquat)
        mujoco.mju_mulQuat(q, fquat, quat)
        pos, quat = p + fpos, q
    kw = {"pos": pos, "quat": quat}
    if g.texture and not g.collide and g.kind in textures.TEXTURED_SHAPES:  # Gazebo's UVs
        kw.update(type=G.mjGEOM_MESH, meshname=textures.add_textured_mesh(spec, g.kind, g.size))
    elif g.kind == "box":
        kw.update(type=G.mjGEOM_BOX, size=[s / 2 for s in g.size])
    elif g.kind == "cylinder":
        kw.update(type=G.mjGEOM_CYLINDER, size=[g.size[0], g.size[1] / 2, 0])
    elif g.kind == "sphere":
        kw.update(type=G.mjGEOM_SPHERE, size=[g.size[0], 0, 0])
    elif g.kind == "plane":
        kw.update(type=G.mjGEOM_PLANE, size=[g.size[0] / 2, g.size[1] / 2, 1.0])
    elif g.kind == "mesh":
        if g.collide and static and add_decomposed_mesh(spec, body, g, prefix, index, kw, shown):
            return
        if _coloured_by_file(g):
            parts = add_part_mesh_assets(spec, g, prefix)
            if parts:
                for k, (mesh_name, rgba, image) in enumerate(parts):
                    geom = body.add_geom(
                        name=f"{prefix}{g.name or 'geom'}#{index}:{k}",
                        type=G.mjGEOM_MESH,
                        meshname=mesh_name,
                        **kw,
                    )
                    _make_visual(geom)
                    geom.rgba = list(rgba)
                    if image is not None:  # the COLLADA texture, by the file's UVs
                        geom.material = textures.add_texture_material(spec, image, geom.name)
                return
        mesh_name = add_mesh_asset(spec, g, prefix)
        if mesh_name is None:
            return
        kw.update(type=G.mjGEOM_MESH, meshname=mesh_name)
    else:
        raise SimulationError(f"geometry kind '{g.kind}' of '{prefix}{g.name}' is not supported")
    geom = body.add_geom(name=f"{prefix}{g.name or 'geom'}#{index}", **kw)
    if g.collide:
        geom.group = VISUAL_GROUP if shown else COLLISION_GROUP
        geom.contype, geom.conaffinity = (2, 1) if static else (1, 3)
        geom.priority = 0 if static else 1
        if g.friction is not None:
            geom.friction = [g.friction[0], 0.005, 0.0001]
        geom.rgba = list(g.rgba) if (shown and g.rgba) else [0.6, 0.6, 0.62, 1.0]
        if shown and g.kind == "plane":
            geom.material = _floor_material(spec)
    else:
        _make_visual(geom)
        geom.rgba = list(g.rgba) if g.rgba is not None else [0.7, 0.7, 0.7, 1.0]
        geom.material = _material_for(spec, g, prefix)
        if geom.material:
            geom.rgba = [1, 1, 1, 1]
        if g.kind == "plane":
            geom.material = _floor_material(spec)


def _make_visual(geom) -> None:
    """Visual group, no contacts, no mass."""
    geom.group = VISUAL_GROUP
    geom.contype = geom.conaffinity = 0
    geom.density = 0


def _coloured_by_file(g: GeomDesc) -> bool:
    """A visual COLLADA mesh whose URDF/SDF gives it no colour or texture: its file's
    materials colour it (Gazebo's rule)."""
    dae = Path(g.mesh or "").suffix.lower() == ".dae"
    return dae and not g.collide and g.rgba is None and not g.texture


def _floor_material(spec) -> str:
    if spec.material("__floor") is None:
        spec.add_texture(
            name="__floor",
            type=mujoco.mjtTexture.mjTEXTURE_2D,
            builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
            width=256,
            height=256,
            rgb1=[0.82, 0.82, 0.8],
            rgb2=[0.74, 0.74, 0.72],
        )
        mat = spec.add_material(name="__floor", texrepeat=[1, 1], texuniform=True)
        mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "__floor"
    return "__floor"


def add_sdf_model(spec: mujoco.MjSpec, m: ModelDesc, pose: Pose | None = None) -> list[str]:
    """Add an SDF model; returns its top-level body names (one per link, ``<model>/<link>``).

    A static model adds no moving bodies: its geoms go straight into the world body (named
    ``<model>/<link>/...``), which MuJoCo's broad phase handles far faster than many static
    bodies (a map world has thousands of wall boxes). Planes are the exception: each gets a
    static body of its own (``<geom name>:plane``), because MuJoCo collides the world body's
    geoms with every moving body through one bounding-volume tree, and a plane's infinite
    bounds would make every descent walk all the walls (100 robots in Willow: 0.4 ms of 1.3 ms
    per step).
    """
    pose = pose if pose is not None else m.pose
    mq = quat_from_rpy(*pose[3:])
    roots = []
    for link in m.links:
        # link pose is relative to the model pose
        lp = np.zeros(3)
        lq = np.zeros(4)
        mujoco.mju_rotVecQuat(lp, np.array(link.pose[:3], float), mq)
        mujoco.mju_mulQuat(lq, mq, quat_from_rpy(*link.pose[3:]))
        lp = lp + np.array(pose[:3], float)
        name = f"{m.name}/{link.name}"
        has_visual = any(not g.collide for g in link.geoms)
        if m.static:
            for i, g in enumerate(link.geoms):
                parent = spec.worldbody
                if g.kind == "plane":
                    parent = parent.add_body(name=f"{name}/{g.name or 'geom'}#{i}:plane")
                add_geom(spec, parent, g, True, f"{name}/", i, not has_visual, (lp, lq))
            continue
        body = spec.worldbody.add_body(name=name, pos=lp, quat=lq)
        body.add_freejoint(name=f"{name}/free")
        body.mass = max(link.mass, MIN_MASS)
        # centre of mass at the link origin; MuJoCo 4 leaves an unset ipos as NaN and then
        # compiles it to the body's own pos, which throws a dropped object sideways
        body.ipos = [0.0, 0.0, 0.0]
        inertia = link.inertia or (link.mass * 0.01,) * 3
        body.inertia = [max(i, MIN_INERTIA) for i in inertia]
        body.explicitinertial = True
        for i, g in enumerate(link.geoms):
            add_geom(spec, body, g, False, f"{name}/", i, not has_visual)
        roots.append(name)
    return roots


def spec_from_world(world: WorldDesc, timestep: float = 0.002) -> tuple[mujoco.MjSpec, dict]:
    """Build the world's spec; returns it and ``{model name: [top-level body names]}``."""
    spec = new_world_spec(timestep)
    spec.option.gravity = list(world.gravity)
    spec.modelname = world.name
    for light in world.lights:
        d = np.array(light.direction, float)
        spec.worldbody.add_light(
            name=f"light:{light.name}",
            pos=light.pose[:3],
            dir=d / max(np.linalg.norm(d), 1e-9),
            type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
            if light.directional
            else mujoco.mjtLightType.mjLIGHT_SPOT,
            diffuse=list(light.diffuse),
            castshadow=False,
        )
    bodies = {}
    for m in world.models:
        if m.name in bodies:
            raise SimulationError(f"{world.source}: duplicate model name '{m.name}'")
        bodies[m.name] = add_sdf_model(spec, m)
    return spec, bodies


def gazebo_colour(name: str | None) -> tuple | None:
    """RGBA of a ``Gazebo/<Colour>`` material name, or None."""
    return GAZEBO_COLOURS.get(name or "")
