"""amcl's "must show" scenarios on the Willow Garage map, with the MuJoCo simulator.

lizi drives `amcl_harness.ROUTE` (62.7 m) with pure pursuit on ground truth; amcl localizes
it from the simulator's wheel-encoder odometry and laser. Errors are measured at every
``amcl_pose`` against ``base_pose_ground_truth`` interpolated at the pose's stamp.

amcl parameters (`TRACKING`): the simulator's skid steer reports several times the true
rotation when turning (wheel scrub), so rotation noise is large (``diff-corrected``,
``odom_alpha1`` 2: a standard deviation of 1.4 x the odometric rotation) and the filter updates
every 0.1 m / 0.1 rad. With amcl's ad-hoc ``likelihood_field`` (1 + sum pz^3) the laser pulls the
heading back too weakly: the estimate lags the truth by ~1.5 s x the turn rate (mean heading
error 0.11-0.14 rad); ``likelihood_field_prob`` (the product over 60 beams) keeps it within
0.01 rad.

Convergence, for the tracking criterion: errors are averaged over the poses after the first
5 m of travel.
"""

import numpy as np
import pytest
from amcl_harness import ROUTE, route_length, start_pose, willow_amcl_run, wrapped

pytestmark = pytest.mark.scenario

TRACKING = {
    "laser_model_type": "likelihood_field_prob",
    "laser_max_beams": 60,
    "odom_model_type": "diff-corrected",
    "odom_alpha1": 2.0,
    "odom_alpha2": 0.05,
    "odom_alpha3": 0.02,
    "odom_alpha4": 0.02,
    "update_min_d": 0.1,
    "update_min_a": 0.1,
    "resample_interval": 1,
}


def test_route_is_long_and_clear_of_walls():
    from amcl_harness import WILLOW, dense_route
    from scipy import ndimage

    from fleetsim.sim.mapworld import load_map

    grid = load_map(WILLOW)
    clearance = ndimage.distance_transform_edt(~grid.occupied) * grid.resolution
    pts = dense_route(ROUTE, 0.02)
    cols = ((pts[:, 0] - grid.origin[0]) / grid.resolution).astype(int)
    rows = ((pts[:, 1] - grid.origin[1]) / grid.resolution).astype(int)
    assert route_length(ROUTE) >= 60.0
    assert clearance[rows, cols].min() >= 0.5


def test_tracking_along_the_willow_route():
    run = willow_amcl_run(seed=1, amcl_params=TRACKING)
    run.drive(max_sim_time=300.0)
    assert run.follower.done and run.follower.travelled >= 60.0
    err = run.log.errors()
    after = err["dist"] > 5.0
    assert after.sum() >= 300
    assert err["pos"][after].mean() <= 0.10, err["pos"][after].mean()
    assert err["yaw"][after].mean() <= 0.05, err["yaw"][after].mean()
    assert err["pos"][after].max() < 0.5  # never lost on the way


def test_global_localization_converges_within_30_m():
    params = dict(
        TRACKING,
        max_particles=20000,
        min_particles=500,
        laser_z_hit=0.8,
        laser_z_rand=0.2,
        recovery_alpha_slow=0.001,
        recovery_alpha_fast=0.1,
    )
    run = willow_amcl_run(seed=2, amcl_params=params, initial_guess=(20.0, 40.0, 0.0))
    run.rt.run(duration=0.5)
    run.global_localization()
    assert run.amcl.filter.particle_count == 20000
    spread = run.amcl.filter.particles[:, :2].std(axis=0)
    assert spread.min() > 5.0  # particles over the whole free space
    run.drive(max_sim_time=120.0, until=lambda: run.follower.travelled >= 30.0)
    truth, est = run.truth(), run.estimate()
    assert np.hypot(*(truth[:2] - est[:2])) < 0.3
    assert abs(wrapped(truth[2] - est[2])) < 0.1
    assert run.amcl.filter.converged


def test_kidnapped_robot_recovers():
    """amcl's random particles (recovery_alpha_*) find a kidnapped lizi again.

    Recovery is a matter of chance: over 18 seeds amcl re-localised the lizi within the 15 m
    left of the route in 10 (implicit integrator) or 13 (implicit-fast), the others converging
    to a wrong, similar-looking spot 6-48 m away (README, known limits). This seed recovers
    with the lasers' per-scan noise streams; it was an expected failure (with a non-strict mark
    that could never fail) under the earlier draws, so a change of any noise stream may flip it:
    then look at whether the failure is that chance or a regression before marking it."""
    params = dict(TRACKING, recovery_alpha_slow=0.001, recovery_alpha_fast=0.1)
    run = willow_amcl_run(seed=3, amcl_params=params)
    run.drive(max_sim_time=60.0, until=lambda: run.follower.travelled >= 8.0)
    before = run.truth()
    assert np.hypot(*(before[:2] - run.estimate()[:2])) < 0.2
    x, y = ROUTE[9]
    heading = np.arctan2(*(ROUTE[10] - ROUTE[9])[::-1])
    assert run.teleport(float(x), float(y), float(heading))
    run.rt.run(duration=1.0)
    moved = run.truth()
    assert np.hypot(moved[0] - x, moved[1] - y) < 1.0  # teleported (and driving on)
    assert np.hypot(*(moved[:2] - run.estimate()[:2])) > 5.0  # amcl still believes the old pose
    kidnapped_at = run.follower.travelled
    run.drive(max_sim_time=120.0, until=lambda: run.follower.travelled >= kidnapped_at + 15.0)
    truth, est = run.truth(), run.estimate()
    assert np.hypot(*(truth[:2] - est[:2])) < 0.3
    assert abs(wrapped(truth[2] - est[2])) < 0.1


def test_start_pose_faces_the_route():
    x, y, yaw = start_pose(ROUTE)
    assert (x, y) == tuple(ROUTE[0])
    d = ROUTE[1] - ROUTE[0]
    assert yaw == pytest.approx(np.arctan2(d[1], d[0]))
