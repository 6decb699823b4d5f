"""Convex decomposition of static non-convex meshes (buildings, furniture), cached on disk.

MuJoCo collides a mesh as its convex hull: Gazebo's ``model://willowgarage`` (one 13,348-triangle
collision mesh of a whole building) becomes one solid block with the robots inside it. A static
mesh is therefore split into convex parts when the world is built; each part collides as itself.

The mesh is welded (coincident vertices merged, degenerate and double-sided duplicate triangles
dropped) and split into connected components. Each component is then, in this order:

1. **convex already**: closed, and every triangle lies on its hull's boundary (within
   ``convex_tol``): kept as one part;
2. **architecture** (every triangle horizontal, or vertical within ``prism_drift`` over its
   height, as walls, door and window openings and lintels are): cut exactly into prisms. The
   component is cut at every vertex height; in each layer its cross-section (the slice of its
   vertical triangles at mid-layer, solid by the even-odd rule) is a polygon with holes, split
   into triangles by a constrained Delaunay triangulation (``shapely``) and merged back into
   convex polygons (Hertel-Mehlhorn: drop every diagonal whose removal keeps both sides
   convex); each polygon extruded over the layer is a part, and equal polygons of consecutive
   layers are stacked into one. The walls are where the mesh puts them (error at most
   ``prism_drift``). Why not CoACD here: its concavity bound is relative to the bounding box
   (a threshold of 0.02 on Willow Garage's 47 m diagonal allows 0.9 m), its voxel preprocessing
   moves 10 cm walls, and it takes 10 s for one 952-triangle wing of Willow Garage (2-core
   machine). Measured on the test building (440 triangles, tests/sim/fixtures): 7-8 s for
   13-18 parts at threshold 0.05, 0.02 or 0.01 (preprocess resolution 50-100), and although
   90% of rays from the rooms meet the parts within 3 mm of the walls, some meet a part up to
   5.9 m early (a door or part of a room filled in). The layered cut is exact (Willow Garage:
   1.5-2.6 s for all 13,348 triangles, rays within 15.5 mm, the error of its 5 mm-leaning
   walls and of 1 cm slabs for single faces);
3. **anything else**: CoACD (``coacd``, Wei et al. 2022) with ``DecompositionParams``.

A component that cannot be decomposed well (more than ``max_hulls`` parts, or CoACD's parts
exceeding the component's volume by more than ``max_volume_error``) is reported in
``Decomposition.problems``; the world builder warns naming the model, link and file.

Results are cached on disk by the mesh's content (vertex and triangle bytes) and the parameters,
under ``$FLEETSIM_CACHE_DIR`` (default ``$XDG_CACHE_HOME/fleetsim`` or ``~/.cache/fleetsim``),
``convex/``: a second load of the same world reads the parts back.
"""

from __future__ import annotations

import hashlib
import itertools
import os
from dataclasses import astuple, dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, QhullError

from fleetsim.sim import prisms

ALGORITHM_VERSION = "4"  # part of the cache key: bump when the decomposition changes
_WELD = 1e-6  # m, vertices closer than this are one


@dataclass(frozen=True)
class DecompositionParams:
    """How static meshes are decomposed (all lengths in metres)."""

    convex_tol: float = 0.005  # a component within this of its hull is convex
    prism_drift: float = 0.01  # max horizontal drift of a "vertical" triangle over its height
    threshold: float = 0.02  # CoACD concavity threshold (relative to the bounding box)
    preprocess_resolution: int = 50  # CoACD manifold preprocessing voxels per side
    max_hulls: int = 64  # CoACD's limit per component; more prisms than 20x this warns
    max_volume_error: float = 0.25  # CoACD parts' volume over the component's, relative
    seed: int = 0  # CoACD's random seed (its tree search is randomised)


DEFAULT_PARAMS = DecompositionParams()


