"""COLLADA (``.dae``) meshes as triangle arrays for ``MjSpec`` (MuJoCo reads only STL/OBJ/MSH).

Reading follows Gazebo classic's ``ColladaLoader``: every ``<instance_geometry>`` reached from
the file's visual scene (``<scene><instance_visual_scene>``) is placed by the composed transforms
of its node hierarchy (``<matrix>``, ``<translate>``, ``<rotate>``, ``<scale>``, nested nodes and
``<instance_node>``), ``<asset><unit meter="...">`` scales the result to metres, and
``<up_axis>`` is ignored (Gazebo's import tutorial has users rotate a Y-up mesh in the SDF pose
themselves). Polylists and polygons are triangulated; lines and points are ignored. A file
without a visual scene contributes its library geometries untransformed.

Materials (``collada_parts``) give one colour per part, as Gazebo draws a DAE whose visual has
no material of its own: the effect's diffuse colour (an emission-only ``constant`` effect: its
emission), or for a diffuse texture the image itself, drawn by the file's texture coordinates
(``MeshPart.texcoords``, flipped to v = 0 at the image's top as Gazebo's loader does for OGRE;
the image looked up next to the ``.dae`` and in a Gazebo model's ``../materials/textures/``).
A texture whose triangles carry no texture coordinates is drawn in the image's mean colour, one
whose image is not found in neutral grey. Alpha comes from ``<transparent>`` scaled by
``<transparency>`` (``opaque="A_ONE"``: alpha times transparency; ``RGB_ZERO``: one minus
luminance times transparency); like Gazebo, a lone ``<transparency>`` without
``<transparent>`` is ignored, since exporters disagree on its direction. Triangles bound to
no material are neutral grey.

Parsing is done by ``pycollada``; the arrays are cached per (path, modification time, size), so a
mesh shared by a hundred robots is read once.
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path
from typing import NamedTuple
from urllib.parse import unquote, urlparse

import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.sim import textures

_CACHE_SIZE = 128  # distinct mesh files kept parsed
NEUTRAL_GREY = (0.7, 0.7, 0.7, 1.0)  # RGBA of triangles without a usable material colour
_LUMINANCE = np.array([0.212671, 0.715160, 0.072169])  # COLLADA's RGB_ZERO weights


class MeshPart(NamedTuple):
    """The triangles of one material of a COLLADA file.

    vertices : ndarray, shape (V, 3), float64, read-only; positions (m) in the COLLADA root frame,
        only those the part's triangles use.
    faces : ndarray, shape (F, 3), int32, read-only; indices into ``vertices``, outward winding.
    rgba : (r, g, b, a) in [0, 1]; the material's colour (``NEUTRAL_GREY`` without one; white
        when ``image`` is drawn).
    name : the material's name (its id when unnamed); ``""`` for triangles without material.
    texcoords : ndarray, shape (T, 2), float64, read-only, or None; (u, v) with v = 0 at the
        image's top, present when ``image`` is.
    texcoord_faces : ndarray, shape (F, 3), int32, read-only, or None; each triangle's indices
        into ``texcoords``.
    image : the texture image file drawn on the part, or None.
    """

    vertices: np.ndarray
    faces: np.ndarray
    rgba: tuple[float, float, float, float]
    name: str
    texcoords: np.ndarray | None = None
    texcoord_faces: np.ndarray | None = None
    image: str | None = None


class _Material(NamedTuple):
    name: str
    colour: tuple[float, float, float] | None  # diffuse (or emission) RGB
    image: str | None  # diffuse texture image, as the file names it
    alpha: float


class _Collada(NamedTuple):
    """A parsed file: per triangle set, (n, 3) vertices (m), (t, 3) local indices and the index
    of its material in ``materials`` (-1: none)."""

    vertices: tuple[np.ndarray, ...]
    faces: tuple[np.ndarray, ...]
    material: tuple[int, ...]
    materials: tuple[_Material, ...]
    #: per triangle set: (u, v) coordinates (n, 2) and (t, 3) indices into them, or None
    texcoords: tuple[tuple[np.ndarray, np.ndarray] | None, ...] = ()


def triangle_mesh_from_collada(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a COLLADA file, in the file's root frame, in metres.

    Parameters
    ----------
    path : str or Path
        The ``.dae`` file.

    Returns
    -------
    vertices : ndarray, shape (V, 3), float64, read-only
        Vertex positions (m) in the COLLADA root frame (node transforms and unit applied,
        ``up_axis`` not applied).
    faces : ndarray, shape (F, 3), int32, read-only
        Vertex indices of each triangle, counter-clockwise seen from outside (winding is
        flipped under a mirroring node transform so that it stays outward).

    Raises
    ------
    SimulationError
        The file does not exist, does not parse as COLLADA, or holds no triangles.
    """
    return _cached_triangles(*_cache_key(path))


