"""Tests for fleetsim.slam.scan_match against a slow transcription of gmapping's score."""

import math

import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from fleetsim.slam.scan_match import add_hits, endpoint_cells, matched_poses
from fleetsim.slam.tiles import CowTiles

LASER = np.array([0.1, 0.05, 0.2])
GEOM_ARGS = (-4.0, -4.0, 4.0, 4.0, 0.05)
W, H = 3.013, 2.017  # half sizes of the room, m


def room_maps(particles=2):
    """Hit maps of a 6 x 4 m rectangle of walls seen from the origin, identical per particle.

    The walls lie off cell boundaries (W, H), so rounding cannot put a beam in another cell.
    """
    maps = CowTiles(particles, *GEOM_ARGS)
    xs = np.arange(-W, W, 0.02)
    ys = np.arange(-H, H, 0.02)
    pts = np.concatenate(
        [
            np.c_[xs, np.full_like(xs, -H)],
            np.c_[xs, np.full_like(xs, H)],
            np.c_[np.full_like(ys, -W), ys],
            np.c_[np.full_like(ys, W), ys],
        ]
    )
    poses = np.zeros((particles, 3))
    r = np.hypot(pts[:, 0], pts[:, 1])
    a = np.arctan2(pts[:, 1], pts[:, 0])
    cells, hits = endpoint_cells(poses, np.zeros(3), r, a, maps.geom)
    maps.write(add_hits, cells, hits)
    return maps


