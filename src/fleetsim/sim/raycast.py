"""Batched planar ray casting against 2-D primitives on a uniform grid (numba kernels).

A planar laser only needs the horizontal slice of the world at its own height. The world's
geometry is reduced to *primitives*, rows of a ``(P, 7)`` or ``(P, 16)`` float64 array in the
world frame (metres)::

    [kind, a, b, c, d, zmin, zmax, x0, y0, z0, x1, y1, z1, x2, y2, z2]
    kind 0 (segment):  a, b = x0, y0 and c, d = x1, y1
    kind 1 (circle):   a, b = centre x, y, c = radius, d unused
    kind 2 (triangle): a, b, c, d = xmin, ymin, xmax, ymax of the triangle whose corners
                       follow (the true triangles of a mesh); sliced at the ray's height

A primitive is hit only by rays whose origin height lies in ``[zmin, zmax]``. Grids hold
16-column rows (segments and circles padded with zeros). Primitives are
binned into a uniform grid (``PrimitiveGrid``, CSR layout); each ray walks the grid cells it
crosses (Amanatides & Woo traversal) and stops at the first cell holding a hit, so the cost per
ray is the number of cells crossed, not the number of walls in the world.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

SEGMENT = 0
CIRCLE = 1
TRIANGLE = 2
PRIM_WIDTH = 16  # columns of a grid's primitives


@dataclass(frozen=True)
class PrimitiveGrid:
    """Primitives binned into a uniform grid (CSR: cell ``k`` holds ``items[start[k]:start[k+1]]``).

    Cells are indexed ``k = iy * nx + ix``; cell ``(ix, iy)`` covers
    ``[x0 + ix * cell, x0 + (ix + 1) * cell) x [y0 + iy * cell, ...)``.
    """

    prims: np.ndarray  # (P, 16) float64
    owner: np.ndarray  # (P,) int64, model index owning the primitive (-1: the static world)
    start: np.ndarray  # (nx * ny + 1,) int64
    items: np.ndarray  # (K,) int64 primitive indices
    x0: float
    y0: float
    cell: float
    nx: int
    ny: int


@numba.njit(cache=True)
def _bbox(p):
    if p[0] != CIRCLE:  # segment, or triangle (its bounding box in a..d)
        return min(p[1], p[3]), min(p[2], p[4]), max(p[1], p[3]), max(p[2], p[4])
    return p[1] - p[3], p[2] - p[3], p[1] + p[3], p[2] + p[3]


@numba.njit(cache=True)
def _touches(p, x0, y0, x1, y1):
    """Whether the footprint of primitive ``p`` (a segment, or the xy shadow of a triangle)
    meets the cell ``[x0, x1] x [y0, y1]``: separating axes (the edge normals; the cell's own
    axes are covered by the bounding-box loop). Circles always do (their box is tight)."""
    if p[0] == CIRCLE:
        return True
    if p[0] == SEGMENT:
        px = (p[1], p[3], p[3])
        py = (p[2], p[4], p[4])
    else:
        px = (p[7], p[10], p[13])
        py = (p[8], p[11], p[14])
    eps = 1e-9
    for e in range(3):
        nx = -(py[(e + 1) % 3] - py[e])
        ny = px[(e + 1) % 3] - px[e]
        if nx == 0.0 and ny == 0.0:
            continue
        lo = np.inf
        hi = -np.inf
        for k in range(3):
            d = nx * px[k] + ny * py[k]
            lo = min(lo, d)
            hi = max(hi, d)
        clo = np.inf
        chi = -np.inf
        for cx, cy in ((x0, y0), (x1, y0), (x0, y1), (x1, y1)):
            d = nx * cx + ny * cy
            clo = min(clo, d)
            chi = max(chi, d)
        scale = eps * (abs(nx) + abs(ny)) * (1.0 + abs(x0) + abs(y0))
        if chi < lo - scale or clo > hi + scale:
            return False
    return True


@numba.njit(cache=True)
def _cell_lists(prims, x0, y0, cell, nx, ny):
    """CSR lists of the cells each primitive's footprint meets (a long diagonal wall is put in
    the cells along it, not in every cell of its bounding box)."""
    n = prims.shape[0]
    counts = np.zeros(nx * ny + 1, np.int64)
    lo = np.empty((n, 2), np.int64)
    hi = np.empty((n, 2), np.int64)
    for i in range(n):
        bx0, by0, bx1, by1 = _bbox(prims[i])
        lo[i, 0] = max(0, min(nx - 1, int(np.floor((bx0 - x0) / cell))))
        lo[i, 1] = max(0, min(ny - 1, int(np.floor((by0 - y0) / cell))))
        hi[i, 0] = max(0, min(nx - 1, int(np.floor((bx1 - x0) / cell))))
        hi[i, 1] = max(0, min(ny - 1, int(np.floor((by1 - y0) / cell))))
        for iy in range(lo[i, 1], hi[i, 1] + 1):
            for ix in range(lo[i, 0], hi[i, 0] + 1):
                cx = x0 + ix * cell
                cy = y0 + iy * cell
                if _touches(prims[i], cx, cy, cx + cell, cy + cell):
                    counts[iy * nx + ix + 1] += 1
    for k in range(nx * ny):
        counts[k + 1] += counts[k]
    items = np.empty(counts[nx * ny], np.int64)
    fill = counts[:-1].copy()
    for i in range(n):
        for iy in range(lo[i, 1], hi[i, 1] + 1):
            for ix in range(lo[i, 0], hi[i, 0] + 1):
                cx = x0 + ix * cell
                cy = y0 + iy * cell
                if _touches(prims[i], cx, cy, cx + cell, cy + cell):
                    k = iy * nx + ix
                    items[fill[k]] = i
                    fill[k] += 1
    return counts, items


def grid_from_primitives(
    prims: np.ndarray, owner: np.ndarray | None = None, cell: float = 0.5
) -> PrimitiveGrid:
    """Bin ``(P, 7)`` or ``(P, 16)`` primitives into a uniform grid of square cells ``cell``
    metres wide (rows are padded to 16 columns)."""
    prims = np.asarray(prims, dtype=np.float64)
    prims = prims.reshape(-1, prims.shape[-1] if prims.ndim == 2 else 7)
    if prims.shape[1] < PRIM_WIDTH:
        prims = np.pad(prims, ((0, 0), (0, PRIM_WIDTH - prims.shape[1])))
    prims = np.ascontiguousarray(prims)
    owner = (
        np.full(len(prims), -1, np.int64)
        if owner is None
        else np.ascontiguousarray(owner, dtype=np.int64)
    )
    if len(prims) == 0:
        return PrimitiveGrid(
            prims, owner, np.zeros(2, np.int64), np.zeros(0, np.int64), 0.0, 0.0, cell, 1, 1
        )
    seg = prims[:, 0] != CIRCLE
    lo = np.where(
        seg[:, None], np.minimum(prims[:, 1:3], prims[:, 3:5]), prims[:, 1:3] - prims[:, 3:4]
    )
    hi = np.where(
        seg[:, None], np.maximum(prims[:, 1:3], prims[:, 3:5]), prims[:, 1:3] + prims[:, 3:4]
    )
    x0, y0 = lo.min(axis=0) - 1e-6
    nx = max(1, int(np.ceil((hi[:, 0].max() - x0) / cell)) + 1)
    ny = max(1, int(np.ceil((hi[:, 1].max() - y0) / cell)) + 1)
    start, items = _cell_lists(prims, x0, y0, cell, nx, ny)
    return PrimitiveGrid(prims, owner, start, items, float(x0), float(y0), cell, nx, ny)


@numba.njit(cache=True)
def _hit_distance(p, ox, oy, dx, dy, tmin):
    """Distance along the unit ray to primitive ``p`` (first hit at t >= tmin), or inf."""
    if p[0] == SEGMENT:
        ex = p[3] - p[1]
        ey = p[4] - p[2]
        den = dx * ey - dy * ex
        if abs(den) < 1e-12:
            return np.inf
        wx = p[1] - ox
        wy = p[2] - oy
        t = (wx * ey - wy * ex) / den
        s = (wx * dy - wy * dx) / den
        if t >= tmin and -1e-12 <= s <= 1.0 + 1e-12:
            return t
        return np.inf
    cx = ox - p[1]
    cy = oy - p[2]
    b = cx * dx + cy * dy
    c = cx * cx + cy * cy - p[3] * p[3]
    disc = b * b - c
    if disc < 0.0:
        return np.inf
    sq = np.sqrt(disc)
    t = -b - sq
    if t >= tmin:
        return t
    t = -b + sq
    if t >= tmin:
        return t
    return np.inf


@numba.njit(cache=True)
def _triangle_hit(p, ox, oy, oz, dx, dy, tmin):
    """Distance along the horizontal unit ray at height ``oz`` to triangle row ``p`` (corners in
    p[7:16]), or inf: the triangle is cut by the plane ``z = oz`` (a corner counts as above when
    its z >= oz, so triangles sharing an edge cut it at the same point) and the cut segment is
    hit as a segment."""
    x0 = y0 = x1 = y1 = 0.0  # the cut's end points (scalars: no allocation per test)
    n = 0
    for e in range(3):
        a = 7 + 3 * e
        b = 7 + 3 * ((e + 1) % 3)
        za = p[a + 2]
        zb = p[b + 2]
        if (za >= oz) != (zb >= oz):
            s = (oz - za) / (zb - za)
            if n == 0:
                x0 = p[a] + s * (p[b] - p[a])
                y0 = p[a + 1] + s * (p[b + 1] - p[a + 1])
            else:
                x1 = p[a] + s * (p[b] - p[a])
                y1 = p[a + 1] + s * (p[b + 1] - p[a + 1])
            n += 1
    if n < 2:
        return np.inf
    ex = x1 - x0
    ey = y1 - y0
    den = dx * ey - dy * ex
    if abs(den) < 1e-12:
        return np.inf
    wx = x0 - ox
    wy = y0 - oy
    t = (wx * ey - wy * ex) / den
    s = (wx * dy - wy * dx) / den
    if t >= tmin and -1e-12 <= s <= 1.0 + 1e-12:
        return t
    return np.inf


@numba.njit(cache=True)
def ranges_from_primitives(
    origins,
    angles,
    range_min,
    range_max,
    ray_owner,
    prims,
    prim_owner,
    start,
    items,
    x0,
    y0,
    cell,
    nx,
    ny,
):
    """Ranges of planar rays to the first primitive they hit.

    Parameters
    ----------
    origins : (R, 3) float64, ray origins in the world frame, metres (z selects primitives).
    angles : (R,) float64, ray directions as yaw in the world frame, radians.
    range_min, range_max : (R,) float64, metres; hits closer than ``range_min`` are ignored.
    ray_owner : (R,) int64, model index of the sensing robot; its own primitives are skipped.
    prims, prim_owner, start, items, x0, y0, cell, nx, ny : a ``PrimitiveGrid``'s fields.

    Returns
    -------
    (R,) float64 distances in metres; ``inf`` where nothing is hit within ``range_max``.
    """
    nrays = origins.shape[0]
    out = np.full(nrays, np.inf)
    gx1 = x0 + nx * cell
    gy1 = y0 + ny * cell
    for r in range(nrays):
        ox = origins[r, 0]
        oy = origins[r, 1]
        oz = origins[r, 2]
        dx = np.cos(angles[r])
        dy = np.sin(angles[r])
        tmin = range_min[r]
        tmax = range_max[r]
        # clip the ray to the grid rectangle (slab method)
        t0 = 0.0
        t1 = tmax
        if abs(dx) < 1e-15:
            if ox < x0 or ox > gx1:
                continue
        else:
            ta = (x0 - ox) / dx
            tb = (gx1 - ox) / dx
            t0 = max(t0, min(ta, tb))
            t1 = min(t1, max(ta, tb))
        if abs(dy) < 1e-15:
            if oy < y0 or oy > gy1:
                continue
        else:
            ta = (y0 - oy) / dy
            tb = (gy1 - oy) / dy
            t0 = max(t0, min(ta, tb))
            t1 = min(t1, max(ta, tb))
        if t0 > t1:
            continue
        px = ox + t0 * dx
        py = oy + t0 * dy
        ix = min(nx - 1, max(0, int((px - x0) / cell)))
        iy = min(ny - 1, max(0, int((py - y0) / cell)))
        stepx = 1 if dx > 0 else -1
        stepy = 1 if dy > 0 else -1
        if abs(dx) > 1e-15:
            nxt = x0 + (ix + (1 if dx > 0 else 0)) * cell
            tmx = (nxt - ox) / dx
            tdx = cell / abs(dx)
        else:
            tmx = np.inf
            tdx = np.inf
        if abs(dy) > 1e-15:
            nyt = y0 + (iy + (1 if dy > 0 else 0)) * cell
            tmy = (nyt - oy) / dy
            tdy = cell / abs(dy)
        else:
            tmy = np.inf
            tdy = np.inf
        best = np.inf
        while True:
            k = iy * nx + ix
            for q in range(start[k], start[k + 1]):
                i = items[q]
                if prim_owner[i] >= 0 and prim_owner[i] == ray_owner[r]:
                    continue
                p = prims[i]
                if oz < p[5] or oz > p[6]:
                    continue
                if p[0] == TRIANGLE:
                    t = _triangle_hit(p, ox, oy, oz, dx, dy, tmin)
                else:
                    t = _hit_distance(p, ox, oy, dx, dy, tmin)
                if t < best:
                    best = t
            cell_exit = min(tmx, tmy)
            if best <= cell_exit or cell_exit > t1:
                break
            if tmx < tmy:
                ix += stepx
                tmx += tdx
                if ix < 0 or ix >= nx:
                    break
            else:
                iy += stepy
                tmy += tdy
                if iy < 0 or iy >= ny:
                    break
        if best <= tmax:
            out[r] = best
    return out


def cast(grid: PrimitiveGrid, origins, angles, range_min, range_max, ray_owner) -> np.ndarray:
    """Convenience wrapper: ``ranges_from_primitives`` over a ``PrimitiveGrid``."""
    n = len(angles)
    return ranges_from_primitives(
        np.ascontiguousarray(origins, np.float64).reshape(n, 3),
        np.ascontiguousarray(angles, np.float64),
        np.broadcast_to(np.asarray(range_min, np.float64), (n,)).copy(),
        np.broadcast_to(np.asarray(range_max, np.float64), (n,)).copy(),
        np.broadcast_to(np.asarray(ray_owner, np.int64), (n,)).copy(),
        grid.prims,
        grid.owner,
        grid.start,
        grid.items,
        grid.x0,
        grid.y0,
        grid.cell,
        grid.nx,
        grid.ny,
    )


@numba.njit(cache=True)
def ranges_with_bodies(
    ranges,
    origins,
    angle0,
    increment,
    nbeams,
    offsets,
    laser_owner,
    range_min,
    range_max,
    centres,
    radii,
    body_owner,
    prim_start,
    prims,
):
    """Lower ``ranges`` (in place) where beams hit movable bodies; each laser only tests the
    beams that fall inside a body's bounding circle (angular culling).

    Parameters
    ----------
    ranges : (R,) float64, current ranges (e.g. from the static world), m; updated in place.
    origins : (L, 3) laser origins, m; angle0, increment : (L,) first beam yaw and spacing, rad.
    nbeams, offsets : (L,) int, beam count and start index of each laser in ``ranges``.
    laser_owner : (L,) int model index carrying each laser (its own bodies are skipped).
    range_min, range_max : (L,) m.
    centres : (B, 2), radii : (B,) bounding circles of the bodies' primitives, m.
    body_owner : (B,) int model index; prim_start : (B + 1,) CSR into ``prims`` (P, 7).
    """
    two_pi = 2.0 * np.pi
    for li in range(origins.shape[0]):
        ox = origins[li, 0]
        oy = origins[li, 1]
        oz = origins[li, 2]
        n = nbeams[li]
        for b in range(centres.shape[0]):
            if body_owner[b] == laser_owner[li]:
                continue
            cx = centres[b, 0] - ox
            cy = centres[b, 1] - oy
            d = np.hypot(cx, cy)
            if d - radii[b] > range_max[li]:
                continue
            if d <= radii[b] or increment[li] <= 0.0:
                k0 = 0
                k1 = n - 1
                shifts = 1
            else:
                half = np.arcsin(radii[b] / d)
                centre = np.arctan2(cy, cx)
                shifts = 3
            for s in range(shifts):
                if shifts == 3:
                    lo = centre - half + (s - 1) * two_pi - angle0[li]
                    hi = centre + half + (s - 1) * two_pi - angle0[li]
                    inc = increment[li]
                    k0 = max(0, int(np.ceil(lo / inc)))
                    k1 = min(n - 1, int(np.floor(hi / inc)))
                for k in range(k0, k1 + 1):
                    a = angle0[li] + k * increment[li]
                    dx = np.cos(a)
                    dy = np.sin(a)
                    q = offsets[li] + k
                    for pi in range(prim_start[b], prim_start[b + 1]):
                        p = prims[pi]
                        if oz < p[5] or oz > p[6]:
                            continue
                        t = _hit_distance(p, ox, oy, dx, dy, range_min[li])
                        if t < ranges[q] and t <= range_max[li]:
                            ranges[q] = t
    return ranges
