"""Mesh assets of a spec, and the collision of static non-convex meshes as convex parts.

Mesh assets are added once per spec for each (file, version, scale) and shared by every model
that uses them. A static collision mesh (a building, Gazebo's ``model://willowgarage``) is
decomposed (``decompose.convex_decomposition``, cached on disk; a convex mesh is its own single
part) and becomes, at the geom's pose:

- one collision geom per convex part, named ``<prefix><name>#<index>:cvx<k>``, in
  ``HULL_GROUP`` (hidden in renders; lasers skip it);
- a ray-only copy of the file's true triangles, ``<prefix><name>#<index>:rays``, in
  ``RAY_GROUP`` with no contacts and no mass: lasers cast against its triangles and
  ``mj_ray`` hits it, so sensors see the walls where the mesh puts them, not the parts' hulls;
- when the link has no visual, a visual copy of the same triangles (what cameras render).

Movable (robot) meshes keep MuJoCo's rule and collide as their convex hull, as with Gazebo's ODE.
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import mujoco
import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.sim import decompose
from fleetsim.sim.mesh_files import triangle_mesh
from fleetsim.sim.meshes import collada_parts, triangle_mesh_from_collada
from fleetsim.sim.world import GeomDesc

G = mujoco.mjtGeom
VISUAL_GROUP = 1
RAY_GROUP = 4  # true triangles of decomposed meshes: seen by rays, not by contacts or cameras
HULL_GROUP = 5  # convex parts of decomposed meshes: contacts only
MESH_FORMATS = (".stl", ".obj", ".msh", ".dae")  # mesh files add_geom reads
MIN_PART_AREA = 1e-12  # m^2; a material part with less surface draws nothing and is left out


def mesh_file_of(g: GeomDesc, prefix: str) -> Path | None:
    """The mesh file of a mesh geom; None (with a warning) when its format is not read."""
    owner = prefix.rstrip("/")
    mesh_file = Path(g.mesh or "")
    if mesh_file.suffix.lower() not in MESH_FORMATS:
        warnings.warn(
            f"mesh '{g.mesh}' of geom '{g.name}' in '{owner}': fleetsim reads "
            f"{'/'.join(s.lstrip('.').upper() for s in MESH_FORMATS)} meshes; the shape is skipped",
            stacklevel=4,
        )
        return None
    if not mesh_file.is_file():
        raise SimulationError(
            f"mesh file '{g.mesh}' of geom '{g.name}' in '{owner}' does not exist; "
            "fix the <mesh> filename/uri (package:// and model:// must resolve to a file)"
        )
    return mesh_file


def mesh_asset_name(mesh_file: Path, scale: list[float]) -> str:
    """Asset name of a mesh file at a scale: one per (file, version, scale) in a spec."""
    st = mesh_file.stat()
    key = f"{mesh_file.resolve()}|{st.st_mtime_ns}|{st.st_size}|{scale}"
    return f"mesh:{mesh_file.name}:{hashlib.sha1(key.encode()).hexdigest()[:12]}"


def add_user_mesh(
    spec, name: str, vertices: np.ndarray, faces: np.ndarray, scale, texcoords=None
) -> None:
    """A mesh asset from arrays; ``texcoords`` is ``((T, 2) uv, (F, 3) indices)`` or None."""
    mesh = spec.add_mesh(name=name, uservert=vertices.ravel(), userface=faces.ravel(), scale=scale)
    if texcoords is not None:  # drawn with a texture: (u, v) per triangle corner
        mesh.usertexcoord = np.ascontiguousarray(texcoords[0]).ravel()
        mesh.userfacetexcoord = np.ascontiguousarray(texcoords[1]).ravel()
    # shell inertia: COLLADA visuals are often open surfaces (a floor, a sign) with no volume;
    # bodies carry explicit inertia, so the mesh's own inertia only places its frame
    mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL


def add_mesh_asset(spec, g: GeomDesc, prefix: str) -> str | None:
    """The mesh asset of a mesh geom, added once per spec for each (file, version, scale) and
    shared by every model that uses it (a hundred robots compile one mesh, and a deleted robot
    can be spawned again); None when the format is not read."""
    mesh_file = mesh_file_of(g, prefix)
    if mesh_file is None:
        return None
    scale = [float(v) for v in g.size]
    mesh_name = mesh_asset_name(mesh_file, scale)
    if spec.mesh(mesh_name) is not None:
        return mesh_name
    if mesh_file.suffix.lower() != ".dae":
        spec.add_mesh(name=mesh_name, file=str(mesh_file), scale=scale)
        return mesh_name
    vertices, faces = triangle_mesh_from_collada(mesh_file)
    if len(vertices) < 4:
        raise SimulationError(
            f"mesh '{g.mesh}' of geom '{g.name}' in '{prefix.rstrip('/')}' has "
            f"{len(vertices)} vertices; MuJoCo needs at least 4 (use a box or a thin solid instead)"
        )
    add_user_mesh(spec, mesh_name, vertices, faces, scale)
    return mesh_name


def add_part_mesh_assets(spec, g: GeomDesc, prefix: str) -> list[tuple[str, tuple, str]] | None:
    """Mesh assets ``(name, rgba, image)`` of the material parts of a ``.dae`` geom, added once
    per spec for each (file, version, scale, part); ``image`` is the texture file drawn by the
    part's texture coordinates, or None. None when the file has no materials (it is then one
    plain mesh). Parts without surface (degenerate triangles) are left out; a one-triangle part
    gets its centroid as an unused fourth vertex, MuJoCo's minimum."""
    mesh_file = mesh_file_of(g, prefix)
    parts = collada_parts(mesh_file)
    if all(not p.name for p in parts):
        return None
    scale = [float(v) for v in g.size]
    base = mesh_asset_name(mesh_file, scale)
    assets = []
    for k, part in enumerate(parts):
        name = f"{base}:{k}"
        if spec.mesh(name) is None:
            v = part.vertices
            a, b, c = (v[part.faces[:, i]] * scale for i in range(3))
            if 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() < MIN_PART_AREA:
                continue
            if len(v) < 4:
                v = np.vstack([v, v.mean(axis=0)])
            uv = None if part.image is None else (part.texcoords, part.texcoord_faces)
            add_user_mesh(spec, name, v, part.faces, scale, uv)
        assets.append((name, part.rgba, part.image))
    return assets


