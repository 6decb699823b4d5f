"""Textures as Gazebo classic applies them: OGRE material scripts, image files, UV-mapped shapes.

Gazebo draws a texture by the UV coordinates of the shape's mesh: every face of a box carries
the whole image, stretched over it (``common::MeshManager::CreateBox``), so a long wall shows
long, blurry bricks and a 0.15 m marker face shows the whole marker. MuJoCo's own mapping of a
2D texture onto a primitive box repeats it by size instead, so a textured box, cylinder or
sphere visual becomes a mesh with the texture coordinates Gazebo's meshes have (``box_uv_mesh``,
``cylinder_uv_mesh``, ``sphere_uv_mesh``) and a 2D texture (``add_texture_material``).
MuJoCo reads texture coordinates with v = 0 at the image's top row, as OGRE does, so Gazebo's
UVs are used unchanged.

OGRE material scripts (``<material><script><uri>…/materials/scripts</uri>
<uri>…/materials/textures</uri><name>Marker</name>``) are parsed into their block structure
(``material`` > ``technique`` > ``pass`` > ``texture_unit`` > ``texture``), with ``//`` comments
and ``material Child : Parent`` inheritance; the first texture of the first technique is the
one drawn, and a pass's ``diffuse`` gives the colour of an untextured material. The texture
image is looked up as OGRE's resource locations do: in every folder the script's URIs name.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
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


@dataclass
class OgreBlock:
    """One statement of an OGRE script: its words, its ``{ }`` children and its line."""

    words: list[str]
    line: int
    children: list[OgreBlock] = field(default_factory=list)

    def blocks(self, keyword: str) -> list[OgreBlock]:
        return [c for c in self.children if c.words and c.words[0] == keyword]


@dataclass(frozen=True)
class OgreMaterial:
    """What fleetsim draws of an OGRE ``material``: its texture image name and colour."""

    name: str
    texture: str | None  # image file name as the script writes it
    diffuse: tuple[float, float, float, float] | None
    source: Path
    line: int


_TOKEN = re.compile(r"\{|\}|\n|[^\s{}]+")


def parse_ogre_script(text: str, source: Path) -> list[OgreBlock]:
    """The top-level blocks of an OGRE script (``material``, ``vertex_program``, ...).

    Raises `SimulationError` naming the file and line on unbalanced braces.
    """
    text = re.sub(r"//[^\n]*", "", text)
    root = OgreBlock([], 0)
    stack = [root]
    words: list[str] = []
    line = 1
    start = 1
    for tok in _TOKEN.findall(text):
        if tok == "\n" or tok in "{}":
            if words:
                stack[-1].children.append(OgreBlock(words, start))
                words = []
            if tok == "\n":
                line += 1
            elif tok == "{":
                if not stack[-1].children:
                    raise SimulationError(f"{source}:{line}: '{{' opens a block without a header")
                stack.append(stack[-1].children[-1])
            else:
                if len(stack) == 1:
                    raise SimulationError(f"{source}:{line}: '}}' closes no block")
                stack.pop()
            continue
        if not words:
            start = line
        words.append(tok)
    if words:
        stack[-1].children.append(OgreBlock(words, start))
    if len(stack) > 1:
        raise SimulationError(
            f"{source}:{stack[-1].line}: block '{' '.join(stack[-1].words)}' is never closed"
        )
    return root.children


def _material_name_and_parent(block: OgreBlock) -> tuple[str, str | None]:
    rest = " ".join(block.words[1:])
    name, _, parent = rest.partition(":")
    return name.strip(), parent.strip() or None


def materials_of_script(text: str, source: Path) -> dict[str, OgreMaterial]:
    """Every ``material`` of a script by name, inheritance (``Child : Parent``) resolved within
    the script."""
    raw: dict[str, tuple[OgreBlock, str | None]] = {}
    for block in parse_ogre_script(text, source):
        if block.words[0] == "material" and len(block.words) > 1:
            name, parent = _material_name_and_parent(block)
            raw[name] = (block, parent)
    out: dict[str, OgreMaterial] = {}

    def resolve(name: str, seen: tuple[str, ...] = ()) -> OgreMaterial:
        if name in out:
            return out[name]
        block, parent = raw[name]
        texture, diffuse = _first_texture_and_colour(block, source)
        if parent is not None and parent in raw and parent not in seen:
            base = resolve(parent, (*seen, name))
            texture = texture or base.texture
            diffuse = diffuse or base.diffuse
        out[name] = OgreMaterial(name, texture, diffuse, source, block.line)
        return out[name]

    for name in raw:
        resolve(name)
    return out


def _first_texture_and_colour(block: OgreBlock, source: Path):
    texture, diffuse = None, None
    for technique in block.blocks("technique")[:1]:
        for pas in technique.blocks("pass"):
            for stmt in pas.children:
                if stmt.words[0] == "diffuse" and diffuse is None and len(stmt.words) >= 4:
                    try:
                        v = [float(w) for w in stmt.words[1:5]]
                    except ValueError:
                        raise SimulationError(
                            f"{source}:{stmt.line}: 'diffuse' needs numbers, got "
                            f"'{' '.join(stmt.words[1:])}'"
                        ) from None
                    diffuse = (*v[:3], v[3] if len(v) > 3 else 1.0)
            for unit in pas.blocks("texture_unit"):
                for stmt in unit.blocks("texture"):
                    if texture is None and len(stmt.words) > 1:
                        texture = stmt.words[1]
    return texture, diffuse


def find_ogre_material(name: str, folders: list[Path]) -> OgreMaterial | None:
    """The material ``name`` from the ``.material`` scripts in ``folders`` (None if absent)."""
    for folder in folders:
        if not folder.is_dir():
            continue
        for f in sorted(folder.glob("*.material")):
            found = materials_of_script(f.read_text(errors="replace"), f).get(name)
            if found is not None:
                return found
    return None


def texture_file(material: OgreMaterial, folders: list[Path], owner: str) -> Path:
    """The image file of a material's texture, looked up in OGRE's resource folders (the
    script's URIs, the script's own folder and its ``../textures``).

    Raises `SimulationError` naming the image, the material script and ``owner`` (model and
    file) when the image is in none of them.
    """
    assert material.texture is not None
    here = material.source.parent
    candidates = [*folders, here, here.parent / "textures"]
    for folder in dict.fromkeys(candidates):
        f = folder / material.texture
        if f.is_file():
            return f
    looked = ", ".join(str(d) for d in dict.fromkeys(candidates))
    raise SimulationError(
        f"{owner}: texture image '{material.texture}' of material '{material.name}' "
        f"({material.source}:{material.line}) not found; looked in {looked}"
    )


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