def scan_from(pose, n=180):
    """Exact ranges of the rectangle from the laser at ``pose (+) LASER``."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    lx = pose[0] + c * LASER[0] - s * LASER[1]
    ly = pose[1] + s * LASER[0] + c * LASER[1]
    angles = -np.pi + 2 * np.pi / n * np.arange(n)
    a = pose[2] + LASER[2] + angles
    dx, dy = np.cos(a), np.sin(a)
    with np.errstate(divide="ignore"):  # a beam along an axis never meets the other walls
        tx = np.where(dx > 0, (W - lx) / dx, np.where(dx < 0, (-W - lx) / dx, np.inf))
        ty = np.where(dy > 0, (H - ly) / dy, np.where(dy < 0, (-H - ly) / dy, np.inf))
    return np.minimum(tx, ty), angles


def reference_score(maps, p, pose, ranges, angles, kernel=1, sigma=0.05, lsigma=0.075, reach=0.0):
    """gmapping's ``score`` and ``likelihoodAndScore``, beam by beam, cell by cell, as it runs:
    the nearest cell with a hit in the kernel (see fleetsim.slam.scan_match on the free cell);
    ``reach`` > 0: the continuous score (each beam's distance capped at reach, found or not)."""
    ox, oy, delta = maps.geom
    dense = np.zeros((*maps.shape_cells, 3))
    for ty in range(maps.table.shape[1]):
        for tx in range(maps.table.shape[2]):
            t = maps.table[p, ty, tx]
            if t >= 0:
                dense[ty * 16 : ty * 16 + 16, tx * 16 : tx * 16 + 16] = maps.pool[t]
    c, s = math.cos(pose[2]), math.sin(pose[2])
    lx = pose[0] + c * LASER[0] - s * LASER[1]
    ly = pose[1] + s * LASER[0] + c * LASER[1]
    score = like = 0.0
    for r, ang in zip(ranges, angles):
        a = pose[2] + LASER[2] + ang
        hx, hy = lx + r * math.cos(a), ly + r * math.sin(a)
        ih = (math.floor((hx - ox) / delta), math.floor((hy - oy) / delta))
        best = None
        for xx in range(-kernel, kernel + 1):
            for yy in range(-kernel, kernel + 1):
                cx, cy = ih[0] + xx, ih[1] + yy
                n, mx, my = dense[cy, cx]  # hit count, mean hit position (m)
                if n <= 0:  # gmapping's free cell lies half a map away: never hit
                    continue
                mu = (hx - mx, hy - my)
                d2 = mu[0] ** 2 + mu[1] ** 2
                best = d2 if best is None else min(best, d2)
        if reach > 0:
            score += math.exp(-min(reach**2 if best is None else best, reach**2) / sigma)
        elif best is not None:
            score += math.exp(-best / sigma)
        like += -best / lsigma if best is not None else -0.5 / lsigma
    return score, like


@settings(max_examples=20, deadline=None, phases=[Phase.explicit, Phase.generate])
@given(
    st.floats(-0.3, 0.3),
    st.floats(-0.3, 0.3),
    st.floats(-0.2, 0.2),
    st.floats(-0.1, 0.1),
    st.sampled_from([0.0, 0.05]),
)
def test_likelihood_at_the_matched_pose_agrees_with_gmapping_score(x, y, yaw, err, reach):
    maps = room_maps()
    true = np.array([x, y, yaw])
    ranges, angles = scan_from(true)
    start = np.array([[x + err, y - err, yaw + err], [x, y, yaw]])
    # no steps and a huge minimum score: the pose stays, only score and likelihood are computed
    out, scores, likes = matched_poses(
        maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0,
        0.0, 0.0, 0, 1e9, reach,
    )  # fmt: skip
    assert np.array_equal(out, start)
    for p in range(2):
        ref_score, ref_like = reference_score(maps, p, start[p], ranges, angles, reach=reach)
        assert scores[p] == pytest.approx(ref_score, rel=1e-6, abs=1e-6)
        assert likes[p] == pytest.approx(ref_like, rel=1e-6, abs=1e-6)


def test_hill_climbing_recovers_an_offset_pose():
    maps = room_maps(particles=3)
    true = np.array([0.2, -0.1, 0.05])
    ranges, angles = scan_from(true)
    start = true + np.array([[0.08, -0.06, 0.04], [-0.1, 0.05, -0.03], [0.0, 0.0, 0.0]])
    out, scores, likes = matched_poses(
        maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0,
        0.05, 0.05, 5, 0.0,
    )  # fmt: skip
    assert np.abs(out - true).max() < 0.015
    assert scores.min() > 0.9 * len(ranges)  # nearly every beam on a wall
    # a score at or below minimumScore keeps the sampled pose
    out2, *_ = matched_poses(
        maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0,
        0.05, 0.05, 5, 1e9,
    )  # fmt: skip
    assert np.array_equal(out2, start)


def test_the_continuous_climber_ends_between_its_last_steps():
    # the manual's 3 halvings of astep 0.05 leave gmapping on a 6 mrad grid round its start;
    # the continuous score's parabola through the last round's scores gets well within it
    maps = room_maps(particles=3)
    true = np.array([0.2, -0.1, 0.05])
    ranges, angles = scan_from(true)
    start = true + np.array([[0.08, -0.06, 0.04], [-0.1, 0.05, -0.03], [0.0, 0.0, 0.0]])
    err = {}
    for reach in (0.0, 0.05):
        out, *_ = matched_poses(
            maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0,
            0.05, 0.05, 3, 0.0, reach,
        )  # fmt: skip
        err[reach] = np.abs(out - true).max(axis=0)
    assert err[0.0][2] > 0.002  # on gmapping's grid: 2.5 mrad off
    assert err[0.05][2] < 0.0005 and err[0.05][:2].max() < 0.0015


def test_lskip_uses_every_nth_beam():
    maps = room_maps(particles=1)
    ranges, angles = scan_from(np.zeros(3))
    args = (maps.pool, maps.table, np.zeros((1, 3)), LASER, ranges, angles, maps.geom, 1)
    _, s0, _ = matched_poses(*args, 0.05, 0.075, 0, 0.0, 0.0, 0, 1e9)
    _, s2, _ = matched_poses(*args, 0.05, 0.075, 2, 0.0, 0.0, 0, 1e9)
    assert s2[0] == pytest.approx(s0[0] / 3, rel=0.05)


def test_the_continuous_score_has_no_jumps_where_gmappings_has():
    # isolated hits (posts, 60 beams' endpoints) and the pose slid along x in 0.5 mm steps:
    # gmapping's score drops by a found beam's worth (0.82-0.95) wherever a window loses its
    # hit; the continuous one changes by no more than its slope
    rng = np.random.default_rng(0)
    r, a = rng.uniform(1.0, 3.0, 60), rng.uniform(-np.pi, np.pi, 60)
    xs = np.arange(0.0, 0.08, 0.0005)
    maps = CowTiles(len(xs), *GEOM_ARGS)
    cells, hits = endpoint_cells(np.zeros((1, 3)), np.zeros(3), r, a, maps.geom)
    maps.write(add_hits, np.repeat(cells, len(xs), 0), np.repeat(hits, len(xs), 0))
    poses = np.c_[xs, np.zeros_like(xs), np.zeros_like(xs)]
    steps, scores = {}, {}
    for reach in (0.0, 0.05):
        _, scores[reach], _ = matched_poses(
            maps.pool, maps.table, poses, np.zeros(3), r, a, maps.geom, 1, 0.05, 0.075, 0,
            0.0, 0.0, 0, 1e9, reach,
        )  # fmt: skip
        steps[reach] = np.abs(np.diff(scores[reach])).max()
    assert scores[0.0][0] == pytest.approx(60.0) and scores[0.0][-1] < 30.0  # hits lost
    assert steps[0.0] > 0.8
    # no more than the slope allows: 60 beams x d/dd exp(-d^2/sigma) <= 2 reach/sigma, x step
    assert steps[0.05] <= 60 * 2 * 0.05 / 0.05 * 0.0005
    assert np.all(np.diff(scores[0.05]) <= 1e-9)  # and it falls steadily away from the hits


@pytest.mark.parametrize("iterations", [5, 3, 1])
def test_the_fast_matcher_finds_the_exact_matchers_pose(iterations):
    # climb_skip 3: the climber scores every 4th of 360 beams, then Gauss-Newton steps of a
    # point-to-line fit of every beam. 24 particles sampled up to 8 cm and 0.06 rad off; with
    # one halving only, the climber's last step is 2.5 cm / 0.025 rad, and without the fit its
    # pose would stay up to half of that off; the fit (to the walls, not to the cells' mean
    # hits) gets to a fifth of a millimetre of the truth, the exact climber to 2.5 mm
    rng = np.random.default_rng(0)
    maps = room_maps(particles=24)
    true = np.array([0.2, -0.1, 0.05])
    ranges, angles = scan_from(true, n=360)
    start = true + rng.uniform(-1, 1, (24, 3)) * [0.08, 0.08, 0.06]
    args = (maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0)
    steps = (0.05, 0.05, iterations, 0.0, 0.05)
    exact, exact_scores, exact_likes = matched_poses(*args, *steps, 0)
    fast, fast_scores, fast_likes = matched_poses(*args, *steps, 3)
    assert np.abs(fast[:, :2] - exact[:, :2]).max() < 0.003
    assert np.abs(fast[:, 2] - exact[:, 2]).max() < 0.003
    assert np.abs(exact[:, :2] - true[:2]).max() < 0.0025
    assert np.abs(fast[:, :2] - true[:2]).max() < 0.0002
    assert np.abs(fast[:, 2] - true[2]).max() < 0.0002
    # score and likelihood of every beam at the final pose
    assert fast_scores == pytest.approx(exact_scores, rel=0.01)
    assert fast_likes == pytest.approx(exact_likes, abs=0.1)
    for p in (0, 11):
        ref_score, ref_like = reference_score(maps, p, fast[p], ranges, angles, reach=0.05)
        assert fast_scores[p] == pytest.approx(ref_score, rel=1e-6)
        assert fast_likes[p] == pytest.approx(ref_like, rel=1e-6, abs=1e-6)


def test_the_fast_matcher_keeps_the_sampled_pose_below_the_minimum_score():
    maps = room_maps(particles=2)
    ranges, angles = scan_from(np.zeros(3), n=360)
    start = np.array([[0.03, -0.02, 0.01], [0.0, 0.0, 0.0]])
    out, scores, _ = matched_poses(
        maps.pool, maps.table, start, LASER, ranges, angles, maps.geom, 1, 0.05, 0.075, 0,
        0.05, 0.05, 3, 1e9, 0.05, 3,
    )  # fmt: skip
    assert np.array_equal(out, start)
    assert scores.min() > 0.9 * 360  # the score still says how well the scan matched
