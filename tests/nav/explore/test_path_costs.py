"""Tests for fleetsim.nav.explore.path_costs (explore's ``path_costs``): the distance a robot
drives to a frontier, and frontiers shared out between two robots by it."""

import math

import numpy as np
import pytest

from fleetsim.nav.explore import frontiers_from_grid
from fleetsim.nav.explore.path_costs import (
    by_path,
    frontier_distances,
    path_distance_field,
)
from fleetsim.nav.explore.peers import frontier_for_robot

RES = 0.1
POTENTIAL, GAIN = 3.0, 1.0  # slam_explore's potential_scale, gain_scale


def rooms() -> np.ndarray:
    """40 x 60 cells at 0.1 m (6 x 4 m): a corridor y 3..4 m along the top; below it two rooms
    x 0..3 and 3..6 m split by a wall at x 3 m, each with a 1 m door to the corridor at its
    west end (x 0.5..1.5 and 3.5..4.5 m). Known and free but for the walls, except the south
    strip (y < 0.5 m) of each room, unknown: two frontiers along y 0.5 m."""
    d = np.zeros((40, 60), dtype=np.int8)
    d[0, :] = d[-1, :] = 100
    d[:, 0] = d[:, -1] = 100
    d[30, :] = 100  # the corridor's south wall, y 3.0 m
    d[30, 5:15] = 0  # door into the west room
    d[30, 35:45] = 0  # door into the east room
    d[:30, 30] = 100  # the wall between the rooms, x 3.0 m
    d[1:5, 1:30] = -1  # the rooms' unknown south strips
    d[1:5, 31:59] = -1
    return d


WEST_ROBOT = (2.5, 2.0)  # in the west room, beside the wall
PEER = (5.0, 3.5)  # in the corridor above the east room's door


def test_the_field_goes_round_walls_through_doors_and_not_into_unknown_cells():
    d = rooms()
    field = path_distance_field(d, RES, (0.0, 0.0), WEST_ROBOT)
    assert field[20, 25] == 0.0  # its own cell
    # (3.5, 2.0) is 1 m east through the wall: out by the west door's east post, along the
    # corridor, in by the east door's west post: at least 1.4 + 2 + 1 m
    through = field[20, 35]
    assert 4.4 < through < 5.5
    # straight across its own room: about the straight line (navfn's approximation)
    assert field[20, 5] == pytest.approx(2.0, rel=0.1)
    assert np.isinf(field[2, 10])  # unknown: not entered
    assert np.isinf(field[30, 30])  # a wall
    # off the grid: nothing reached
    assert np.isinf(path_distance_field(d, RES, (0.0, 0.0), (-1.0, 2.0))).all()


def test_a_robot_standing_on_a_wall_cell_starts_from_the_nearest_passable_one():
    field = path_distance_field(rooms(), RES, (0.0, 0.0), (3.05, 2.0))  # on the wall x 3 m
    assert math.isfinite(field[20, 25]) or math.isfinite(field[20, 35])


def test_frontier_distances_and_ranking_by_path():
    d = rooms()
    fs = frontiers_from_grid(d, RES, (0.0, 0.0), WEST_ROBOT, POTENTIAL, GAIN, 0.5)
    west, east = sorted(fs, key=lambda f: f.centroid[0])
    field = path_distance_field(d, RES, (0.0, 0.0), WEST_ROBOT)
    dist = frontier_distances(field, RES, (0.0, 0.0), [west, east])
    assert dist[0] == pytest.approx(1.5, abs=0.15)  # straight down to y 0.5 m
    assert dist[1] > 5.0  # the east room's strip, by the doors
    # make the east strip the bigger one: by straight lines it is cheapest, by path not
    d[1:5, 31:59] = 0
    d[1:5, 40:59] = -1  # east strip x 4..5.9 m
    d[1:5, 1:20] = 0  # west strip x 2..2.9 m, the smaller
    fs = frontiers_from_grid(d, RES, (0.0, 0.0), WEST_ROBOT, POTENTIAL, GAIN, 0.5)
    assert [f.centroid[0] > 3.0 for f in fs] == [True, False]  # explore_lite: east first
    ranked, dist = by_path(d, RES, (0.0, 0.0), fs, [WEST_ROBOT, PEER], POTENTIAL, GAIN)
    assert [f.centroid[0] > 3.0 for f in ranked] == [False, True]  # by path: west first
    size = ranked[0].size
    assert ranked[0].cost == pytest.approx(POTENTIAL * dist[0, 0] * RES - GAIN * size * RES)
    assert ranked[0].min_distance == fs[1].min_distance  # progress stays the straight line
    assert dist.shape == (2, 2) and dist[1, 1] < dist[1, 0]  # the peer is nearer the east one


def test_the_next_rooms_frontier_is_the_peers_when_the_peer_drives_less_to_it():
    # the east strip: 0.5-1 m from this robot in a straight line through the wall, ~7 m by the
    # doors; the peer above the east door ~3.5 m by path but farther in a straight line
    d = rooms()
    d[1:5, 31:59] = 0
    d[1:5, 31:45] = -1  # east strip x 3.1..4.5 m
    d[1:5, 1:20] = 0  # west strip x 2..2.9 m, smaller than the east one
    fs = frontiers_from_grid(d, RES, (0.0, 0.0), WEST_ROBOT, POTENTIAL, GAIN, 0.5)
    west = next(f for f in fs if f.centroid[0] < 3.0)
    east = next(f for f in fs if f.centroid[0] > 3.0)
    assert math.dist(east.centroid, WEST_ROBOT) < math.dist(east.centroid, PEER)
    # straight lines: the east strip is this robot's, and the cheapest
    assert frontier_for_robot(fs, WEST_ROBOT, None, [], [PEER], 3.0) is east
    ranked, dist = by_path(d, RES, (0.0, 0.0), fs, [WEST_ROBOT, PEER], POTENTIAL, GAIN)
    chosen = frontier_for_robot(ranked, WEST_ROBOT, None, [], [PEER], 3.0, distances=dist)
    assert chosen.centroid == west.centroid
    # the peer, computing the same distances from its side, takes the east strip
    ranked_p, dist_p = by_path(d, RES, (0.0, 0.0), fs, [PEER, WEST_ROBOT], POTENTIAL, GAIN)
    mine = frontier_for_robot(ranked_p, PEER, None, [], [WEST_ROBOT], 3.0, distances=dist_p)
    assert mine.centroid == east.centroid


def test_with_only_the_peers_frontier_left_the_robot_farther_by_path_waits():
    # only the east strip left, the peer heading for it and nearer by path: wait, though the
    # strip is nearer to this robot in a straight line (which would send it after the peer)
    d = rooms()
    d[1:5, 1:30] = 0
    fs = frontiers_from_grid(d, RES, (0.0, 0.0), WEST_ROBOT, POTENTIAL, GAIN, 0.5)
    (east,) = fs
    peer_goal = [east.centroid]
    assert frontier_for_robot(fs, WEST_ROBOT, None, peer_goal, [PEER], 3.0) is east
    ranked, dist = by_path(d, RES, (0.0, 0.0), fs, [WEST_ROBOT, PEER], POTENTIAL, GAIN)
    assert frontier_for_robot(ranked, WEST_ROBOT, None, peer_goal, [PEER], 3.0, 0.0, dist) is None
