"""Tests for fleetsim.localization.amcl.filter: tracking, global localization, recovery, gating.

All runs use the synthetic world of ``amcl_world`` (exact ray caster, drifting odometry) and
fixed seeds.
"""

import numpy as np
import pytest
from amcl_world import ROUTE, drive, scan, world_map
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.localization.amcl import (
    AmclParams,
    LocalizationError,
    ParticleFilter,
    ScanBeams,
    beams_from_scan,
)

GRID = world_map()


def run(pf, route, seed, kidnap_after=None, kidnap_offset=(0.0, 3.5, 0.0), stop=None):
    """Drive ``route``, feed a scan every 0.1 m to ``pf``; return per-estimate records.

    Each record: (distance travelled m, position error m, |yaw error| rad, particle count).
    """
    rng = np.random.default_rng(seed)
    offset = np.zeros(3)
    travelled, prev, out = 0.0, None, []
    for k, (true, odom) in enumerate(drive(route, rng)):
        if prev is not None:
            travelled += float(np.hypot(*(true[:2] - prev[:2])))
        prev = true
        if kidnap_after is not None and travelled > kidnap_after:
            offset = np.array(kidnap_offset)  # teleported: odometry does not see it
        pose = true + offset
        if k % 2:
            continue
        ranges, amin, inc = scan(pose, 360, 10.0, 0.01, rng)
        p = pf.params
        beams = beams_from_scan(
            ranges, amin, inc, 0.05, 10.0, p.laser_max_beams, p.laser_model_type
        )
        if pf.update(odom, beams).estimate_changed:
            e = pf.estimate.pose
            yaw_err = abs((e[2] - pose[2] + np.pi) % (2 * np.pi) - np.pi)
            out.append(
                (travelled, float(np.hypot(*(e[:2] - pose[:2]))), yaw_err, pf.particle_count)
            )
            if stop is not None and stop(out):
                break
    return np.array(out)


@pytest.mark.parametrize("model", ["likelihood_field", "likelihood_field_prob", "beam"])
def test_tracks_a_moving_pose(model):
    params = AmclParams(
        initial_pose_x=1.5,
        initial_pose_y=5.0,
        max_particles=2000,
        laser_max_beams=60,
        laser_model_type=model,
    )
    pf = ParticleFilter(params, np.random.default_rng(1), GRID)
    rec = run(pf, ROUTE, seed=2)
    assert rec[-1, 0] > 50  # the whole route
    assert rec[:, 1].mean() < 0.10 and rec[:, 1].max() < 0.25
    assert rec[:, 2].mean() < 0.05
    assert rec[-1, 3] < 1000  # KLD keeps few particles once converged (max 2000)


def test_global_localization_converges_and_kld_count_shrinks():
    params = AmclParams(max_particles=20000, laser_max_beams=60, initial_pose_x=1.0)
    pf = ParticleFilter(params, np.random.default_rng(3), GRID)
    pf.global_localization()
    assert pf.particle_count == 20000 and not pf.converged
    free = GRID.occ_state[GRID.cells_from_points(pf.particles[:, :2])[::-1]]
    assert np.all(free == -1)
    rec = run(pf, ROUTE, seed=4, stop=lambda r: r[-1][0] > 25)
    converged_at = rec[np.argmax(rec[:, 1] < 0.2), 0]
    assert converged_at < 15.0
    late = rec[rec[:, 0] > 20]
    assert late[:, 1].max() < 0.25
    assert rec[0, 3] == 20000 and late[:, 3].max() < 2000
    assert pf.converged


def test_kidnapped_robot_recovers_with_recovery_alphas():
    params = AmclParams(
        initial_pose_x=1.5,
        initial_pose_y=5.0,
        max_particles=5000,
        laser_max_beams=60,
        recovery_alpha_slow=0.001,
        recovery_alpha_fast=0.1,
    )
    pf = ParticleFilter(params, np.random.default_rng(0), GRID)
    rec = run(pf, np.vstack([ROUTE, ROUTE, ROUTE]), seed=10, kidnap_after=15.0)
    assert rec[rec[:, 0] < 15, 1].max() < 0.25  # tracking before the kidnap
    assert rec[(rec[:, 0] > 15) & (rec[:, 0] < 17), 1].min() > 2.0  # lost right after it
    assert rec[-20:, 1].max() < 0.3  # and found again


def beams_at(pose, n=60):
    r, amin, inc = scan(np.asarray(pose, float), n, 10.0, 0.0, np.random.default_rng(0))
    return beams_from_scan(r, amin, inc, 0.05, 10.0, n, "likelihood_field")


def test_update_gating_resample_interval_and_nomotion_update():
    params = AmclParams(initial_pose_x=5.0, initial_pose_y=5.0, laser_max_beams=60)
    pf = ParticleFilter(params, np.random.default_rng(0), GRID)
    b = beams_at([5.0, 5.0, 0.0])
    first = pf.update(np.zeros(3), b)
    assert first.updated and not first.resampled and first.estimate_changed
    assert not pf.update(np.array([0.1, 0.1, 0.2]), b).updated  # below update_min_d / _a
    second = pf.update(np.array([0.0, 0.0, 0.6]), b)  # rotation > pi/6
    assert second.updated and second.resampled  # resample_interval 2
    third = pf.update(np.array([0.25, 0.0, 0.6]), b)  # x > update_min_d (per axis)
    assert third.updated and not third.resampled
    pf.request_nomotion_update()
    before = pf.particles.copy()
    forced = pf.update(np.array([0.25, 0.0, 0.6]), b)
    assert forced.updated and forced.resampled
    assert not pf.update(np.array([0.25, 0.0, 0.6]), b).updated  # the request is used up
    assert len(before) >= 1


