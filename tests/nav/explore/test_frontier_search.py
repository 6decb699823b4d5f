"""Tests for fleetsim.nav.explore.frontier_search against explore_lite's rules."""

import numpy as np
import pytest

from fleetsim.nav.explore import frontiers_from_grid


def grid():
    """20 x 30 cells at 0.1 m: a known free room x < 1.0 m, walls at y = 0 and 1.9, unknown
    beyond; a 6-cell free pocket behind a wall (unreachable) next to unknown cells."""
    d = np.full((20, 30), -1, dtype=np.int8)
    d[:, :10] = 0
    d[0, :10] = d[19, :10] = 100
    d[5:8, 5] = 100  # a pillar with inflation-like cost next to it
    d[5:8, 6] = 50
    d[2:8, 20] = 0  # the pocket, not reachable from the room
    return d


def test_frontier_is_the_unknown_edge_reachable_from_the_robot():
    fs = frontiers_from_grid(grid(), 0.1, (0.0, 0.0), (0.35, 1.05), min_frontier_size=0.5)
    assert len(fs) == 1  # the pocket's edge is not reachable
    f = fs[0]
    assert f.size == 18  # x = 10, rows 1..18 (the wall rows are not free)
    assert f.centroid == pytest.approx((1.05, 1.0))
    assert f.min_distance == pytest.approx(np.hypot(0.7, 0.0), abs=1e-9)
    assert f.cost == pytest.approx(1e-3 * f.min_distance * 0.1 - 18 * 0.1)


def test_small_frontiers_are_dropped_and_the_list_is_sorted_by_cost():
    d = grid()
    d[1:17, 10] = 100  # close the room but for a 2-cell gap at rows 17..18
    d[3:7, 0] = -1  # and a 4-cell unknown hole at its far side
    fs = frontiers_from_grid(d, 0.1, (0.0, 0.0), (0.35, 1.05), min_frontier_size=0.3)
    assert [f.size for f in fs] == [4]  # the 2-cell gap (0.2 m) is too small
    fs = frontiers_from_grid(d, 0.1, (0.0, 0.0), (0.35, 1.05), min_frontier_size=0.1)
    assert [f.size for f in fs] == [4, 2]  # bigger gain first


def test_a_robot_on_cost_starts_from_the_nearest_free_cell_and_off_the_grid_sees_none():
    on_cost = frontiers_from_grid(grid(), 0.1, (0.0, 0.0), (0.65, 0.65))
    assert len(on_cost) == 1
    assert frontiers_from_grid(grid(), 0.1, (0.0, 0.0), (-1.0, 1.0)) == []


def test_a_door_with_a_little_inflation_cost_does_not_hide_the_frontiers_beyond_it():
    # the robot in a closed room whose only door carries cost 1 (inflation from the door
    # posts); beyond the door a known corridor with an unknown end. explore_lite's walk
    # through free cells only stops at the door and finds nothing (m-explore #26)
    d = np.full((20, 30), -1, dtype=np.int8)
    d[:, :10] = 0  # the room
    d[:, 10] = 100  # its wall ...
    d[9:11, 10] = 1  # ... with a door of cost 1
    d[:, 11:20] = 0  # the corridor, unknown beyond x = 2.0 m
    d[2:4, 5] = 99  # inscribed cost: impassable, the walk goes round it
    fs = frontiers_from_grid(d, 0.1, (0.0, 0.0), (0.35, 1.05))
    assert [f.size for f in fs] == [20]
    assert fs[0].centroid == pytest.approx((2.05, 1.0))
    d[9:11, 10] = 99  # a door the robot does not fit through: nothing reachable beyond
    assert frontiers_from_grid(d, 0.1, (0.0, 0.0), (0.35, 1.05)) == []
