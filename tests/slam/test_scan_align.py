"""Tests for fleetsim.slam.scan_align: the fast matcher (climb_skip) against the exact climber."""

import numpy as np
import pytest
from test_scan_match import LASER, room_maps, scan_from

from fleetsim.errors import ParameterError
from fleetsim.slam.params import gmapping_params
from fleetsim.slam.scan_align import aligned_pose
from fleetsim.slam.scan_match import matched_poses

TRUE = np.array([0.2, -0.1, 0.05])
REACH = 0.05  # kernelSize 1 x delta 0.05: the continuous score's cap


def matches(maps, start, ranges, angles, iterations, climb_skip, minimum_score=0.0):
    return matched_poses(
        maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0,
        0.05, 0.05, iterations, minimum_score, REACH, climb_skip,
    )  # fmt: skip


@pytest.mark.parametrize("iterations", [5, 1])
def test_the_fast_matcher_finds_the_exact_matchers_pose(iterations):
    # 24 particles sampled up to 8 cm and 0.06 rad off the true pose, a 360-beam scan; with
    # one halving only the climber stops on a 2.5 cm / 0.025 rad grid (a climber without the
    # Gauss-Newton steps would stay up to 12 mm and 12 mrad off): the exact matcher's parabola
    # and the fast one's steps both get within a few millimetres of each other, the fast one
    # (fitting the walls, not the cells' mean hits) to a tenth of a millimetre of the truth
    rng = np.random.default_rng(0)
    maps = room_maps(particles=24)
    ranges, angles = scan_from(TRUE, n=360)
    start = TRUE + rng.uniform(-1, 1, (24, 3)) * [0.08, 0.08, 0.06]
    exact, exact_scores, exact_likes = matches(maps, start, ranges, angles, iterations, 0)
    fast, fast_scores, fast_likes = matches(maps, start, ranges, angles, iterations, 3)
    assert np.abs(fast[:, :2] - exact[:, :2]).max() < 0.003
    assert np.abs(fast[:, 2] - exact[:, 2]).max() < 0.003
    assert np.abs(exact[:, :2] - TRUE[:2]).max() < 0.0025
    assert np.abs(fast[:, :2] - TRUE[:2]).max() < 0.0002
    assert np.abs(fast[:, 2] - TRUE[2]).max() < 0.0002
    # scores and likelihoods of the full scan, as the exact matcher's (its score is the
    # climber's last grid point's, a little lower than at its refined pose)
    assert fast_scores == pytest.approx(exact_scores, rel=0.01)
    assert fast_likes == pytest.approx(exact_likes, rel=0.05, abs=0.5)


def test_the_fast_matcher_keeps_the_sampled_pose_below_the_minimum_score():
    maps = room_maps(particles=2)
    ranges, angles = scan_from(TRUE, n=360)
    start = TRUE + np.array([[0.03, -0.02, 0.01], [0.0, 0.0, 0.0]])
    out, scores, _ = matches(maps, start, ranges, angles, 3, 3, minimum_score=1e9)
    assert np.array_equal(out, start)
    assert scores.min() > 0.9 * 360  # the score still says how well the scan matched


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


def test_climb_skip_must_not_be_negative():
    with pytest.raises(ParameterError, match="climb_skip"):
        gmapping_params({"climb_skip": -1})
