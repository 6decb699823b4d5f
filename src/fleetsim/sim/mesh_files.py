"""Triangles of a mesh file in any format fleetsim reads (STL, OBJ, COLLADA), as arrays.

MuJoCo loads STL and OBJ itself, but it re-centres and re-orients the vertices it keeps and
keeps only the convex hull for collision; the convex decomposition of a static mesh
(``decompose``) and the exact ray casts of lasers need the file's own triangles in the file's
own frame. STL (binary and ASCII) and OBJ (``v`` and ``f`` records; polygons fanned into
triangles, negative indices counted from the end) are small formats read here; COLLADA comes
from ``meshes.triangle_mesh_from_collada``.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path

import numpy as np

from fleetsim.errors import SimulationError
from fleetsim.sim.meshes import triangle_mesh_from_collada

_STL_RECORD = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])


def triangle_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a ``.stl``, ``.obj`` or ``.dae`` file, in the file's frame.

    Returns
    -------
    vertices : ndarray, shape (V, 3), float64, read-only; positions in the file's units (m).
    faces : ndarray, shape (F, 3), int32, read-only; vertex indices of each triangle.

    Raises
    ------
    SimulationError
        The file cannot be read, is not of a known format, or holds no triangles.
    """
    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        raise SimulationError(f"mesh file '{p}' cannot be read: {exc.strerror}") from exc
    if p.suffix.lower() == ".dae":
        return triangle_mesh_from_collada(p)
    return _cached(str(p.resolve()), st.st_mtime_ns, st.st_size)


@functools.lru_cache(maxsize=32)
def _cached(path: str, mtime_ns: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    del mtime_ns, size  # cache key only
    suffix = Path(path).suffix.lower()
    if suffix == ".stl":
        vertices, faces = _read_stl(path)
    elif suffix == ".obj":
        vertices, faces = _read_obj(path)
    else:
        raise SimulationError(f"mesh file '{path}': fleetsim reads triangles of STL, OBJ and DAE")
    if len(faces) == 0:
        raise SimulationError(f"mesh file '{path}' holds no triangles")
    if not np.all(np.isfinite(vertices)):
        raise SimulationError(f"mesh file '{path}' has non-finite vertex coordinates")
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int32)
    vertices.flags.writeable = False
    faces.flags.writeable = False
    return vertices, faces


def _read_stl(path: str) -> tuple[np.ndarray, np.ndarray]:
    data = Path(path).read_bytes()
    if len(data) >= 84:
        count = int(np.frombuffer(data, "<u4", 1, 80)[0])
        if 84 + 50 * count == len(data):  # binary: the size matches the triangle count
            rec = np.frombuffer(data, _STL_RECORD, count, 84)
            vertices = rec["v"].reshape(-1, 3).astype(np.float64)
            return vertices, np.arange(len(vertices)).reshape(-1, 3)
    text = data.decode("ascii", errors="replace")
    if not text.lstrip().startswith("solid"):
        raise SimulationError(
            f"mesh file '{path}' is neither binary STL (size does not match its triangle "
            "count) nor ASCII STL (does not start with 'solid')"
        )
    nums = re.findall(r"vertex\s+(\S+)\s+(\S+)\s+(\S+)", text)
    try:
        vertices = np.array(nums, dtype=np.float64).reshape(-1, 3)
    except ValueError as exc:
        raise SimulationError(f"mesh file '{path}': a vertex is not three numbers") from exc
    if len(vertices) % 3:
        raise SimulationError(f"mesh file '{path}': {len(vertices)} vertices is not whole facets")
    return vertices, np.arange(len(vertices)).reshape(-1, 3)


def _read_obj(path: str) -> tuple[np.ndarray, np.ndarray]:
    vertices: list[list[float]] = []
    faces: list[tuple[int, int, int]] = []
    with open(path, errors="replace") as fh:
        for lineno, line in enumerate(fh, 1):
            parts = line.split()
            if not parts:
                continue
            try:
                if parts[0] == "v":
                    vertices.append([float(x) for x in parts[1:4]])
                elif parts[0] == "f":
                    idx = [int(tok.split("/")[0]) for tok in parts[1:]]
                    idx = [i - 1 if i > 0 else len(vertices) + i for i in idx]
                    faces += [(idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1)]
            except ValueError as exc:
                raise SimulationError(
                    f"{path}:{lineno}: malformed OBJ record '{line.strip()}'"
                ) from exc
    v = np.array(vertices, dtype=np.float64).reshape(-1, 3)
    f = np.array(faces, dtype=np.int64).reshape(-1, 3)
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise SimulationError(f"mesh file '{path}': a face refers to a vertex that does not exist")
    return v, f
