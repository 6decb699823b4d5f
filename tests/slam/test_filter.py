"""Tests for fleetsim.slam.filter, motion and tree: the RBPF off the graph on the synthetic room."""

import numpy as np
import pytest
from slam_world import LASER, ROUTE, drive, exact_ranges

from fleetsim.slam import filter as slam_filter
from fleetsim.slam.filter import Beams, GmappingFilter, systematic_resample
from fleetsim.slam.motion import poses_after_motion
from fleetsim.slam.params import GmappingParams
from fleetsim.slam.quality import ate
from fleetsim.slam.render import cast_counts, occupancy_from_counts
from fleetsim.slam.tiles import COUNT_CELL, TILE, CowTiles

ANGLES = -np.pi + 2 * np.pi / 360 * np.arange(360)
FORWARD = np.linspace(-np.pi / 2, np.pi / 2, 361)  # the hunter's laser: 180 degrees, 10 m
# slam_gmapping's parameters in the manual's nav_stack.launch (what the hunter maps with)
MANUAL = dict(astep=0.03, iterations=3, srt=0.1, stt=0.1, angularUpdate=0.2, particles=20)


def beams_at(true, rng, angles=ANGLES, max_range=12.0):
    c, s = np.cos(true[2]), np.sin(true[2])
    sensor = true + np.array([c * LASER[0], s * LASER[0], 0.0])
    r = exact_ranges(sensor, angles, max_range) + 0.01 * rng.standard_normal(len(angles))
    keep = np.isfinite(r)
    return Beams(r[keep], angles[keep])


def test_motion_noise_follows_gmappings_formula():
    rng = np.random.default_rng(0)
    poses = np.zeros((20000, 3))
    out = poses_after_motion(poses, np.array([1.0, 0.0, 0.5]), np.zeros(3), 0.1, 0.2, 0.1, 0.2, rng)
    assert out.mean(axis=0) == pytest.approx([1.0, 0.0, 0.5], abs=0.01)
    # x: srr|dx| + str|dth| = 0.15; y: str|dth| + 0.3 srr|dx| = 0.08; yaw: stt|dth| + srt*1 = 0.3
    assert out.std(axis=0) == pytest.approx([0.15, 0.08, 0.3], rel=0.05)


def test_systematic_resampling_keeps_heavy_particles():
    rng = np.random.default_rng(1)
    idx = systematic_resample(np.array([0.7, 0.1, 0.1, 0.1, 0.0]), rng)
    assert len(idx) == 5 and 4 not in idx and (idx == 0).sum() in (3, 4)


def test_the_published_map_is_the_best_particles_whole_history_read_out(monkeypatch):
    rng = np.random.default_rng(2)
    # resampling often (so that lineages branch and tiles are shared): a high threshold
    params = GmappingParams(
        particles=10, xmin=-4, ymin=-4, xmax=14, ymax=10, linearUpdate=0.3, angularUpdate=0.3,
        resampleThreshold=0.99,
    )  # fmt: skip
    f = GmappingFilter(params, rng, LASER, 11.99, 11.99)
    # each particle's history of (pose, scan), followed through resampling
    history = [[] for _ in range(params.particles)]
    real = GmappingFilter._resample

    def resample(self, idx):
        history[:] = [list(history[i]) for i in idx]
        real(self, idx)

    monkeypatch.setattr(GmappingFilter, "_resample", resample)
    resampled = 0
    for i, (true, odom) in enumerate(drive(ROUTE, np.random.default_rng(3))):
        beams = beams_at(true, rng)
        result = f.process(odom, 0.1 * i, beams)
        resampled += result.resampled
        if result.updated:
            for p in range(params.particles):
                history[p].append((f.poses[p].copy(), beams))
    assert f.updates > 60 and resampled > 5
    # reading the map out casts nothing: its cost does not grow with the run
    monkeypatch.setattr(slam_filter, "cast_counts", None)
    data, geom = f.occupancy()
    # ... and it is what replaying the best particle's whole history gives (gmapping's map)
    best = f.best_index
    replay = CowTiles(1, *f.counts.bounds[:2], *f.counts.bounds[2:], 0.05, COUNT_CELL)
    for pose, beams in history[best]:
        replay.write(cast_counts, pose[None], LASER, beams.ranges, beams.angles, 11.99, replay.geom)
    counts = replay.dense(0)
    assert np.array_equal(f.counts.dense(best), counts)
    assert np.array_equal(data, occupancy_from_counts(counts[..., 0], counts[..., 1], 0.25))
    assert np.array_equal(geom, replay.geom) and (data == 100).sum() > 500
    # tiles shared, not ten full copies of every grid
    h, w = f.counts.shape_cells
    assert f.counts.tiles_in_use < 0.5 * params.particles * h * w / TILE**2