def collada_parts(path: str | Path) -> tuple[MeshPart, ...]:
    """The triangles of a COLLADA file grouped by material, each with the material's colour.

    Parts come in the order their material first appears in the visual scene; together they
    hold every triangle of ``triangle_mesh_from_collada(path)``. Triangles without a bound
    material form one part named ``""`` in ``NEUTRAL_GREY``. A diffuse texture whose image is
    not found is warned about once and drawn in ``NEUTRAL_GREY``.

    Raises
    ------
    SimulationError
        As ``triangle_mesh_from_collada``.
    """
    return _cached_parts(*_cache_key(path))


def clear_mesh_cache() -> None:
    """Forget every parsed mesh (the cache also refreshes by itself when a file changes)."""
    _cached_parts.cache_clear()
    _cached_triangles.cache_clear()
    _cached_collada.cache_clear()


def _cache_key(path: str | Path) -> tuple[str, int, int]:
    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        raise SimulationError(f"COLLADA mesh '{p}' cannot be read: {exc.strerror}") from exc
    return str(p.resolve()), st.st_mtime_ns, st.st_size


@functools.lru_cache(maxsize=_CACHE_SIZE)
def _cached_collada(path: str, mtime_ns: int, size: int) -> _Collada:
    del mtime_ns, size  # cache key only: a rewritten file is read again
    with warnings.catch_warnings():
        # pycollada builds its transforms with numpy.matrix
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        return _parse(path)


