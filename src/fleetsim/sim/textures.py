"""Textures as Gazebo classic draws them: image files on shapes by their UV coordinates.

Gazebo draws a texture by the UV coordinates of the shape's mesh: every face of a box carries
the whole image, stretched over it (``common::MeshManager::CreateBox``), so a long wall shows
long, blurry bricks and a 0.15 m marker face shows the whole marker. MuJoCo's own mapping of a
2D texture onto a primitive box repeats it by size instead, so a textured box, cylinder or
sphere visual becomes a mesh with the texture coordinates Gazebo's meshes have (``box_uv_mesh``,
``cylinder_uv_mesh``, ``sphere_uv_mesh``) and a 2D texture (``add_texture_material``).
MuJoCo reads texture coordinates with v = 0 at the image's top row, as OGRE does, so Gazebo's
UVs are used unchanged. COLLADA files bring their own UVs (``texcoords_of_triangle_set``).
OGRE material scripts, which name the images, are read by ``ogre_scripts``.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from fleetsim.errors import SimulationError

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tga", ".gif", ".tif", ".tiff")

# Gazebo's CreateBox: corner signs, the corners of each face (outward winding) and the UVs of a
# face's four corners, in that order; faces -y, +y, +z, -x, -z, +x
_CORNERS = np.array(
    [
        [-1, -1, -1],
        [-1, -1, 1],
        [1, -1, 1],
        [1, -1, -1],
        [-1, 1, -1],
        [-1, 1, 1],
        [1, 1, 1],
        [1, 1, -1],
    ],
    float,
)
_FACE_CORNERS = ((2, 1, 0, 3), (5, 6, 7, 4), (2, 6, 5, 1), (1, 5, 4, 0), (0, 4, 7, 3), (6, 2, 3, 7))
_FACE_UV = np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
_FACE_TRIANGLES = ((0, 1, 2), (2, 3, 0))


def checked_image(path: str | Path, owner: str) -> Path:
    """``path`` if it is an image file MuJoCo can load, else a `SimulationError` naming it and
    ``owner``."""
    p = Path(path)
    if not p.is_file():
        raise SimulationError(f"{owner}: texture image '{p}' not found")
    if p.suffix.lower() not in IMAGE_SUFFIXES:
        raise SimulationError(
            f"{owner}: texture image '{p}' is not an image file fleetsim reads "
            f"({', '.join(IMAGE_SUFFIXES)})"
        )
    return p


def box_uv_mesh(size) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A box as Gazebo's renderer meshes it: 4 vertices and 2 triangles per face, the whole
    texture stretched over each face.

    Parameters
    ----------
    size : (3,) full side lengths (m) along x, y, z.

    Returns
    -------
    vertices : ndarray, shape (24, 3), float64; metres, box centred on the origin.
    faces : ndarray, shape (12, 3), int32; vertex indices, counter-clockwise from outside.
    texcoords : ndarray, shape (24, 2), float64; (u, v) per vertex, v = 0 at the image's top.
    """
    half = np.asarray(size, float) / 2
    vertices = np.array([_CORNERS[c] * half for face in _FACE_CORNERS for c in face])
    texcoords = np.tile(_FACE_UV, (6, 1))
    faces = np.array(
        [[4 * f + i for i in tri] for f in range(6) for tri in _FACE_TRIANGLES], np.int32
    )
    return vertices, faces, texcoords


def cylinder_uv_mesh(radius: float, length: float, segments: int = 32):
    """A cylinder (axis z) as Gazebo's renderer meshes it (``CreateCylinder``, one ring of
    ``segments``): the image wrapped once round the side (u with the angle from +y towards +x,
    v = 0 at the bottom rim, 1 at the top), each cap's rim at v = 1 (top) or 0 (bottom) with
    its centre at (0, 0).

    Returns vertices (V, 3) m, faces (F, 3) int32 counter-clockwise from outside, and per-face
    texture coordinates: texcoords (T, 2) and texcoord faces (F, 3) int32 (positions are welded
    where Gazebo repeats them for the texture seam, the coordinates are not).
    """
    n = segments + 1
    a = np.arange(n) * (2 * np.pi / segments)
    ring = np.stack([radius * np.sin(a), radius * np.cos(a)], axis=1)  # Gazebo: x sin, y cos
    u = np.arange(n) / segments
    h = length / 2
    # vertex blocks (positions and texcoords in step): bottom ring, top ring (the side), then
    # each cap's rim and centre
    pos = [np.c_[ring, np.full(n, -h)], np.c_[ring, np.full(n, h)]]
    uv = [np.c_[u, np.zeros(n)], np.c_[u, np.ones(n)]]
    tri = []
    for k in range(segments):
        tri += [[k, k + 1, n + k + 1], [k, n + k + 1, n + k]]
    for z, v, first in ((h, 1.0, 2 * n), (-h, 0.0, 3 * n + 1)):
        pos += [np.c_[ring, np.full(n, z)], np.array([[0.0, 0.0, z]])]
        uv += [np.c_[u, np.full(n, v)], np.zeros((1, 2))]
        tri += [[first + n, first + k, first + k + 1] for k in range(segments)]
    tri = np.array(tri)
    return _welded(np.concatenate(pos), tri, np.concatenate(uv), tri.copy())


