"""Tests for fleetsim.nav.explore.peers: which frontier an explorer takes beside a peer."""

import numpy as np
import pytest

from fleetsim.nav.explore.frontier_search import Frontier
from fleetsim.nav.explore.peers import frontier_for_robot

POTENTIAL, GAIN, RES = 3.0, 1.0, 0.05  # slam_explore's potential_scale, gain_scale; cell m


def frontier(cells: np.ndarray, robot: tuple[float, float]) -> Frontier:
    """A frontier of (N, 2) cell centres as frontiers_from_grid builds it (explore_lite cost)."""
    d = np.hypot(cells[:, 0] - robot[0], cells[:, 1] - robot[1])
    k = int(np.argmin(d))
    return Frontier(
        size=len(cells),
        centroid=(float(cells[:, 0].mean()), float(cells[:, 1].mean())),
        middle=tuple(cells[len(cells) // 2]),
        initial=tuple(cells[k]),
        min_distance=float(d[k]),
        cost=float(POTENTIAL * d[k] * RES - GAIN * len(cells) * RES),
        points=cells,
    )


def line(x0: float, x1: float, y: float) -> np.ndarray:
    xs = np.arange(x0, x1, RES)
    return np.c_[xs, np.full_like(xs, y)]


def ranked(*frontiers: Frontier) -> list[Frontier]:
    return sorted(frontiers, key=lambda f: f.cost)


ME, PEER = (4.0, 10.0), (23.0, 10.0)


def test_a_band_reaching_towards_this_robot_whose_centroid_is_nearer_the_peer_is_the_peers():
    # the edge of the unknown east part: along the corridor from 0.5 m east of this robot, then
    # north along x 19 m; its nearest cell is this robot's (0.5 m, the peer's 4 m: the old
    # peer_frames rule gave it to this robot), its centroid (the goal it would send, about
    # (15, 12.7)) is nearer to the peer; a room door 3 m away is nearer to it
    north = np.c_[np.full(240, 19.0), 10.05 + RES * np.arange(240)]
    band = frontier(np.r_[line(4.5, 19.0, 10.0), north], ME)
    door = frontier(line(2.5, 3.5, 7.0), ME)
    candidates = ranked(band, door)
    assert candidates[0] is band  # alone, the band is the cheapest (explore_lite's choice)
    chosen = frontier_for_robot(candidates, ME, None, [], [PEER], peer_radius=3.0)
    assert chosen is door
    # without a peer, explore_lite's choice
    assert frontier_for_robot(candidates, ME, None, [], [], peer_radius=3.0) is band


def test_the_frontier_it_heads_for_is_kept_unless_another_is_clearly_cheaper():
    # two small corners of about the same cost, both on this robot's side
    a = frontier(line(1.0, 1.8, 1.0), ME)  # 16 cells
    b = frontier(line(7.0, 7.75, 1.0), ME)  # 15 cells
    candidates = ranked(a, b)
    first, second = candidates
    margin = POTENTIAL * RES * 5.0  # switch_distance 5 m
    assert abs(first.cost - second.cost) < margin
    goal = second.centroid  # heading for the dearer one
    kept = frontier_for_robot(candidates, ME, goal, [], [PEER], 3.0, margin)
    assert kept is second
    # explore_lite's replanning (no margin) flips to the cheaper one
    assert frontier_for_robot(candidates, ME, goal, [], [PEER], 3.0, 0.0) is first
    # a much cheaper frontier (a wide door right beside it) wins despite the margin
    big = frontier(line(4.0, 7.0, 8.5), ME)
    assert frontier_for_robot(ranked(a, b, big), ME, goal, [], [PEER], 3.0, margin) is big
    # the tracked frontier shrank and its centroid moved: still the same frontier
    shrunk = frontier(line(7.4, 7.75, 1.0), ME)
    assert frontier_for_robot(ranked(a, shrunk), ME, goal, [], [PEER], 3.0, margin) is shrunk


def test_the_frontier_it_heads_for_is_left_when_the_peer_takes_it():
    a = frontier(line(1.0, 1.8, 1.0), ME)
    b = frontier(line(7.0, 7.75, 1.0), ME)
    margin = POTENTIAL * RES * 5.0
    chosen = frontier_for_robot(ranked(a, b), ME, b.centroid, [b.centroid], [PEER], 3.0, margin)
    assert chosen is a


def test_a_robot_whose_side_is_done_helps_with_the_nearest_frontier_the_peer_leaves():
    # every frontier is nearer to the peer; the peer heads for the east one
    west = frontier(line(15.0, 16.0, 1.0), ME)
    east = frontier(line(24.0, 26.0, 1.0), ME)
    candidates = ranked(west, east)
    chosen = frontier_for_robot(candidates, ME, None, [east.centroid], [PEER], 3.0)
    assert chosen is west
    # only the peer's frontier left, the peer nearer to it: wait rather than follow the peer
    assert frontier_for_robot([east], ME, None, [east.centroid], [PEER], 3.0) is None
    # ... unless this robot is the nearer one (the peer leaves it when it sees this goal)
    assert frontier_for_robot([west], ME, None, [west.centroid], [(30.0, 10.0)], 3.0) is west
    # a peer whose position tf does not know: go anyway (peer_goals without peer_frames)
    assert frontier_for_robot([east], ME, None, [east.centroid], [], 3.0) is east


@pytest.mark.parametrize("goal", [None, (1.4, 1.0)])
def test_without_peers_or_margin_the_cheapest_frontier_is_explore_lites_choice(goal):
    a = frontier(line(1.0, 1.8, 1.0), ME)
    b = frontier(line(7.0, 7.75, 1.0), ME)
    candidates = ranked(a, b)
    assert frontier_for_robot(candidates, ME, goal, [], [], 3.0, 0.0) is candidates[0]
