"""Tests for fleetsim.slam.quality: ATE and the map's precision and recall against the truth."""

import numpy as np
import pytest
from scipy import ndimage

from fleetsim.slam.quality import ate, occupancy_precision_recall, surface_cells, visible_cells

RES = 0.05


def room():
    """(80, 120) cells: 0.2 m outer walls, a solid 1 x 0.5 m desk, a closed 1 m cupboard."""
    occ = np.zeros((80, 120), dtype=bool)
    occ[:4], occ[-4:], occ[:, :4], occ[:, -4:] = True, True, True, True
    occ[20:30, 30:50] = True  # the desk
    occ[50:70, 90:110] = True  # the cupboard's walls ...
    occ[54:66, 94:106] = False  # ... around a space no robot gets into
    return occ


def centres(mask):
    iy, ix = np.nonzero(mask)
    return np.c_[(ix + 0.5) * RES, (iy + 0.5) * RES]


def test_only_what_a_laser_can_see_from_the_start_counts():
    occ = room()
    seen = surface_cells(occ, (40, 10))
    # the desk's outline (2 * (20 + 10) - 4 cells) and not its inside; the room's inner wall
    # faces and not the cells behind them; the cupboard's outside, not its inside faces
    assert seen[20:30, 30:50].sum() == 56
    assert not seen[:3].any() and seen[3, 4:116].all()
    assert seen[50:70, 90:110].sum() == 76 and not seen[54:66, 94:106].any()
    with pytest.raises(ValueError, match=r"start cell \(0, 0\) is occupied"):
        surface_cells(occ, (0, 0))


def test_a_shifted_complete_map_scores_one_after_alignment_and_a_half_map_half_recall():
    occ = room()
    seen = surface_cells(occ, (40, 10))
    shifted = centres(seen) + np.array([0.1, -0.05])
    p, r, (dx, dy, yaw) = occupancy_precision_recall(shifted, occ, RES, (0, 0), (0.5, 2.0))
    assert (p, r) == (1.0, 1.0) and (dx, dy, yaw) == pytest.approx((-0.1, 0.05, 0.0), abs=1e-9)
    # only the west half mapped: everything mapped is right, half the walls are missing (not
    # aligned: a shift along the walls would find a few more cells)
    west = seen.copy()
    west[:, 60:] = False
    p, r, _ = occupancy_precision_recall(
        centres(west), occ, RES, (0, 0), (0.5, 2.0), shifts=0.0, turns=0.0
    )
    near_west = ndimage.distance_transform_edt(~west) * RES <= 0.1 + 1e-9  # a slow reference
    assert p == 1.0 and r == pytest.approx((seen & near_west).sum() / seen.sum())
    assert 0.45 < r < 0.55
    # cells in free space lower the precision
    noise = np.r_[centres(seen), [[2.0, 2.0], [3.0, 3.0]]]
    p, r, _ = occupancy_precision_recall(noise, occ, RES, (0, 0), (0.5, 2.0))
    assert p == pytest.approx(1 - 2 / len(noise)) and r == 1.0


def test_ate_is_zero_for_a_rigidly_moved_trajectory():
    rng = np.random.default_rng(0)
    truth = rng.uniform(0, 10, (50, 2))
    c, s = np.cos(0.3), np.sin(0.3)
    est = truth @ np.array([[c, s], [-s, c]]) + (1.0, -2.0)
    assert ate(est, truth) == pytest.approx(0.0, abs=1e-9)
    assert ate(est + rng.normal(0, 0.1, est.shape), truth) == pytest.approx(0.14, abs=0.04)


ALL_ROUND = np.linspace(0.0, 2 * np.pi, 2000, endpoint=False)  # a 360-degree laser's beams


def test_visible_cells_are_the_walls_a_route_passes_in_sight_of():
    occ = room()  # the desk spans x 1.5-2.5 m, y 1.0-1.5 m
    west = visible_cells(occ, RES, (0.0, 0.0), [(0.6, 1.25, 0.0)], ALL_ROUND, max_range=10.0)
    assert west[20:30, 30].all() and not west[20:30, 49].any()  # its near face, not its far one
    assert not west[54:66, 94:106].any()  # nothing inside the closed cupboard
    route = [(0.6, 1.25, 0.0), (3.5, 1.25, 0.0)]
    both = visible_cells(occ, RES, (0.0, 0.0), route, ALL_ROUND, 10.0)
    assert both[20:30, 49].all() and (both & ~surface_cells(occ, (40, 10))).sum() == 0
    short = visible_cells(occ, RES, (0.0, 0.0), [(0.6, 1.25, 0.0)], ALL_ROUND, max_range=0.5)
    assert short.sum() > 0 and not short[:, 30:].any()  # nothing beyond 0.5 m
    # recall over what the route saw: a map of exactly that scores 1
    p, r, _ = occupancy_precision_recall(centres(west), occ, RES, (0, 0), None, visible=west)
    assert (p, r) == (1.0, 1.0)