@dataclass
class Decomposition:
    """Convex parts of one mesh.

    parts : list of (n_k, 3) float64 arrays, vertices of each part (their hull is the part),
        in the mesh's frame, metres.
    convex : the whole mesh is one convex component (its hull is the mesh).
    methods : how each component was split ("convex", "prisms", "coacd"), one per component.
    problems : human-readable descriptions of components decomposed badly.
    """

    parts: list[np.ndarray]
    convex: bool
    methods: list[str] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)


def cache_dir() -> Path:
    """Where decompositions are kept: ``$FLEETSIM_CACHE_DIR``, else the XDG cache folder."""
    env = os.environ.get("FLEETSIM_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(xdg) / "fleetsim"


def cache_file(vertices: np.ndarray, faces: np.ndarray, params: DecompositionParams) -> Path:
    """The cache file of a mesh's decomposition: named by a hash of its content and params."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(faces, dtype=np.int64).tobytes())
    h.update(repr((ALGORITHM_VERSION, astuple(params))).encode())
    return cache_dir() / "convex" / f"{h.hexdigest()[:40]}.npz"


def convex_decomposition(
    vertices: np.ndarray, faces: np.ndarray, params: DecompositionParams = DEFAULT_PARAMS
) -> Decomposition:
    """Convex parts of a triangle mesh, read from the disk cache when it was done before.

    Parameters
    ----------
    vertices : (V, 3) float64, metres (scale already applied).
    faces : (F, 3) int, triangle vertex indices.
    params : tolerances and CoACD settings.
    """
    path = cache_file(vertices, faces, params)
    cached = _read(path)
    if cached is not None:
        return cached
    result = decompose(vertices, faces, params)
    _write(path, result)
    return result


def decompose(
    vertices: np.ndarray, faces: np.ndarray, params: DecompositionParams = DEFAULT_PARAMS
) -> Decomposition:
    """The decomposition itself (no cache); see the module docstring for the rules."""
    v, f = weld(vertices, faces)
    out = Decomposition([], False)
    components = split_components(v, f)
    for k, cf in enumerate(components):
        used, local = np.unique(cf, return_inverse=True)
        cv, cf = v[used], local.reshape(-1, 3)
        where = f"component {k + 1} of {len(components)} ({len(cf)} triangles)"
        if is_convex(cv, cf, params.convex_tol):
            out.parts.append(cv)
            out.methods.append("convex")
            continue
        pieces = prisms.prisms_of_architecture(cv, cf, params.prism_drift)
        if pieces is not None:
            out.methods.append("prisms")
            if len(pieces) > 20 * params.max_hulls:
                out.problems.append(f"{where}: {len(pieces)} prism parts")
            out.parts += pieces
            continue
        pieces, problem = _coacd(cv, cf, params)
        out.methods.append("coacd")
        out.parts += pieces
        if problem:
            out.problems.append(f"{where}: {problem}")
    out.convex = out.methods == ["convex"]
    out.parts = [p for p in out.parts if is_solid(p)]
    return out


def is_solid(part: np.ndarray, thickness: float = 1e-5) -> bool:
    """Whether a part's hull has volume: its mean thickness (volume over half its area) is at
    least ``thickness`` m. Slivers (from vertices of neighbouring pieces a fraction of a micron
    apart) are dropped: they hold nothing and MuJoCo cannot build their hull."""
    try:
        hull = ConvexHull(part)
    except (QhullError, ValueError):
        return False
    return bool(hull.volume >= thickness * 0.5 * hull.area)


def weld(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge vertices closer than 1 um; drop degenerate triangles and repeated ones (a
    double-sided mesh holds each triangle twice, once per winding; the first is kept)."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    q = np.round(v / _WELD).astype(np.int64)
    _, first, inverse = np.unique(q, axis=0, return_index=True, return_inverse=True)
    f = inverse.reshape(-1)[np.asarray(faces, dtype=np.int64).reshape(-1, 3)]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    _, keep = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
    return v[first], f[np.sort(keep)]


def split_components(vertices: np.ndarray, faces: np.ndarray) -> list[np.ndarray]:
    """Triangles ``(F_k, 3)`` of each connected component (triangles sharing a vertex)."""
    n = len(vertices)
    if len(faces) == 0:
        return []
    rows = faces[:, [0, 1, 2]].ravel()
    cols = faces[:, [1, 2, 0]].ravel()
    graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    of_face = label[faces[:, 0]]
    order = np.argsort(of_face, kind="stable")
    bounds = np.flatnonzero(np.diff(of_face[order])) + 1
    return [faces[idx] for idx in np.split(order, bounds)]


def is_closed(faces: np.ndarray) -> bool:
    """Every edge is shared by exactly two triangles."""
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, count = np.unique(e, axis=0, return_counts=True)
    return bool(np.all(count == 2))


def is_convex(vertices: np.ndarray, faces: np.ndarray, tol: float) -> bool:
    """A closed mesh whose every triangle lies in a facet plane of its hull (within ``tol``):
    a closed surface on the boundary of a convex body is that boundary."""
    if not is_closed(faces):
        return False
    try:
        hull = ConvexHull(vertices)
    except (QhullError, ValueError):  # flat or degenerate: no volume to be convex
        return False
    planes = np.unique(np.round(hull.equations, 9), axis=0)
    dist = np.abs(vertices @ planes[:, :3].T + planes[:, 3]) <= tol  # (V, H)
    on = dist[faces[:, 0]] & dist[faces[:, 1]] & dist[faces[:, 2]]  # (F, H)
    return bool(on.any(axis=1).all())


def mesh_volume(vertices: np.ndarray, faces: np.ndarray) -> float | None:
    """Enclosed volume of a closed, consistently wound mesh (m^3); None when the winding is
    not consistent (each directed edge must appear once), so no volume is defined."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, count = np.unique(e, axis=0, return_counts=True)
    if not is_closed(faces) or np.any(count != 1):
        return None
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return float(abs(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0)


def _coacd(v: np.ndarray, f: np.ndarray, params: DecompositionParams):
    """CoACD's parts of one component and a problem description ("" when none)."""
    import coacd  # imported here: only worlds with non-architectural static meshes pay for it

    coacd.set_log_level("error")
    parts = coacd.run_coacd(
        coacd.Mesh(v, f),
        threshold=params.threshold,
        max_convex_hull=params.max_hulls,
        preprocess_mode="auto",
        preprocess_resolution=params.preprocess_resolution,
        seed=params.seed,
    )
    pieces = [np.asarray(pv, dtype=np.float64) for pv, _ in parts]
    problem = []
    if len(pieces) >= params.max_hulls:
        problem.append(f"CoACD needed the maximum of {params.max_hulls} parts")
    volume = mesh_volume(v, f)
    if volume is not None and volume > 0:
        total = 0.0
        for pv in pieces:
            try:
                total += ConvexHull(pv).volume
            except (QhullError, ValueError):
                continue
        error = total / volume - 1.0
        if error > params.max_volume_error:
            problem.append(
                f"its {len(pieces)} convex parts fill {100 * error:.0f}% more volume than the "
                f"mesh (bound {100 * params.max_volume_error:.0f}%)"
            )
    return pieces, "; ".join(problem)


def _read(path: Path) -> Decomposition | None:
    try:
        with np.load(path, allow_pickle=False) as z:
            verts, offsets = z["vertices"], z["offsets"]
            parts = [verts[a:b] for a, b in itertools.pairwise(offsets)]
            return Decomposition(
                parts,
                bool(z["convex"]),
                list(map(str, z["methods"])),
                list(map(str, z["problems"])),
            )
    except (OSError, KeyError, ValueError):  # absent, or written by another version
        return None


def _write(path: Path, d: Decomposition) -> None:
    """Write atomically (another process may read the same cache)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
        sizes = [len(p) for p in d.parts]
        np.savez(
            tmp,
            vertices=np.concatenate(d.parts) if d.parts else np.zeros((0, 3)),
            offsets=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
            convex=np.array(d.convex),
            methods=np.array(d.methods, dtype=str),
            problems=np.array(d.problems, dtype=str),
        )
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only cache only costs time