def add_decomposed_mesh(
    spec, body, g: GeomDesc, prefix: str, index: int, kw: dict, shown: bool
) -> bool:
    """Add a static collision mesh as its convex parts plus a ray-only copy (see the module
    docstring); a convex mesh is one part, and lasers still see its triangles (not the
    bounding box the slicer would make of a mesh geom). ``kw`` holds the geom's ``pos`` and
    ``quat`` in ``body``. Returns True when the geom was handled."""
    mesh_file = mesh_file_of(g, prefix)
    if mesh_file is None:
        return True  # format not read: warned, nothing to add
    vertices, faces = triangle_mesh(mesh_file)
    scale = [float(v) for v in g.size]
    result = decompose.convex_decomposition(
        vertices * np.asarray(scale), faces, decompose.DEFAULT_PARAMS
    )
    model, _, link = prefix.rstrip("/").partition("/")
    if result.problems:
        warnings.warn(
            f"model '{model}' link '{link}' collision '{g.name}': mesh '{mesh_file}' does not "
            f"decompose well into convex parts ({'; '.join(result.problems)}); it may collide "
            "bigger than it is: give it box collisions, or split the mesh into simpler pieces",
            stacklevel=4,
        )
    base = mesh_asset_name(mesh_file, scale)
    name = f"{prefix}{g.name or 'geom'}#{index}"
    for k, part in enumerate(result.parts):
        box = box_of(part)
        if box is not None:  # most wall prisms: boxes collide 2x cheaper than meshes
            centre, half, yaw = box
            pos, quat = _in_frame(kw, centre, yaw)
            geom = body.add_geom(
                name=f"{name}:cvx{k}", type=G.mjGEOM_BOX, size=half, pos=pos, quat=quat
            )
        else:
            asset = f"{base}:cvx{k}"
            if spec.mesh(asset) is None:
                spec.add_mesh(name=asset, uservert=np.ascontiguousarray(part).ravel())
            geom = body.add_geom(name=f"{name}:cvx{k}", type=G.mjGEOM_MESH, meshname=asset, **kw)
        geom.group = HULL_GROUP
        geom.contype, geom.conaffinity = 2, 1
        if g.friction is not None:
            geom.friction = [g.friction[0], 0.005, 0.0001]
        geom.rgba = [0.6, 0.6, 0.62, 1.0]
    # the ray copy: the welded triangles, each once (a double-sided COLLADA mesh holds every
    # triangle twice, which would double the lasers' work)
    ray_mesh = f"{base}:rays"
    if spec.mesh(ray_mesh) is None:
        wv, wf = decompose.weld(vertices * np.asarray(scale), faces)
        add_user_mesh(spec, ray_mesh, wv, wf, [1.0, 1.0, 1.0])
    copies = [(f"{name}:rays", RAY_GROUP, ray_mesh)]
    if shown:
        copies.append((f"{name}:shown", VISUAL_GROUP, add_mesh_asset(spec, g, prefix)))
    for geom_name, group, mesh in copies:
        geom = body.add_geom(name=geom_name, type=G.mjGEOM_MESH, meshname=mesh, **kw)
        geom.group = group
        geom.contype = geom.conaffinity = 0
        geom.density = 0
        geom.rgba = list(g.rgba) if g.rgba else [0.7, 0.7, 0.7, 1.0]
    return True