@functools.lru_cache(maxsize=_CACHE_SIZE)
def _cached_triangles(path: str, mtime_ns: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    sets = _cached_collada(path, mtime_ns, size)
    vertices, faces = _joined(sets.vertices, sets.faces)
    vertices.flags.writeable = False
    faces.flags.writeable = False
    return vertices, faces


@functools.lru_cache(maxsize=_CACHE_SIZE)
def _cached_parts(path: str, mtime_ns: int, size: int) -> tuple[MeshPart, ...]:
    sets = _cached_collada(path, mtime_ns, size)
    parts = []
    for m in dict.fromkeys(sets.material):  # first-appearance order
        members = [i for i, k in enumerate(sets.material) if k == m]
        v, f = _joined([sets.vertices[i] for i in members], [sets.faces[i] for i in members])
        used, inverse = np.unique(f, return_inverse=True)  # drop vertices of other parts
        vertices = np.ascontiguousarray(v[used])
        faces = np.ascontiguousarray(inverse.reshape(-1, 3).astype(np.int32))
        vertices.flags.writeable = False
        faces.flags.writeable = False
        if m < 0:
            parts.append(MeshPart(vertices, faces, NEUTRAL_GREY, ""))
            continue
        mat = sets.materials[m]
        uv = (
            textures.joined_texcoords([sets.texcoords[i] for i in members])
            if sets.texcoords
            else None
        )
        image = _texture_file(mat.image, Path(path).parent) if mat.image and uv else None
        if image is None:
            parts.append(MeshPart(vertices, faces, _rgba_of(mat, path), mat.name))
        else:
            parts.append(
                MeshPart(vertices, faces, (1.0, 1.0, 1.0, mat.alpha), mat.name, *uv, str(image))
            )
    return tuple(parts)


def _joined(verts, faces) -> tuple[np.ndarray, np.ndarray]:
    """One (V, 3) float64 vertex array and (F, 3) int32 index array from per-set arrays."""
    offsets = np.cumsum([0] + [len(v) for v in verts[:-1]])
    vertices = np.concatenate(verts).astype(np.float64)
    tri = np.concatenate([f + o for f, o in zip(faces, offsets)]).astype(np.int32)
    return np.ascontiguousarray(vertices), np.ascontiguousarray(tri)


def _rgba_of(mat: _Material, dae_path: str) -> tuple[float, float, float, float]:
    rgb = mat.colour
    if mat.image is not None:
        image = _texture_file(mat.image, Path(dae_path).parent)
        rgb = _mean_rgb_of_image(image, mat, dae_path) if image is not None else None
        if image is None:
            warnings.warn(
                f"COLLADA mesh '{dae_path}': texture image '{mat.image}' of material "
                f"'{mat.name}' is not found next to the file or in ../materials/textures; "
                "the part is drawn in neutral grey (put the image there to see its colour)",
                stacklevel=4,
            )
    if rgb is None:
        return (*NEUTRAL_GREY[:3], mat.alpha)
    r, g, b = (float(np.clip(c, 0.0, 1.0)) for c in rgb)
    return (r, g, b, mat.alpha)


def _texture_file(written: str, folder: Path) -> Path | None:
    """The image file a COLLADA ``<init_from>`` names: as written (absolute, or relative to the
    ``.dae``), by its bare name next to the ``.dae``, or in ``../materials/textures`` (Gazebo's
    model layout); None when none exists."""
    text = written.strip()
    if text.startswith("file:"):
        text = urlparse(text).path
    rel = Path(unquote(text))
    for candidate in (
        folder / rel,
        folder / rel.name,
        folder.parent / "materials/textures" / rel.name,
    ):
        if candidate.is_file():
            return candidate
    return None


def _mean_rgb_of_image(image: Path, mat: _Material, dae_path: str) -> tuple[float, ...] | None:
    """Mean RGB in [0, 1] of an image's pixels weighted by their alpha; None (and a warning)
    when the file does not decode or is fully transparent."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(image) as im:
            im = im.convert("RGBA")
            im.thumbnail((128, 128))  # area-averaged: the mean barely moves, big images cost less
            px = np.asarray(im, dtype=np.float64) / 255.0
    except (OSError, UnidentifiedImageError, ValueError) as exc:
        warnings.warn(
            f"COLLADA mesh '{dae_path}': texture image '{image}' of material '{mat.name}' "
            f"does not decode ({exc}); the part is drawn in neutral grey",
            stacklevel=5,
        )
        return None
    weight = px[..., 3].ravel()
    if weight.sum() <= 0:
        return None
    return tuple(np.average(px[..., :3].reshape(-1, 3), axis=0, weights=weight))


def _parse(path: str) -> _Collada:
    import collada  # imported here (0.3 s): only worlds with .dae meshes pay for it
    from collada.common import DaeBrokenRefError, DaeUnsupportedError

    try:
        # unsupported extras (animations, skins) and broken references do not stop the rest
        # of the file from loading, as in Gazebo; what they dropped is reported below
        dae = collada.Collada(path, ignore=[DaeUnsupportedError, DaeBrokenRefError])
    except Exception as exc:  # pycollada raises DaeError, lxml and ValueError alike
        raise SimulationError(
            f"COLLADA mesh '{path}' does not parse ({type(exc).__name__}: {exc}); "
            "re-export it from a modelling tool or convert it to STL/OBJ"
        ) from exc
    unit = 1.0
    if dae.assetInfo is not None and dae.assetInfo.unitmeter is not None:
        unit = float(dae.assetInfo.unitmeter)
        if not np.isfinite(unit) or unit <= 0:
            raise SimulationError(
                f"COLLADA mesh '{path}': <unit meter='{unit}'> must be a positive number"
            )
    try:
        verts, faces, mats, uvs = _triangles_of_scene(dae)
        used = list(dict.fromkeys(m for m in mats if m is not None))  # first-use order
        slots = {id(m): i for i, m in enumerate(used)}
        materials = tuple(_material_of(m) for m in used)
    except SimulationError:
        raise
    except Exception as exc:  # malformed index arrays surface while binding
        raise SimulationError(
            f"COLLADA mesh '{path}' has malformed geometry or materials "
            f"({type(exc).__name__}: {exc})"
        ) from exc
    dropped = "; ".join(dict.fromkeys(str(e) for e in dae.errors))  # pycollada's own words
    if not faces:
        raise SimulationError(
            f"COLLADA mesh '{path}' holds no triangles (only lines, points or empty geometry "
            "in its visual scene); a <mesh> needs <triangles>, <polylist> or <polygons>"
            + (f"; parts that did not load: {dropped}" if dropped else "")
        )
    if dropped:
        warnings.warn(
            f"COLLADA mesh '{path}': parts that did not load are left out: {dropped}",
            stacklevel=2,
        )
    vertices = tuple(np.asarray(v, dtype=np.float64) * unit for v in verts)
    if not all(np.all(np.isfinite(v)) for v in vertices):
        raise SimulationError(f"COLLADA mesh '{path}' has non-finite vertex coordinates")
    material = tuple(-1 if m is None else slots[id(m)] for m in mats)
    return _Collada(vertices, tuple(faces), material, materials, tuple(uvs))


def _triangles_of_scene(dae) -> tuple[list[np.ndarray], list[np.ndarray], list, list]:
    """Per triangle set: (n, 3) transformed vertices, (t, 3) local indices, the pycollada
    ``Material`` it is bound to (None: unbound) and its texture coordinates (or None)."""
    from collada.polylist import BoundPolylist
    from collada.triangleset import BoundTriangleSet

    if dae.scene is not None:
        bound = list(dae.scene.objects("geometry"))
    else:
        bound = [g.bind(np.identity(4), {}) for g in dae.geometries]
    verts, faces, mats, uvs = [], [], [], []
    for geom in bound:
        mirrored = np.linalg.det(np.asarray(geom.matrix, float)[:3, :3]) < 0
        for prim in geom.primitives():
            if isinstance(prim, BoundPolylist):  # BoundPolygons is a BoundPolylist too
                prim = prim.triangleset()
            if not isinstance(prim, BoundTriangleSet) or prim.vertex is None:
                continue  # lines, points
            idx = np.asarray(prim.vertex_index, dtype=np.int64).reshape(-1, 3)
            if len(idx) == 0:
                continue
            v = np.asarray(prim.vertex, dtype=np.float64).reshape(-1, 3)
            if idx.min() < 0 or idx.max() >= len(v):
                raise SimulationError(
                    f"COLLADA mesh '{dae.filename}': geometry '{geom.original.id}' has triangle "
                    f"indices {int(idx.min())}..{int(idx.max())} for {len(v)} vertices"
                )
            uv = textures.texcoords_of_triangle_set(prim, len(idx))
            if mirrored:
                idx = idx[:, ::-1]
                uv = uv if uv is None else (uv[0], uv[1][:, ::-1])
            verts.append(v)
            faces.append(idx)
            mats.append(_bound_material(dae, prim))
            uvs.append(uv)
    return verts, faces, mats, uvs


def _bound_material(dae, prim):
    """The ``Material`` a triangle set uses: bound through ``<bind_material>``, or (as Gazebo
    falls back to) the material whose id is the set's ``material`` symbol; None otherwise."""
    if prim.material is not None:
        return prim.material
    symbol = getattr(prim.original, "material", None)
    return dae.materials.get(symbol) if symbol else None


def _material_of(mat) -> _Material:
    """Colour, texture image and alpha of a pycollada ``Material`` (profile_COMMON effect)."""
    from collada.material import OPAQUE_MODE, Map

    name = mat.name or mat.id or ""
    fx = mat.effect
    if fx is None:
        return _Material(name, None, None, 1.0)
    colour, image = None, None
    diffuse = fx.diffuse
    if diffuse is None and fx.shadingtype == "constant":  # unlit: its emission is its colour
        diffuse = fx.emission
    if isinstance(diffuse, Map):
        surface = getattr(diffuse.sampler, "surface", None)
        cimage = getattr(surface, "image", None)
        image = getattr(cimage, "path", None) or ""
    elif diffuse is not None:
        colour = tuple(float(c) for c in np.asarray(diffuse, float).ravel()[:3])
    alpha = 1.0
    transparent = fx.transparent
    if transparent is not None and not isinstance(transparent, Map):
        t = np.asarray(transparent, float).ravel()
        written = any(str(e.tag).endswith("transparency") for e in fx.xmlnode.iter())
        amount = float(fx.transparency) if written else 1.0  # COLLADA's default is 1
        if fx.opaque_mode == OPAQUE_MODE.RGB_ZERO:
            alpha = 1.0 - amount * float(_LUMINANCE @ t[:3])
        else:  # A_ONE, the default
            alpha = (t[3] if len(t) > 3 else 1.0) * amount
    return _Material(name, colour, image, float(np.clip(alpha, 0.0, 1.0)))
