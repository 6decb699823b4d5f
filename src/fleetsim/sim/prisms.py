"""Exact convex decomposition of architectural meshes into vertical prisms (see ``decompose``).

A closed mesh whose triangles are all horizontal, or vertical within a small drift, is a stack
of layers between consecutive vertex heights; in each layer its cross-section does not change.
The cross-section at mid-layer is the slice of the vertical triangles (segments), its solid
faces found by the even-odd rule; ``shapely`` triangulates it (constrained Delaunay, holes
kept) and the triangles are merged back into convex polygons (Hertel-Mehlhorn). Each convex
polygon extruded over its layer is a part; the same polygon in consecutive layers is one part.
"""

from __future__ import annotations

import itertools

import numpy as np
import shapely

_HORIZONTAL = 1e-6  # m, a triangle with less height than this is horizontal
_LEVEL = 1e-5  # m, vertex heights closer than this are one level
_ROUND = 9  # decimals of 2-D coordinates used as keys (nm)
SHEET = 0.01  # m, thickness given to faces of an open mesh with empty space on both sides


def prisms_of_architecture(
    vertices: np.ndarray, faces: np.ndarray, drift: float
) -> list[np.ndarray] | None:
    """Convex prisms whose union is the solid bounded by a mesh of horizontal and
    (near-)vertical triangles (faces with empty space on both sides, as an open mesh has,
    become ``SHEET``-thick slabs); None when the mesh is not of that kind.

    Parameters
    ----------
    vertices : (V, 3) float64, m; faces : (F, 3) int, a closed (welded) triangle mesh.
    drift : m, the largest horizontal displacement a "vertical" triangle may have over its
        height (the error of the prisms against the mesh).

    Returns
    -------
    list of (2n, 3) float64 arrays: each prism's bottom and top polygon vertices, m.
    """
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    z = np.stack([a[:, 2], b[:, 2], c[:, 2]], axis=1)
    height = z.max(axis=1) - z.min(axis=1)
    n = np.cross(b - a, c - a)
    horizontal_n = np.hypot(n[:, 0], n[:, 1])
    # horizontal drift of a triangle over its height: |nz| / |n_xy| per metre of height;
    # zero-area (collinear) triangles have no normal and bound nothing: slope 0
    slope = np.where(horizontal_n > 0, np.abs(n[:, 2]) / np.maximum(horizontal_n, 1e-300), 0.0)
    slope[(horizontal_n == 0) & (np.abs(n[:, 2]) > 0)] = np.inf
    tall = height > _HORIZONTAL
    vertical = tall & (np.where(tall, slope, 0.0) * height <= drift)
    if not np.all(vertical | (height <= _HORIZONTAL)):
        return None
    levels = _levels(vertices[:, 2])
    parts: list[np.ndarray] = []
    open_: dict[tuple, list] = {}  # polygon key -> [ring, z0, z1] of the prism being stacked
    tri, tz = np.stack([a, b, c], axis=1)[vertical], z[vertical]
    for lo, hi in itertools.pairwise(levels):
        pieces = _layer_polygons(tri, tz, faces[vertical], 0.5 * (lo + hi))
        if pieces is None:
            return None
        now: dict[tuple, list] = {}
        for ring in pieces:
            key = tuple(sorted(map(tuple, np.round(ring, _ROUND))))
            prev = open_.pop(key, None)
            if prev is not None and prev[2] == lo:
                prev[2] = hi
                now[key] = prev
            else:
                if prev is not None:
                    parts.append(_prism(*prev))
                now[key] = [ring, lo, hi]
        parts += [_prism(*p) for p in open_.values()]
        open_ = now
    parts += [_prism(*p) for p in open_.values()]
    return parts


def _levels(z: np.ndarray) -> np.ndarray:
    zs = np.sort(z)
    keep = np.concatenate([[True], np.diff(zs) > _LEVEL])
    return zs[keep]


def _prism(ring: np.ndarray, z0: float, z1: float) -> np.ndarray:
    k = len(ring)
    return np.column_stack([np.vstack([ring, ring]), np.repeat([z0, z1], k)])


def _layer_polygons(tri, tz, faces, zm) -> list[np.ndarray] | None:
    """Convex polygons ((n, 2) rings, counter-clockwise) covering the cross-section at ``zm``."""
    segments = _slice(tri, tz, faces, zm)
    if len(segments) == 0:
        return []
    lines = shapely.multilinestrings(segments)
    polys, _, _, invalid = shapely.polygonize_full(shapely.node(lines).geoms)
    if not invalid.is_empty:
        return None  # self-touching rings: not a solid of this kind
    # segments outside every closed loop (an open mesh's lone faces) become sheets below
    faces_2d = list(polys.geoms)
    solid = [p for p in faces_2d if _inside(p.representative_point(), segments)]
    area = shapely.union_all(solid) if solid else shapely.Polygon()
    out: list[np.ndarray] = []
    for poly in getattr(area, "geoms", [area]):
        if poly.is_empty or poly.area <= 0:
            continue
        tris = shapely.constrained_delaunay_triangles(poly)
        rings = [np.asarray(t.exterior.coords)[:3] for t in tris.geoms]
        out += _merge_convex(rings)
    return out + _sheets(segments, area)