def test_selective_resampling_keeps_particles_while_neff_is_high():
    params = AmclParams(
        initial_pose_x=5.0,
        initial_pose_y=5.0,
        selective_resampling=True,
        resample_interval=1,
        laser_max_beams=60,
        laser_sigma_hit=50.0,  # nearly flat likelihood: N_eff stays ~N
    )
    pf = ParticleFilter(params, np.random.default_rng(0), GRID)
    before = pf.particles.copy()
    pf.update(np.zeros(3), beams_at([5.0, 5.0, 0.0]))
    assert pf.n_effective > 0.99 * len(before)
    np.testing.assert_array_equal(pf.particles, before)


def test_initial_pose_from_params_and_message():
    params = AmclParams(initial_pose_x=3.0, initial_pose_y=4.0, initial_pose_a=1.0)
    pf = ParticleFilter(params, np.random.default_rng(0), GRID)
    np.testing.assert_allclose(pf.particles.mean(axis=0), [3.0, 4.0, 1.0], atol=0.03)
    np.testing.assert_allclose(np.cov(pf.particles[:, :2].T), np.diag([0.25, 0.25]), atol=0.02)
    cov6 = np.zeros(36)
    cov6[0] = cov6[7] = 0.01
    cov6[35] = 0.001
    pf.set_initial_pose(np.array([10.0, 5.0, -2.0]), cov6)  # as in an initialpose message
    assert pf.particles[:, 0].std() == pytest.approx(0.1, rel=0.1)
    assert pf.odom_pose is None and pf.converged


@pytest.mark.parametrize("pose", [(30.0, 4.0), (3.0, -1.0)])
def test_initial_pose_outside_the_map_raises(pose):
    params = AmclParams(initial_pose_x=pose[0], initial_pose_y=pose[1])
    with pytest.raises(LocalizationError, match=r"initial pose .* is outside the map"):
        ParticleFilter(params, np.random.default_rng(0), GRID)


def test_missing_map_and_bad_inputs_raise_clear_errors():
    pf = ParticleFilter(AmclParams(), np.random.default_rng(0))
    with pytest.raises(LocalizationError, match="no map yet"):
        pf.update(np.zeros(3), beams_at([5.0, 5.0, 0.0]))
    with pytest.raises(LocalizationError, match="no map yet"):
        pf.global_localization()
    pf.set_map(GRID, np.array([5.0, 5.0, 0.0]))
    with pytest.raises(LocalizationError, match="odometry pose .* is not finite"):
        pf.update(np.array([np.nan, 0.0, 0.0]), beams_at([5.0, 5.0, 0.0]))
    with pytest.raises(LocalizationError, match="not positive semi-definite"):
        pf.set_initial_pose(np.array([5.0, 5.0, 0.0]), -np.eye(3))


def test_scan_without_usable_beams_keeps_weights():
    params = AmclParams(initial_pose_x=5.0, initial_pose_y=5.0)
    pf = ParticleFilter(params, np.random.default_rng(0), GRID)
    nan_scan = beams_from_scan(
        np.full(100, np.nan), -np.pi, 0.06, 0.05, 10.0, 30, "likelihood_field"
    )
    assert len(nan_scan.ranges) == 0
    res = pf.update(np.zeros(3), nan_scan)
    assert res.updated and np.allclose(pf.weights, 1.0 / pf.particle_count)
    empty = ScanBeams(np.zeros(0), np.zeros(0), 10.0)
    pf.request_nomotion_update()
    assert pf.update(np.zeros(3), empty).updated


def test_same_seed_same_result():
    def once():
        params = AmclParams(initial_pose_x=1.5, initial_pose_y=5.0, max_particles=1000)
        pf = ParticleFilter(params, np.random.default_rng(7), GRID)
        run(pf, ROUTE[:3], seed=8)
        return pf.particles

    np.testing.assert_array_equal(once(), once())


@given(st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-3, 3)))
@settings(max_examples=40, deadline=None)
def test_needs_update_says_what_update_will_do(odom):
    """The node reads a scan only when needs_update says the filter will use it."""
    params = AmclParams(initial_pose_x=5.0, initial_pose_y=5.0, laser_max_beams=20)
    pf = ParticleFilter(params, np.random.default_rng(0), GRID)
    b = beams_at([5.0, 5.0, 0.0], n=20)
    assert pf.needs_update(np.zeros(3))  # the first scan always
    pf.update(np.zeros(3), b)
    pose = np.array(odom)
    assert pf.needs_update(pose) == pf.update(pose, b).updated
    pf.request_nomotion_update()
    assert pf.needs_update(pf.odom_pose)