def sphere_uv_mesh(radius: float, rings: int = 32, segments: int = 32):
    """A sphere as Gazebo's renderer meshes it (``CreateSphere``): poles on the y axis, u with
    the angle about y, v = 0 at the +y pole and 1 at the -y pole. Returns as
    ``cylinder_uv_mesh``; the triangles that collapse at the poles are left out."""
    ring_a = np.arange(rings + 1) * (np.pi / rings)
    seg_a = np.arange(segments + 1) * (2 * np.pi / segments)
    r0 = radius * np.sin(ring_a)[:, None]
    y = radius * np.cos(ring_a)[:, None] * np.ones((1, segments + 1))
    vertices = np.stack([r0 * np.sin(seg_a), y, r0 * np.cos(seg_a)], axis=-1).reshape(-1, 3)
    u, v = np.meshgrid(np.arange(segments + 1) / segments, np.arange(rings + 1) / rings)
    texcoords = np.stack([u.ravel(), v.ravel()], axis=1)
    n = segments + 1
    tri = []
    for r in range(rings):
        for k in range(segments):
            a, b, c, d = r * n + k, r * n + k + 1, (r + 1) * n + k + 1, (r + 1) * n + k
            tri += [[a, c, b], [a, d, c]]
    tri = np.array(tri)
    return _welded(vertices, tri, texcoords, tri.copy())


def _welded(vertices, faces, texcoords, texcoord_faces):
    """Merge repeated positions (texture seams, poles) and drop the triangles that collapse;
    faces are turned to point away from the centroid (all shapes here are convex)."""
    key = np.round(vertices, 9)
    unique, inverse = np.unique(key, axis=0, return_inverse=True)
    f = inverse.reshape(-1)[faces]
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    f, tf = f[keep], texcoord_faces[keep]
    a, b, c = (unique[f[:, i]] for i in range(3))
    outward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c - 3 * unique.mean(0)) > 0
    f[~outward] = f[~outward][:, ::-1]
    tf[~outward] = tf[~outward][:, ::-1]
    return unique, f.astype(np.int32), texcoords, tf.astype(np.int32)


TEXTURED_SHAPES = ("box", "cylinder", "sphere")


def add_textured_mesh(spec: mujoco.MjSpec, kind: str, size) -> str:
    """The mesh asset (one per kind and size in a spec) of a textured ``box`` (full sizes),
    ``cylinder`` (radius, length) or ``sphere`` (radius,) with Gazebo's texture coordinates."""
    name = f"tex{kind}:" + "x".join(f"{float(s):.6g}" for s in size)
    if spec.mesh(name) is None:
        if kind == "box":
            v, f, t = box_uv_mesh(size)
            tf = f
        elif kind == "cylinder":
            v, f, t, tf = cylinder_uv_mesh(*size[:2])
        elif kind == "sphere":
            v, f, t, tf = sphere_uv_mesh(size[0])
        else:
            raise SimulationError(
                f"no texture coordinates for a {kind}; textured: {TEXTURED_SHAPES}"
            )
        mesh = spec.add_mesh(
            name=name,
            uservert=v.ravel(),
            userface=f.ravel(),
            usertexcoord=t.ravel(),
            userfacetexcoord=tf.ravel(),
        )
        # a visual has no mass; a marker's 0.1 mm thick face is too thin for a volume inertia
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
    return name


def add_texture_material(spec: mujoco.MjSpec, image: str | Path, owner: str) -> str:
    """A material drawing ``image`` by the geom's texture coordinates (added once per image
    file in a spec); errors name the image and ``owner``."""
    path = checked_image(image, owner).resolve()
    name = f"tex:{path}"
    if spec.material(name) is None:
        spec.add_texture(name=name, type=mujoco.mjtTexture.mjTEXTURE_2D, file=str(path))
        mat = spec.add_material(name=name)
        mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = name
    return name


def texcoords_of_triangle_set(prim, n_triangles: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The first texture coordinate set of a pycollada triangle set: (n, 2+) values and (t, 3)
    indices into them; None when it has none or they do not fit its ``n_triangles``."""
    sets = getattr(prim, "texcoordset", None) or ()
    index_sets = getattr(prim, "texcoord_indexset", None) or ()
    if not sets or not index_sets:
        return None
    uv = np.asarray(sets[0], dtype=np.float64)
    uv = uv.reshape(-1, uv.shape[-1] if uv.ndim > 1 else 2)
    ti = np.asarray(index_sets[0], dtype=np.int64).reshape(-1, 3)
    if len(ti) != n_triangles or len(uv) == 0 or ti.min() < 0 or ti.max() >= len(uv):
        return None
    return uv, ti


def joined_texcoords(sets) -> tuple[np.ndarray, np.ndarray] | None:
    """One texture coordinate array for triangle sets drawn as one mesh.

    Parameters
    ----------
    sets : list of ``((n, 2+) uv, (t, 3) indices)`` per triangle set (COLLADA convention, v
        growing upwards), or None entries for sets without coordinates.

    Returns
    -------
    (T, 2) float64 uv with v = 0 at the image's top (Gazebo's loader flips COLLADA's v for
    OGRE; MuJoCo reads v the same way) and (F, 3) int32 indices, both read-only; None unless
    every set has coordinates.
    """
    if not sets or any(s is None for s in sets):
        return None
    offsets = np.cumsum([0] + [len(s[0]) for s in sets[:-1]])
    uv = np.concatenate([s[0][:, :2] for s in sets]).astype(np.float64)
    uv[:, 1] = 1.0 - uv[:, 1]
    faces = np.concatenate([s[1] + o for s, o in zip(sets, offsets, strict=True)]).astype(np.int32)
    uv, faces = np.ascontiguousarray(uv), np.ascontiguousarray(faces)
    uv.flags.writeable = False
    faces.flags.writeable = False
    return uv, faces
