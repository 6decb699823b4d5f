"""Laser sweeps over a map's walls checked against casting on the map's extruded wall boxes."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.sim import occupancy_cast, raycast
from fleetsim.sim.mapworld import OccupancyMap, wall_boxes

X0, Y0, RES = -1.0, 2.0, 0.1


def random_map(rng):
    occ = rng.random((40, 50)) < 0.04
    occ[10, 5:45] = True  # a long wall
    occ[20:30, 20:23] = True  # a thick block (interior cells)
    return occ


def reference(occ, origins, angle0, inc, nb, rmin, rmax):
    """Per-beam ranges from ``raycast`` over the four sides of every extruded wall box; a beam
    whose start (at range_min) lies inside a wall hits there (the sides alone would not say)."""
    boxes = wall_boxes(OccupancyMap(occ, RES, (X0, Y0, 0.0), "<test>"), 1.0)
    segs = []
    for cx, cy, _, hx, hy, _, _ in boxes:
        c = [(cx - hx, cy - hy), (cx + hx, cy - hy), (cx + hx, cy + hy), (cx - hx, cy + hy)]
        segs += [[0, *c[k], *c[(k + 1) % 4], 0.0, 1.0] for k in range(4)]
    pgrid = raycast.grid_from_primitives(np.array(segs), cell=0.5)
    which = np.repeat(np.arange(len(nb)), nb)
    beam = np.concatenate([np.arange(k) for k in nb])
    angles = angle0[which] + beam * inc[which]
    want = raycast.cast(pgrid, origins[which], angles, rmin[which], rmax[which], -1)
    start = origins[which, :2] + rmin[which, None] * np.c_[np.cos(angles), np.sin(angles)]
    col = np.floor((start[:, 0] - X0) / RES).astype(int)
    row = np.floor((start[:, 1] - Y0) / RES).astype(int)
    inside = (col >= 0) & (col < occ.shape[1]) & (row >= 0) & (row < occ.shape[0])
    inside[inside] = occ[row[inside], col[inside]]
    want[inside] = rmin[which][inside]
    return want


def sweep(occ, origins, angle0, inc, nb, rmin, rmax, zmax=1.0):
    wt = occupancy_cast.wall_tiles(occ, tile=8)
    out = np.full(int(nb.sum()), np.inf)
    offsets = np.concatenate([[0], np.cumsum(nb)[:-1]]).astype(np.int64)
    occupancy_cast.ranges_from_walls(
        origins, angle0, inc, nb, offsets, rmin, rmax,
        wt.occupied, wt.boxes, wt.start, wt.items, wt.tile, wt.th, wt.tw,
        X0, Y0, RES, zmax, out,
    )  # fmt: skip
    return out


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_sweeps_match_casting_on_the_extruded_boxes(seed):
    """Full circles, partial fields of view, clockwise lasers and single beams, from free cells."""
    rng = np.random.default_rng(seed)
    occ = random_map(rng)
    n = 12
    free = np.argwhere(~occ)[rng.integers(0, (~occ).sum(), n)]
    origins = np.c_[
        X0 + (free[:, 1] + rng.random(n)) * RES,
        Y0 + (free[:, 0] + rng.random(n)) * RES,
        np.full(n, 0.3),
    ]
    nb = rng.choice([1, 7, 90, 360, 720], n).astype(np.int64)
    fov = rng.choice([2 * np.pi, np.pi, 0.5, 4.7], n) * rng.choice([1.0, -1.0], n)
    inc = np.where(nb > 1, fov / np.maximum(nb - 1, 1), 0.0)
    angle0 = rng.uniform(-np.pi, np.pi, n)
    rmin = rng.choice([0.0, 0.12], n)
    rmax = rng.choice([0.5, 2.0, 8.0], n)
    got = sweep(occ, origins, angle0, inc, nb, rmin, rmax)
    want = reference(occ, origins, angle0, inc, nb, rmin, rmax)
    np.testing.assert_allclose(got, want, atol=1e-9)


def test_a_beam_starting_inside_a_wall_hits_at_range_min():
    occ = np.zeros((20, 20), bool)
    occ[5:15, 5:15] = True  # a thick block; (10, 10) is deep inside it
    origin = np.array(
        [[X0 + 10.5 * RES, Y0 + 10.5 * RES, 0.3], [X0 + 1.5 * RES, Y0 + 10.5 * RES, 0.3]]
    )
    nb = np.array([8, 1], np.int64)
    got = sweep(
        occ, origin, np.array([0.0, 0.0]), np.array([np.pi / 4, 0.0]), nb,
        np.array([0.05, 0.05]), np.array([5.0, 5.0]),
    )  # fmt: skip
    np.testing.assert_allclose(got[:8], 0.05)  # inside: every beam at range_min
    assert got[8] == pytest.approx(3.5 * RES)  # from free space: the block's face


def test_lasers_above_the_walls_see_nothing():
    occ = np.ones((10, 10), bool)
    origin = np.array([[X0 + 0.5, Y0 + 0.5, 1.5], [X0 + 0.5, Y0 + 0.5, -0.1]])
    got = sweep(
        occ, origin, np.zeros(2), np.full(2, 0.1), np.array([4, 4], np.int64),
        np.zeros(2), np.full(2, 3.0),
    )  # fmt: skip
    assert np.isinf(got).all()


def test_wall_tiles_list_every_box_in_every_tile_it_overlaps():
    occ = np.zeros((30, 30), bool)
    occ[3, 2:27] = True  # one long box across four 8-cell tiles
    wt = occupancy_cast.wall_tiles(occ, tile=8)
    assert len(wt.boxes) == 1 and (wt.th, wt.tw) == (4, 4)
    holding = [k for k in range(16) if wt.start[k + 1] > wt.start[k]]
    assert holding == [0, 1, 2, 3]


@settings(max_examples=200, deadline=None)
@given(
    x0=st.floats(-5, 5), y0=st.floats(-5, 5), w=st.floats(0.01, 3), h=st.floats(0.01, 3),
    a0=st.floats(-4, 4),
)  # fmt: skip
def test_beam_span_covers_a_rectangles_angular_extent(x0, y0, w, h, a0):
    """From its two silhouette corners, the span holds the directions of all four corners
    (exact arctangents), widened by no more than the margin plus the polynomial's error."""
    bx0, by0, bx1, by1 = x0, y0, x0 + w, y0 + h
    if bx0 <= 0 <= bx1 and by0 <= 0 <= by1:
        return  # the origin inside: the caller casts every beam
    lo, hi = occupancy_cast._beam_span(bx0, by0, bx1, by1, a0, 2 * np.pi, 1.0)
    assert 0 <= lo + occupancy_cast._MARGIN < 2 * np.pi + 1e-9 and hi - lo < np.pi + 1e-3
    corners = np.arctan2([by0, by0, by1, by1], [bx0, bx1, bx0, bx1]) - a0
    mid = (lo + hi) / 2  # each corner's direction, unwrapped next to the span's middle
    rel = corners - 2 * np.pi * np.round((corners - mid) / (2 * np.pi))
    assert np.all(rel >= lo + occupancy_cast._MARGIN - 2e-5)
    assert np.all(rel <= hi - occupancy_cast._MARGIN + 2e-5)
    assert rel.min() <= lo + occupancy_cast._MARGIN + 2e-5
    assert rel.max() >= hi - occupancy_cast._MARGIN - 2e-5
