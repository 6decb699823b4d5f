"""Tests for fleetsim.slam.scan_align: the fast matcher's Gauss-Newton step (the fast matcher
itself against the exact climber: tests/slam/test_scan_match.py)."""

import numpy as np
import pytest
from test_scan_match import LASER, room_maps, scan_from

from fleetsim.slam.scan_align import aligned_pose
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
