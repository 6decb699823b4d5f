"""Tests for fleetsim.slam.scan_align: the fast matcher's Gauss-Newton step (the fast matcher
itself against the exact climber: tests/slam/test_scan_match.py)."""

import numpy as np
import pytest
from test_scan_match import LASER, H, W, room_maps, scan_from

from fleetsim.slam.scan_align import aligned_pose, constrained_pose
from fleetsim.slam.scan_match import matched_poses

TRUE = np.array([0.2, -0.1, 0.05])
REACH = 0.05  # kernelSize 1 x delta 0.05: the continuous score's cap


def matches(maps, start, ranges, angles, iterations, climb_skip, minimum_score=0.0):
    return matched_poses(
        maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0,
        0.05, 0.05, iterations, minimum_score, REACH, climb_skip,
    )  # fmt: skip


def test_a_gauss_newton_step_closes_most_of_the_gap():
    # from 1-2 cm and 10 mrad off, one step of the point-to-line fit lands within 0.5 mm and
    # 0.2 mrad of the true pose (a point-to-point step goes a third of the way), and the
    # score it reports is the continuous score at the pose it started from
    maps = room_maps(particles=1)
    ranges, angles = scan_from(TRUE, n=360)
    ex, ey = ranges * np.cos(angles), ranges * np.sin(angles)
    for off in ([0.015, -0.01, 0.01], [-0.02, 0.0, -0.01], [0.0, 0.02, 0.0]):
        pose = TRUE + np.array(off)
        new, score = aligned_pose(
            maps.pool, maps.table, 0, pose, LASER, ex, ey, maps.geom, 1, 0.05, REACH
        )
        assert np.abs(new[:2] - TRUE[:2]).max() < 0.0005, off
        assert abs(new[2] - TRUE[2]) < 0.0002, off
        _, ref, _ = matches(maps, pose[None], ranges, angles, 0, 0, minimum_score=1e9)
        assert score == pytest.approx(ref[0], rel=1e-5)


def test_along_a_lone_wall_the_match_keeps_the_sampled_translation():
    # the beams that end on the north wall only: they fix y and the yaw, not x (along it)
    maps = room_maps(particles=1)
    ranges, angles = scan_from(TRUE, n=360)
    ex, ey = ranges * np.cos(angles), ranges * np.sin(angles)
    c, s = np.cos(TRUE[2]), np.sin(TRUE[2])
    lx, ly = TRUE[0] + c * LASER[0] - s * LASER[1], TRUE[1] + s * LASER[0] + c * LASER[1]
    a = TRUE[2] + LASER[2] + angles
    wx, wy = lx + ranges * np.cos(a), ly + ranges * np.sin(a)
    north = (np.abs(wy - H) < 1e-6) & (np.abs(wx) < W - 1.0)
    assert north.sum() > 30
    sampled = TRUE + np.array([-0.04, 0.03, 0.0])  # where the motion model put the particle
    matched = TRUE + np.array([0.05, 0.0, 0.0])  # the climber slid 5 cm along the wall

    def constrained(pose, beams, threshold):
        bx, by = ex[beams], ey[beams]
        return constrained_pose(
            maps.pool, maps.table, 0, pose, sampled, LASER, bx, by, maps.geom, 1, 0.05, REACH,
            threshold,
        )  # fmt: skip

    out = constrained(matched, north, 20.0)
    assert out == pytest.approx([sampled[0], TRUE[1], TRUE[2]], abs=2e-3)
    # the whole room constrains both directions: a match there is kept as it is
    everything = np.ones(len(ex), dtype=bool)
    assert constrained(TRUE, everything, 20.0) == pytest.approx(TRUE)
    # off (threshold 0): kept as well; and with no wall in reach, the sampled translation
    assert constrained(matched, north, 0.0) == pytest.approx(matched)
    far = constrained(matched + np.array([0.0, 1.0, 0.0]), north, 20.0)
    assert far[:2] == pytest.approx(sampled[:2])
