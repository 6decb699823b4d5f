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


def test_visible_cells_are_the_walls_a_route_passes_in_sight_of():
    occ = room()  # the desk spans x 1.5-2.5 m, y 1.0-1.5 m
    west = visible_cells(occ, RES, (0.0, 0.0), [(0.6, 1.25)], max_range=10.0, beams=2000)
    assert west[20:30, 30].all() and not west[20:30, 49].any()  # its near face, not its far one
    assert not west[54:66, 94:106].any()  # nothing inside the closed cupboard
    both = visible_cells(occ, RES, (0.0, 0.0), [(0.6, 1.25), (3.5, 1.25)], 10.0, beams=2000)
    assert both[20:30, 49].all() and (both & ~surface_cells(occ, (40, 10))).sum() == 0
    short = visible_cells(occ, RES, (0.0, 0.0), [(0.6, 1.25)], max_range=0.5)
    assert short.sum() > 0 and not short[:, 30:].any()  # nothing beyond 0.5 m
    # recall over what the route saw: a map of exactly that scores 1
    p, r, _ = occupancy_precision_recall(centres(west), occ, RES, (0, 0), None, visible=west)
    assert (p, r) == (1.0, 1.0)
