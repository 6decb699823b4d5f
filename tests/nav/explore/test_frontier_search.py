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


def test_a_door_whose_middle_alone_is_free_opens_onto_a_frontier_as_wide_as_the_door():
    # a room whose door (10 cells) carries inflation cost but for its 2 middle cells, unknown
    # beyond it: explore_lite's frontier (unknown cells with a free neighbour) is those 2 cells,
    # 0.2 m, dropped at min_frontier_size 0.5 (office seed 5: a room never explored); every
    # door cell the robot's centre may stand on borders the frontier
    d = np.full((20, 30), -1, dtype=np.int8)
    d[:, :10] = 0
    d[:, 10] = 100
    d[5:15, 10] = [90, 60, 30, 10, 0, 0, 10, 30, 60, 90]
    fs = frontiers_from_grid(d, 0.1, (0.0, 0.0), (0.35, 1.05), min_frontier_size=0.5)
    assert [f.size for f in fs] == [10]
    assert fs[0].centroid == pytest.approx((1.15, 1.0))
    d[5:15, 10] = 99  # inscribed cost: the robot's centre cannot stand there
    assert frontiers_from_grid(d, 0.1, (0.0, 0.0), (0.35, 1.05), min_frontier_size=0.1) == []


def _slam_sized(rng):
    """A gmapping-sized grid (400 x 500 cells at 0.05 m) that is all unknown but for a 4 x 3 m
    office of two rooms with a door and a gap in its outer wall, part of it seen, placed off the
    grid's middle."""
    d = np.full((400, 500), -1, dtype=np.int8)
    room = np.zeros((60, 80), dtype=np.int8)
    room[0, :] = room[-1, :] = room[:, 0] = room[:, -1] = 100
    room[:, 40] = 100
    room[25:35, 40] = 0  # the door
    room[0, 10:20] = 0  # a gap in the south wall onto the unknown outside
    room[30:, 60:] = -1  # the east room's far corner not seen yet
    room[rng.integers(1, 59, 40), rng.integers(1, 79, 40)] = 60  # some cost
    d[250:310, 120:200] = room
    return d


def test_the_known_window_gives_the_whole_grids_frontiers_and_driving_distances():
    from fleetsim.nav.explore.frontier_search import known_window
    from fleetsim.nav.explore.path_costs import path_distance_field

    d = _slam_sized(np.random.default_rng(3))
    origin, robot, peer = (-10.0, -12.0), (-10 + 130 * 0.05, -12 + 280 * 0.05), (-3.0, 7.0)
    win, worigin = known_window(d, 0.05, origin, [robot, peer])
    assert win.size < d.size / 4
    assert win.base is d or win.base is d.base  # a view, not a copy
    whole = frontiers_from_grid(d, 0.05, origin, robot, min_frontier_size=0.1)
    part = frontiers_from_grid(win, 0.05, worigin, robot, min_frontier_size=0.1)
    assert len(whole) == len(part) > 0
    for a, b in zip(whole, part):
        assert a.size == b.size and a.cost == pytest.approx(b.cost)
        np.testing.assert_allclose(a.points, b.points)
    # the peer, on unknown cells far outside the office, is inside the window
    cx = int(np.floor((peer[0] - worigin[0]) / 0.05))
    cy = int(np.floor((peer[1] - worigin[1]) / 0.05))
    assert 0 <= cx < win.shape[1] and 0 <= cy < win.shape[0]
    for allow_unknown in (False, True):
        f_whole = path_distance_field(d, 0.05, origin, robot, allow_unknown)
        f_part = path_distance_field(win, 0.05, worigin, robot, allow_unknown)
        x0 = round((worigin[0] - origin[0]) / 0.05)
        y0 = round((worigin[1] - origin[1]) / 0.05)
        known = d >= 0
        cut = f_whole[y0 : y0 + win.shape[0], x0 : x0 + win.shape[1]]
        np.testing.assert_array_equal(cut[known[y0:, x0:][: win.shape[0], : win.shape[1]]],
                                      f_part[win >= 0])  # fmt: skip
    # nothing known: the grid as it is
    empty = np.full((50, 60), -1, dtype=np.int8)
    assert known_window(empty, 0.05, origin, [robot])[0] is empty
