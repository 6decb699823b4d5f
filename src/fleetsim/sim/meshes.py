"""COLLADA (``.dae``) meshes as triangle arrays for ``MjSpec`` (MuJoCo reads only STL/OBJ/MSH).

Reading follows Gazebo classic's ``ColladaLoader``: every ``<instance_geometry>`` reached from
the file's visual scene (``<scene><instance_visual_scene>``) is placed by the composed transforms
of its node hierarchy (``<matrix>``, ``<translate>``, ``<rotate>``, ``<scale>``, nested nodes and
``<instance_node>``), ``<asset><unit meter="...">`` scales the result to metres, and
``<up_axis>`` is ignored (Gazebo's import tutorial has users rotate a Y-up mesh in the SDF pose
themselves). Polylists and polygons are triangulated; lines and points are ignored. A file
without a visual scene contributes its library geometries untransformed.

Parsing is done by ``pycollada``; the arrays are cached per (path, modification time, size), so a
mesh shared by a hundred robots is read once.
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path

import numpy as np

from fleetsim.errors import SimulationError

_CACHE_SIZE = 128  # distinct mesh files kept parsed


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
    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        raise SimulationError(f"COLLADA mesh '{p}' cannot be read: {exc.strerror}") from exc
    return _cached_triangles(str(p.resolve()), st.st_mtime_ns, st.st_size)


def clear_mesh_cache() -> None:
    """Forget every parsed mesh (the cache also refreshes by itself when a file changes)."""
    _cached_triangles.cache_clear()


@functools.lru_cache(maxsize=_CACHE_SIZE)
def _cached_triangles(path: str, mtime_ns: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    del mtime_ns, size  # cache key only: a rewritten file is read again
    vertices, faces = _read_collada(path)
    vertices.flags.writeable = False
    faces.flags.writeable = False
    return vertices, faces


def _read_collada(path: str) -> tuple[np.ndarray, np.ndarray]:
    with warnings.catch_warnings():
        # pycollada builds its transforms with numpy.matrix
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        return _parse(path)


def _parse(path: str) -> tuple[np.ndarray, np.ndarray]:
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
        verts, faces = _triangles_of_scene(dae)
    except SimulationError:
        raise
    except Exception as exc:  # malformed index arrays surface while binding
        raise SimulationError(
            f"COLLADA mesh '{path}' has malformed geometry ({type(exc).__name__}: {exc})"
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
    offsets = np.cumsum([0] + [len(v) for v in verts[:-1]])
    vertices = np.concatenate(verts).astype(np.float64) * unit
    tri = np.concatenate([f + o for f, o in zip(faces, offsets)]).astype(np.int32)
    if not np.all(np.isfinite(vertices)):
        raise SimulationError(f"COLLADA mesh '{path}' has non-finite vertex coordinates")
    return np.ascontiguousarray(vertices), np.ascontiguousarray(tri)


def _triangles_of_scene(dae) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Per triangle set: (n, 3) transformed vertices and (t, 3) local indices."""
    from collada.polylist import BoundPolylist
    from collada.triangleset import BoundTriangleSet

    if dae.scene is not None:
        bound = list(dae.scene.objects("geometry"))
    else:
        bound = [g.bind(np.identity(4), {}) for g in dae.geometries]
    verts, faces = [], []
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
            if mirrored:
                idx = idx[:, ::-1]
            verts.append(v)
            faces.append(idx)
    return verts, faces
