"""Tests for fleetsim.nav.explore.view_points: where the robot sees a frontier from."""

import math

import numpy as np
import pytest

from fleetsim.nav.explore import frontiers_from_grid
from fleetsim.nav.explore.frontier_search import INSCRIBED, Frontier
from fleetsim.nav.explore.path_costs import path_distance_field
from fleetsim.nav.explore.view_points import cell_value, view_point

RES = 0.1
ORIGIN = (0.0, 0.0)


def column_frontier(x: int, rows: range) -> Frontier:
    """A frontier of the cells in column ``x`` over ``rows`` (0.1 m cells)."""
    pts = np.array([((x + 0.5) * RES, (y + 0.5) * RES) for y in rows])
    c = pts.mean(axis=0)
    return Frontier(len(pts), (c[0], c[1]), (c[0], c[1]), (c[0], c[1]), 0.0, 0.0, pts)


def desk_corner() -> np.ndarray:
    """40 x 60 cells: a known room whose south-east part is a desk (lethal, x 3..5 m, y 1..2 m)
    with its inflation (inscribed cost one cell round it, then 60), and the strip behind the
    desk (y 0.1..1 m, x from 2.6 m) unknown: an L-shaped frontier round the desk's corner and
    along the strip's mouth, whose centroid falls in the desk's inflation."""
    d = np.zeros((40, 60), dtype=np.int8)
    d[0, :] = d[-1, :] = 100
    d[:, 0] = d[:, -1] = 100
    d[9:21, 29:51] = 60
    d[10:20, 30:50] = INSCRIBED
    d[11:19, 31:49] = 100
    d[1:10, 26:59] = -1  # the strip behind the desk
    d[9:21, 50:59] = -1  # and round its east end
    return d


def test_a_frontier_whose_centroid_the_robot_cannot_drive_to_gets_a_drivable_view_point():
    d = desk_corner()
    robot = (1.0, 3.0)
    field = path_distance_field(d, RES, ORIGIN, robot)
    frontiers = frontiers_from_grid(d, RES, ORIGIN, robot, 3.0, 1.0, 0.5)
    corner = max(frontiers, key=lambda f: f.size)
    assert math.isinf(cell_value(field, RES, ORIGIN, corner.centroid))  # not drivable
    vp = view_point(field, d, RES, ORIGIN, corner, 3.0)
    assert vp is not None
    assert math.isfinite(cell_value(field, RES, ORIGIN, vp))
    ix, iy = int(vp[0] / RES), int(vp[1] / RES)
    assert d[iy, ix] < INSCRIBED and d[iy, ix] >= 0
    # the nearest such cell to the centroid: no drivable cell is nearer
    ys, xs = np.nonzero(np.isfinite(field))
    nearest = np.hypot((xs + 0.5) * RES - corner.centroid[0], (ys + 0.5) * RES - corner.centroid[1])
    assert math.dist(vp, corner.centroid) == pytest.approx(nearest.min(), abs=1e-9)


def test_a_drivable_cell_behind_a_wall_does_not_see_the_frontier():
    d = np.zeros((40, 80), dtype=np.int8)
    d[:, 18] = 100  # a wall between the frontier (column 20) and the cells west of it
    frontier = column_frontier(20, range(10, 15))
    field = np.full(d.shape, np.inf)
    field[10:15, 17] = 1.0  # drivable, 0.3 m from the frontier, behind the wall
    field[12, 25] = 2.0  # drivable, 0.5 m from it, in sight
    assert view_point(field, d, RES, ORIGIN, frontier, 3.0) == pytest.approx((2.55, 1.25))
    # unknown cells between do not block the laser: it maps them on the way
    d[10:15, 21:25] = -1
    assert view_point(field, d, RES, ORIGIN, frontier, 3.0) == pytest.approx((2.55, 1.25))


def test_no_view_point_when_no_drivable_cell_sees_the_frontier_within_view_range():
    d = np.zeros((40, 80), dtype=np.int8)
    d[:, 18] = 100
    frontier = column_frontier(20, range(10, 15))
    field = np.full(d.shape, np.inf)
    field[10:15, 17] = 1.0  # behind the wall
    field[12, 60] = 2.0  # in sight, 4 m away
    assert view_point(field, d, RES, ORIGIN, frontier, 3.0) is None
    assert view_point(field, d, RES, ORIGIN, frontier, 4.5) == pytest.approx((6.05, 1.25))