def box_of(part: np.ndarray, tol: float = 1e-4):
    """An upright rectangular prism's box: centre (3,), half sizes (3,) and yaw (rad) in the
    part's frame; None for any other part. ``part`` is (8, 3) in any order: 4 corners at one
    height and the same 4 at another."""
    if part.shape != (8, 3):
        return None
    part = part[np.argsort(part[:, 2], kind="stable")]
    bottom, top = part[:4], part[4:]
    if np.ptp(bottom[:, 2]) > tol or np.ptp(top[:, 2]) > tol:
        return None

    def ring(p):
        c = p[:, :2].mean(axis=0)
        return p[np.argsort(np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0])), :2]

    rb, rt = ring(bottom), ring(top)
    if not np.allclose(rb, rt, atol=tol):
        return None
    e = np.roll(rb, -1, axis=0) - rb
    length = np.linalg.norm(e, axis=1)
    dots = np.abs(np.einsum("ij,ij->i", e, np.roll(e, -1, 0)))
    if length.min() <= tol or np.any(dots > tol * length.max() ** 2):
        return None
    z0, z1 = bottom[0, 2], top[0, 2]
    half = np.array([length[0] / 2, length[1] / 2, (z1 - z0) / 2])
    if half[2] <= tol:
        return None
    centre = np.array([*rb.mean(axis=0), 0.5 * (z0 + z1)])
    return centre, half, float(np.arctan2(e[0, 1], e[0, 0]))


def _in_frame(kw: dict, centre: np.ndarray, yaw: float) -> tuple[np.ndarray, np.ndarray]:
    """Position and orientation in the body of a box given in the geom frame ``kw``."""
    pos, quat = np.asarray(kw["pos"], float), np.asarray(kw["quat"], float)
    p, q = np.zeros(3), np.zeros(4)
    mujoco.mju_rotVecQuat(p, centre, quat)
    mujoco.mju_mulQuat(q, quat, np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)]))
    return p + pos, q