def test_map_grows_when_the_robot_leaves_it():
    rng = np.random.default_rng(4)
    params = GmappingParams(particles=3, xmin=-1, ymin=-1, xmax=1, ymax=1)
    f = GmappingFilter(params, rng, LASER, 11.99, 11.99)
    true = np.array([1.5, 1.5, 0.0])
    f.process(np.zeros(3), 0.0, beams_at(true, rng))
    x0, y0, x1, y1 = f.maps.bounds
    assert x0 <= -12 - slam_filter.ENLARGE_STEP + 1 and x1 >= 12 + slam_filter.ENLARGE_STEP - 1
    data, geom = f.occupancy()
    assert data.shape == f.counts.shape_cells and tuple(geom[:2]) == (x0, y0)


def test_the_map_grows_by_the_usable_range_not_the_lasers():
    """maxUrange 4 m on a 30 m laser: gmapping enlarges its map for end points clipped to
    the usable range (computeActiveArea), so the map stays within 4 m (+ the enlarge step)
    of the robot; by maxRange it had grown ~30 m each way."""
    rng = np.random.default_rng(4)
    params = GmappingParams(particles=3, xmin=-1, ymin=-1, xmax=1, ymax=1)
    f = GmappingFilter(params, rng, LASER, 29.99, 4.0)
    f.process(np.zeros(3), 0.0, beams_at(np.zeros(3), rng, max_range=29.99))
    x0, y0, x1, y1 = f.maps.bounds
    reach = 4.0 + abs(LASER[0]) + slam_filter.ENLARGE_STEP
    assert -reach - 1.0 <= x0 <= -4.0 and 4.0 <= x1 <= reach + 1.0
    assert -reach - 1.0 <= y0 <= -4.0 and 4.0 <= y1 <= reach + 1.0


def test_a_forward_laser_does_not_drift_while_the_robot_turns():
    # the hunter's 180-degree laser on a robot driving small squares (turning on the spot at
    # each corner, as an exploring robot does): every match used to pull the pose a few mm
    # away from what the laser sees, which a 360-degree laser cancels and a forward one adds
    # up (ATE 0.14-0.25 m here, 1 m over the office) -- see scan_match's module docstring
    rng = np.random.default_rng(5)
    params = GmappingParams(xmin=-5, ymin=-5, xmax=15, ymax=12, **MANUAL)
    f = GmappingFilter(params, rng, LASER, 9.99, 9.99)
    square = np.array([[6.0, 3.5], [6.5, 3.5], [6.5, 4.0], [6.0, 4.0]] * 5 + [[6.0, 3.5]])
    est, true_xy = [], []
    for i, (true, odom) in enumerate(drive(square, np.random.default_rng(6))):
        result = f.process(odom, 0.1 * i, beams_at(true, rng, FORWARD, 10.0))
        if result.updated:
            est.append(f.best_pose[:2] + square[0])  # the map frame starts at the first pose
            true_xy.append(true[:2])
    est, true_xy = np.array(est), np.array(true_xy)
    assert f.updates > 100
    assert np.hypot(*(est - true_xy).T).max() < 0.1
    assert ate(est, true_xy) < 0.04


def test_the_continuous_score_keeps_a_forward_laser_on_its_route():
    # the room's route twice with drifting odometry, the hunter's 180-degree laser and the
    # manual's parameters: gmapping's score (a count of the beams that find a hit, jumping at
    # cell edges) leaves every match a little off and the errors add up; the continuous score
    # with the climber's sub-step refinement stays within a few cm (see scan_match)
    route = np.asarray(ROUTE, float)
    route = np.concatenate([route, route[1:]])
    worst = {}
    for continuous in (False, True):
        rng = np.random.default_rng(5)
        params = GmappingParams(
            xmin=-5, ymin=-5, xmax=15, ymax=12, continuous_score=continuous,
            **{**MANUAL, "particles": 10},
        )  # fmt: skip
        f = GmappingFilter(params, rng, LASER, 9.99, 9.99)
        est, true_xy = [], []
        for i, (true, odom) in enumerate(drive(route, np.random.default_rng(6))):
            if f.process(odom, 0.1 * i, beams_at(true, rng, FORWARD, 10.0)).updated:
                est.append(f.best_pose[:2] + route[0])  # the map frame starts at the first pose
                true_xy.append(true[:2])
        est, true_xy = np.array(est), np.array(true_xy)
        worst[continuous] = np.hypot(*(est - true_xy).T).max()
        if continuous:
            assert f.updates > 150 and ate(est, true_xy) < 0.02
    assert worst[True] < 0.05 and worst[False] > 2 * worst[True], worst