def test_visible_cells_keep_to_the_lasers_field_of_view():
    occ = room()
    # a 180-degree laser at the desk's west, facing east: the desk's west face, not the west
    # wall behind the laser; facing west: the other way round
    front = np.linspace(-np.pi / 2, np.pi / 2, 1000)
    east = visible_cells(occ, RES, (0.0, 0.0), [(0.6, 1.25, 0.0)], front, 10.0)
    west = visible_cells(occ, RES, (0.0, 0.0), [(0.6, 1.25, np.pi)], front, 10.0)
    assert east[20:30, 30].all() and not east[:, 3].any()
    assert west[5:75, 3].all() and not west[20:30, 30].any()


def test_no_beam_slips_between_cells_that_touch_at_a_corner():
    # a wall drawn diagonally: cells touching at their corners only, as maps draw slanted walls
    occ = np.zeros((60, 60), dtype=bool)
    for k in range(60):
        occ[k, 59 - k] = True
    below = visible_cells(occ, RES, (0.0, 0.0), [(0.5, 0.5, 0.0)], ALL_ROUND, 10.0)
    iy, ix = np.nonzero(below)
    assert len(iy) > 40 and (iy + ix == 59).all()  # the diagonal, nothing beyond it
    # stepping along each beam at half a cell (this function before) saw through it: 1 beam
    # in ~10 slipped between two corners, and the cells beyond counted as in sight
    steps = np.arange(0.0, 10.0, RES / 2)
    x = 0.5 + np.cos(ALL_ROUND)[:, None] * steps
    y = 0.5 + np.sin(ALL_ROUND)[:, None] * steps
    cx, cy = np.floor(x / RES).astype(int), np.floor(y / RES).astype(int)
    inside = (cx >= 0) & (cy >= 0) & (cx < 60) & (cy < 60)
    hit = np.zeros(cx.shape, dtype=bool)
    hit[inside] = occ[cy[inside], cx[inside]]
    past = inside & (cx + cy > 59)  # a step beyond the wall before any step on it
    first_hit = np.where(hit.any(1), hit.argmax(1), steps.size)
    first_past = np.where(past.any(1), past.argmax(1), steps.size)
    assert (first_past < first_hit).sum() > 50


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_visible_cells_are_where_the_simulators_laser_ends(seed):
    """The first wall of each beam is the cell the simulator's own laser (which casts on the
    boxes the world's walls are extruded into, `fleetsim.sim.occupancy_cast`) ends in."""
    from fleetsim.sim import occupancy_cast

    rng = np.random.default_rng(seed)
    occ = rng.random((40, 50)) < 0.05
    occ[[0, -1]], occ[:, [0, -1]] = True, True
    free = np.argwhere(~occ)
    poses = []
    for row, col in free[rng.choice(len(free), 8, replace=False)]:
        poses.append(((col + rng.random()) * RES, (row + rng.random()) * RES, rng.uniform(-3, 3)))
    poses = np.array(poses)
    angles = np.linspace(-2.0, 2.0, 300)
    seen = visible_cells(occ, RES, (0.0, 0.0), poses, angles, max_range=1.2)
    wt = occupancy_cast.wall_tiles(occ, tile=8)
    n = len(poses)
    ranges = np.full(n * len(angles), np.inf)
    occupancy_cast.ranges_from_walls(
        np.c_[poses[:, :2], np.full(n, 0.5)], poses[:, 2] + angles[0],
        np.full(n, angles[1] - angles[0]), np.full(n, len(angles), np.int64),
        np.arange(n, dtype=np.int64) * len(angles), np.zeros(n), np.full(n, 1.2),
        wt.occupied, wt.boxes, wt.start, wt.items, wt.tile, wt.th, wt.tw,
        0.0, 0.0, RES, 1.0, ranges,
    )  # fmt: skip
    a = (poses[:, 2:3] + angles).ravel()
    r = ranges + 1e-6  # just inside the wall the beam ends on
    ok = np.isfinite(ranges)
    x = np.repeat(poses[:, 0], len(angles)) + r * np.cos(a)
    y = np.repeat(poses[:, 1], len(angles)) + r * np.sin(a)
    want = np.zeros_like(occ)
    want[np.floor(y[ok] / RES).astype(int), np.floor(x[ok] / RES).astype(int)] = True
    assert seen.sum() > 50 and (seen == want).all()