def _sheets(segments: np.ndarray, area) -> list[np.ndarray]:
    """Slabs ``SHEET`` thick centred on the slice segments with empty space on both sides:
    a mesh that is not closed (a wall drawn as one face) still stops robots, as a triangle
    mesh does in Gazebo's ODE."""
    p, q = segments[:, 0], segments[:, 1]
    d = q - p
    length = np.linalg.norm(d, axis=1)
    n = np.column_stack([-d[:, 1], d[:, 0]]) / np.maximum(length, 1e-30)[:, None]
    mid = 0.5 * (p + q)
    probe = 1e-4
    left = shapely.contains_xy(area, *(mid + probe * n).T)
    right = shapely.contains_xy(area, *(mid - probe * n).T)
    sheet = ~left & ~right & (length > 0)
    half = 0.5 * SHEET * n[sheet]
    a, b = p[sheet], q[sheet]
    rings = np.stack([a - half, b - half, b + half, a + half], axis=1)
    return list(rings)


def _slice(tri, tz, faces, zm) -> np.ndarray:
    """(S, 2, 2) segments where the triangles cross the plane ``z = zm``. A vertex counts as
    above when its z >= zm, so a shared edge gives both of its triangles the same point; the
    crossing is computed from the edge's endpoints in vertex-index order (bitwise equal)."""
    above = tz >= zm
    cross = above.any(axis=1) & ~above.all(axis=1)
    tri, above, faces = tri[cross], above[cross], faces[cross]
    pts = []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        flip = faces[:, i] > faces[:, j]
        p = np.where(flip[:, None], tri[:, j], tri[:, i])
        q = np.where(flip[:, None], tri[:, i], tri[:, j])
        s = (zm - p[:, 2]) / np.where(q[:, 2] == p[:, 2], 1.0, q[:, 2] - p[:, 2])
        pts.append((p + s[:, None] * (q - p))[:, :2])
        pts[-1][above[:, i] == above[:, j]] = np.nan
    pts = np.stack(pts, axis=1)  # (T, 3 edges, 2); exactly two edges cross
    ok = ~np.isnan(pts[:, :, 0])
    seg = pts[ok].reshape(-1, 2, 2)
    seg = np.round(seg, _ROUND)
    seg = seg[np.any(seg[:, 0] != seg[:, 1], axis=1)]
    key = np.sort(seg.reshape(-1, 2, 2).view(np.dtype((np.void, 16))).reshape(-1, 2), axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    return seg[np.sort(first)]


def _inside(point, segments: np.ndarray) -> bool:
    """Even-odd rule: a ray from ``point`` in a fixed generic direction crosses the slice's
    segments an odd number of times."""
    px, py = point.x, point.y
    d = np.array([0.8972, 0.4416])  # generic: not along any wall in practice
    p, q = segments[:, 0], segments[:, 1]
    e = q - p
    den = d[0] * e[:, 1] - d[1] * e[:, 0]
    w = p - (px, py)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / den
        s = (w[:, 0] * d[1] - w[:, 1] * d[0]) / den
    hits = (np.abs(den) > 1e-15) & (t > 0) & (s >= 0) & (s < 1)
    return bool(hits.sum() % 2)


def _merge_convex(rings: list[np.ndarray]) -> list[np.ndarray]:
    """Hertel-Mehlhorn: merge triangles across shared edges while the union stays convex."""
    polys: dict[int, list[tuple]] = {}
    owner: dict[tuple, int] = {}  # directed edge -> polygon
    for i, r in enumerate(rings):
        r = r if _signed_area(r) > 0 else r[::-1]
        ring = [tuple(np.round(p, _ROUND)) for p in r]
        polys[i] = ring
        for u, v in zip(ring, ring[1:] + ring[:1]):
            owner[(u, v)] = i
    for u, v in list(owner):
        i, j = owner.get((u, v)), owner.get((v, u))
        if i is None or j is None or i == j:
            continue
        merged = _joined(polys[i], polys[j], u, v)
        if merged is None or not _convex(merged):
            continue
        for e in zip(polys[j], polys[j][1:] + polys[j][:1]):
            owner[e] = i
        owner.pop((u, v), None)
        owner.pop((v, u), None)
        polys[i] = merged
        del polys[j]
    return [_without_collinear(np.array(r, dtype=np.float64)) for r in polys.values()]


def _without_collinear(ring: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """The ring without vertices lying on the line of their neighbours (a rectangle merged
    from triangles keeps its 4 corners, so it can become a box)."""
    while len(ring) > 3:
        e1 = ring - np.roll(ring, 1, axis=0)
        e2 = np.roll(ring, -1, axis=0) - ring
        cross = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        scale = np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
        flat = np.flatnonzero(cross <= tol * np.maximum(scale, 1e-30))
        if not len(flat):
            break
        ring = np.delete(ring, flat[0], axis=0)
    return ring


def _joined(ri: list, rj: list, u, v) -> list | None:
    """The ring of polygon i (holding edge u->v) joined with polygon j (holding v->u)."""
    a = ri.index(v)
    ri = ri[a:] + ri[:a]  # v ... u
    b = rj.index(u)
    rj = rj[b:] + rj[:b]  # u ... v
    if ri[-1] != u or rj[-1] != v:
        return None
    return ri + rj[1:-1]


def _signed_area(r) -> float:
    x, y = np.asarray(r, float)[:, 0], np.asarray(r, float)[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _convex(ring: list) -> bool:
    p = np.asarray(ring, float)
    e1 = np.roll(p, -1, axis=0) - p
    e2 = np.roll(p, -2, axis=0) - np.roll(p, -1, axis=0)
    cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    scale = np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
    return bool(np.all(cross >= -1e-9 * np.maximum(scale, 1e-30)))
