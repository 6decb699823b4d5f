"""Planar lasers against the walls of a map world: the occupied cells of an occupancy grid.

The occupied cells are covered by axis-aligned boxes (``mapworld.rectangles_from_occupancy``,
the same boxes the world is extruded into) binned into square tiles. A laser's beams share one
origin, so instead of walking every beam through the grid (a serial dependency chain per cell
that a CPU cannot overlap), each laser visits the boxes within its range once: a box's angular
extent seen from the origin picks the few beams that can cross it, and an exact slab test gives
each beam's entry distance. The nearest entry per beam is the range; the result equals casting
against the extruded boxes (tests check it against ``raycast``), at a cost that follows the walls
near each laser rather than the cells each beam crosses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

TILE = 32  # cells per tile side
_MARGIN = 2e-4  # rad added to a box's angular extent: covers the arctangent approximation


@dataclass(frozen=True)
class WallTiles:
    """Wall boxes of an occupancy grid binned into tiles (CSR: tile ``k`` holds
    ``boxes[items[start[k]:start[k + 1]]]``; a box overlapping several tiles is in each).

    ``boxes`` rows are ``[x0, y0, x1, y1]`` in cell units (column, row) from the grid origin.
    """

    occupied: np.ndarray  # (H, W) bool, row 0 at the grid origin's y
    boxes: np.ndarray  # (B, 4) float64
    start: np.ndarray  # (th * tw + 1,) int64
    items: np.ndarray  # (K,) int64
    tile: int
    th: int
    tw: int


def wall_tiles(occupied: np.ndarray, tile: int = TILE) -> WallTiles:
    """Bin the boxes covering ``occupied`` (H, W bool) into ``tile`` x ``tile`` cell tiles."""
    from fleetsim.sim.mapworld import rectangles_from_occupancy

    occupied = np.ascontiguousarray(occupied, dtype=np.bool_)
    h, w = occupied.shape
    th, tw = -(-h // tile), -(-w // tile)
    rects = rectangles_from_occupancy(occupied)  # [r0, c0, r1, c1], half-open
    ty0, tx0 = rects[:, 0] // tile, rects[:, 1] // tile
    nty, ntx = (rects[:, 2] - 1) // tile - ty0 + 1, (rects[:, 3] - 1) // tile - tx0 + 1
    per = nty * ntx
    box = np.repeat(np.arange(len(rects)), per)
    local = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
    tiles = (ty0[box] + local // ntx[box]) * tw + tx0[box] + local % ntx[box]
    order = np.argsort(tiles, kind="stable")
    start = np.zeros(th * tw + 1, np.int64)
    start[1:] = np.cumsum(np.bincount(tiles, minlength=th * tw))
    boxes = np.ascontiguousarray(rects[:, [1, 0, 3, 2]], dtype=np.float64)
    return WallTiles(occupied, boxes, start, box[order].astype(np.int64), tile, th, tw)


@numba.njit(cache=True, inline="always")
def _atan2(y, x):
    """atan2 within 1e-5 rad (a minimax polynomial): cheaper than libm, the margin absorbs it."""
    ax = abs(x)
    ay = abs(y)
    swap = ay > ax
    if swap:
        z = ax / ay
    else:
        z = ay / ax if ax > 0 else 0.0
    z2 = z * z
    r = z * (
        0.99997726
        + z2
        * (
            -0.33262347
            + z2 * (0.19354346 + z2 * (-0.11643287 + z2 * (0.05265332 - 0.0117212 * z2)))
        )
    )
    if swap:
        r = 0.5 * np.pi - r
    if x < 0:
        r = np.pi - r
    return -r if y < 0 else r


@numba.njit(cache=True)
def ranges_from_walls(
    origins, angle0, inc, nb, offsets, range_min, range_max, occupied, boxes, start, items,
    tile, th, tw, x0, y0, res, zmax, out,
):  # fmt: skip
    """Ranges of planar lasers to the walls of an occupancy grid (extruded 0..zmax), in place.

    Parameters
    ----------
    origins : (L, 3) float64 laser origins, world (= map) frame, m.
    angle0 : (L,) float64 world yaw of each laser's first beam, rad.
    inc : (L,) float64 angle between beams, rad (negative: beams sweep clockwise).
    nb, offsets : (L,) int64 beams per laser and the index of its first beam in ``out``.
    range_min, range_max : (L,) float64, m.
    occupied : (H, W) bool grid, row 0 at ``y0``; cell (i, j) covers
        ``[x0 + j res, x0 + (j + 1) res) x [y0 + i res, y0 + (i + 1) res)``.
    boxes, start, items, tile, th, tw : ``WallTiles`` of ``occupied``.
    zmax : wall height, m; lasers above it (or below 0) see nothing.
    out : (R,) float64 ranges, m, lowered in place where a wall is nearer; beams that start
        (at ``range_min``) inside an occupied cell get ``range_min``.
    """
    h, w = occupied.shape
    inv = 1.0 / res
    maxnb = 1
    for q in range(nb.shape[0]):
        maxnb = max(maxnb, nb[q])
    ibx = np.empty(maxnb)
    iby = np.empty(maxnb)
    hit = np.empty(maxnb)
    seen = np.full(boxes.shape[0], -1, np.int64)
    for q in range(origins.shape[0]):
        oz = origins[q, 2]
        if oz < 0.0 or oz > zmax:
            continue
        ox = (origins[q, 0] - x0) * inv
        oy = (origins[q, 1] - y0) * inv
        tmin = range_min[q] * inv
        tmax = range_max[q] * inv
        n = nb[q]
        da = abs(inc[q])
        a0 = angle0[q] if inc[q] >= 0 else angle0[q] + (n - 1) * inc[q]  # beam k: a0 + k da
        span = (n - 1) * da
        ida = 1.0 / da if da > 0 else 0.0
        cd = np.cos(da)
        sd = np.sin(da)
        c = 1.0
        s = 0.0
        for k in range(n):
            if k % 32 == 0:  # exact every 32 beams, rotated in between
                c = np.cos(a0 + k * da)
                s = np.sin(a0 + k * da)
            else:
                c, s = c * cd - s * sd, s * cd + c * sd
            ibx[k] = 1.0 / c if abs(c) > 1e-12 else 1e12
            iby[k] = 1.0 / s if abs(s) > 1e-12 else 1e12
            hit[k] = np.inf
            ix = int(np.floor(ox + tmin * c))
            iy = int(np.floor(oy + tmin * s))
            if 0 <= ix < w and 0 <= iy < h and occupied[iy, ix]:
                hit[k] = tmin
        tx0 = max(int(np.floor((ox - tmax) / tile)), 0)
        tx1 = min(int(np.floor((ox + tmax) / tile)), tw - 1)
        ty0 = max(int(np.floor((oy - tmax) / tile)), 0)
        ty1 = min(int(np.floor((oy + tmax) / tile)), th - 1)
        tmax2 = tmax * tmax
        # tiles ring by ring outwards from the laser's own, so that near walls are found first
        # and the tiles behind them are skipped whole (`_occluded`): in a building most boxes
        # in range are behind a wall
        cx = min(max(int(np.floor(ox / tile)), tx0), tx1)
        cy = min(max(int(np.floor(oy / tile)), ty0), ty1)
        rings = max(cx - tx0, tx1 - cx, cy - ty0, ty1 - cy)
        for ring in range(rings + 1):
            for ty in range(max(cy - ring, ty0), min(cy + ring, ty1) + 1):
                on_edge = ty == cy - ring or ty == cy + ring
                step = 1 if on_edge else 2 * ring
                for tx in range(cx - ring, cx + ring + 1, max(step, 1)):
                    if tx < tx0 or tx > tx1:
                        continue
                    t_i = ty * tw + tx
                    if start[t_i] == start[t_i + 1]:
                        continue
                    ex = max(tx * tile - ox, 0.0, ox - (tx + 1) * tile)
                    ey = max(ty * tile - oy, 0.0, oy - (ty + 1) * tile)
                    d2 = ex * ex + ey * ey
                    if d2 > tmax2:
                        continue
                    if d2 > 0.0 and _occluded(
                        tx * tile - ox, ty * tile - oy, (tx + 1) * tile - ox,
                        (ty + 1) * tile - oy, np.sqrt(d2), a0, span, ida, n, hit,
                    ):  # fmt: skip
                        continue
                    _cast_tile(
                        start, items, boxes, seen, q, ox, oy, tmin, tmax, tmax2, a0, span,
                        ida, n, ibx, iby, hit, t_i,
                    )  # fmt: skip
        o = offsets[q]
        for k in range(n):
            i = o + k if inc[q] >= 0 else o + n - 1 - k
            out[i] = min(out[i], hit[k] * res)


@numba.njit(cache=True, inline="always")
def _beam_span(bx0, by0, bx1, by1, a0, span, ida):
    """The angles (lo, hi) relative to the first beam, within ``[0, 2 pi)`` for ``lo``, that a
    rectangle (corners relative to the origin, which lies outside it) subtends, widened by the
    arctangent's margin.

    The extent's ends are the directions of the rectangle's two silhouette corners, which the
    side of each axis the origin lies on names: two arctangents instead of one per corner and
    one for the centre. (A corner not on the silhouette lies within the extent, so it never
    widens it; the beams chosen are then tested exactly, and the margin is far wider than the
    rounding of either way.)
    """
    two_pi = 2.0 * np.pi
    # x of the corners: the near vertical edge when the rectangle lies wholly to one side,
    # else both ends of the near horizontal edge (and likewise for y)
    if bx0 > 0.0:  # rectangle right of the origin
        if by0 > 0.0:
            px, py, qx, qy = bx1, by0, bx0, by1
        elif by1 < 0.0:
            px, py, qx, qy = bx0, by0, bx1, by1
        else:
            px, py, qx, qy = bx0, by0, bx0, by1
    elif bx1 < 0.0:  # left of it
        if by0 > 0.0:
            px, py, qx, qy = bx1, by1, bx0, by0
        elif by1 < 0.0:
            px, py, qx, qy = bx0, by1, bx1, by0
        else:
            px, py, qx, qy = bx1, by1, bx1, by0
    elif by0 > 0.0:  # above, across x = 0
        px, py, qx, qy = bx1, by0, bx0, by0
    else:  # below, across x = 0
        px, py, qx, qy = bx0, by1, bx1, by1
    ap = _atan2(py, px)
    d = _atan2(qy, qx) - ap  # counter-clockwise from p to q, the extent being < pi
    if d > np.pi:
        d -= two_pi
    elif d < -np.pi:
        d += two_pi
    lo = min(d, 0.0)
    hi = max(d, 0.0)
    rel = ap - a0
    rel -= two_pi * np.floor(rel / two_pi)
    return lo + rel - _MARGIN, hi + rel + _MARGIN


@numba.njit(cache=True, inline="always")
def _turns(lo, hi, span):
    """The whole turns ``m`` for which angles ``[lo, hi] + 2 pi m`` meet the beams' ``[0,
    span]`` (an extent repeats every 2 pi)."""
    two_pi = 2.0 * np.pi
    return int(np.ceil(-hi / two_pi)), int(np.floor((span - lo) / two_pi))


@numba.njit(cache=True, inline="always")
def _beams_in(lo, hi, m, ida, n):
    """First and last beam ``k`` (at angle ``k / ida``) within ``[lo, hi] + 2 pi m``; every
    beam for a single-beam laser (``ida`` 0)."""
    if ida == 0.0:
        return 0, n - 1
    two_pi = 2.0 * np.pi
    k0 = max(int(np.ceil((lo + m * two_pi) * ida)), 0)
    k1 = min(int(np.floor((hi + m * two_pi) * ida)), n - 1)
    return k0, k1


@numba.njit(cache=True, inline="always")
def _occluded(bx0, by0, bx1, by1, dmin, a0, span, ida, n, hit):
    """Whether every beam that can cross a tile (corners relative to the origin, which lies
    outside it, nearest point ``dmin`` away) already hits something nearer than ``dmin``: then
    nothing in the tile can lower a range (a box reaching out of the tile is listed in the
    other tiles it overlaps too)."""
    lo, hi = _beam_span(bx0, by0, bx1, by1, a0, span, ida)
    m0, m1 = _turns(lo, hi, span)
    for m in range(m0, m1 + 1):
        k0, k1 = _beams_in(lo, hi, m, ida, n)
        for k in range(k0, k1 + 1):
            if hit[k] >= dmin:
                return False
    return True


@numba.njit(cache=True, inline="always")
def _cast_tile(
    start, items, boxes, seen, q, ox, oy, tmin, tmax, tmax2, a0, span, ida, n, ibx, iby, hit, t_i
):  # fmt: skip
    """Lower ``hit`` (cell units) by the boxes of tile ``t_i`` not yet seen by laser ``q``."""
    for j in range(start[t_i], start[t_i + 1]):
        b = items[j]
        if seen[b] == q:
            continue
        seen[b] = q
        bx0 = boxes[b, 0] - ox
        by0 = boxes[b, 1] - oy
        bx1 = boxes[b, 2] - ox
        by1 = boxes[b, 3] - oy
        ex = max(bx0, 0.0, -bx1)
        ey = max(by0, 0.0, -by1)
        if ex * ex + ey * ey > tmax2:
            continue
        if (ex == 0.0 and ey == 0.0) or ida == 0.0:
            lo = 0.0  # the origin touches the box (or a single beam): all beams
            hi = span
        else:
            lo, hi = _beam_span(bx0, by0, bx1, by1, a0, span, ida)
        m0, m1 = _turns(lo, hi, span)
        for m in range(m0, m1 + 1):
            k0, k1 = _beams_in(lo, hi, m, ida, n)
            for k in range(k0, k1 + 1):
                t1 = bx0 * ibx[k]
                t2 = bx1 * ibx[k]
                t3 = by0 * iby[k]
                t4 = by1 * iby[k]
                tn = max(min(t1, t2), min(t3, t4))
                tf = min(max(t1, t2), max(t3, t4))
                if tf >= tn and tf >= tmin:
                    t = max(tn, tmin)
                    if t <= tmax and t < hit[k]:
                        hit[k] = t
