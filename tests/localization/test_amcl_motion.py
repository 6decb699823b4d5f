"""Tests for fleetsim.localization.amcl.motion: the four odometry models."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.errors import ParameterError
from fleetsim.localization.amcl.motion import (
    angle_diff,
    odometry_delta,
    particles_after_odometry,
    wrapped_angles,
)

MODELS = ("diff", "omni", "diff-corrected", "omni-corrected")
angles = st.floats(-np.pi, np.pi)
coords = st.floats(-20, 20)


def relative(pose, ref):
    """Pose of ``pose`` in the frame of ``ref``."""
    c, s = np.cos(ref[2]), np.sin(ref[2])
    d = pose[:2] - ref[:2]
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], angle_diff(pose[2], ref[2])])


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    st.sampled_from(MODELS),
    st.tuples(coords, coords, angles),
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), angles),
    st.tuples(coords, coords, angles),
)
def test_noise_free_step_is_the_odometry_step_in_each_particle_frame(model, old, step, particle):
    """With zero alphas every particle moves by the odometry step expressed in its own frame."""
    old = np.array(old)
    step = np.array(step)
    if model.startswith("diff"):
        step[1] = 0.0  # a differential drive cannot strafe
    c, s = np.cos(old[2]), np.sin(old[2])
    new = old + np.array([c * step[0] - s * step[1], s * step[0] + c * step[1], step[2]])
    p = np.array([particle])
    out = particles_after_odometry(p, old, new, model, (0.0,) * 5, np.random.default_rng(0))
    rel = relative(out[0], p[0])
    if model.startswith("diff") and np.hypot(step[0], step[1]) < 0.01:
        # amcl drops the initial rotation for tiny translations; the heading still matches
        assert rel[2] == pytest.approx(wrapped_angles(step[2]), abs=1e-9)
        return
    np.testing.assert_allclose(rel[:2], step[:2], atol=1e-9)
    assert abs(angle_diff(rel[2], step[2])) < 1e-9


@pytest.mark.parametrize("model", MODELS)
def test_noise_is_unbiased_and_grows_with_alphas(model):
    rng = np.random.default_rng(3)
    p = np.zeros((20000, 3))
    new = np.array([0.5, 0.0, 0.2])
    small = particles_after_odometry(p, np.zeros(3), new, model, (0.01,) * 5, rng)
    big = particles_after_odometry(p, np.zeros(3), new, model, (0.2,) * 5, rng)
    noise_free = particles_after_odometry(p[:1], np.zeros(3), new, model, (0,) * 5, rng)[0]
    np.testing.assert_allclose(small.mean(axis=0), noise_free, atol=0.01)
    assert np.all(big.std(axis=0) > small.std(axis=0))


def test_corrected_models_use_sqrt_of_variance():
    rng = np.random.default_rng(4)
    p = np.zeros((40000, 3))
    new = np.array([1.0, 0.0, 0.0])
    a = (0.0, 0.0, 0.04, 0.0, 0.0)  # translation noise only: alpha3 * trans^2 = 0.04
    sd_plain = particles_after_odometry(p, np.zeros(3), new, "diff", a, rng)[:, 0].std()
    sd_corr = particles_after_odometry(p, np.zeros(3), new, "diff-corrected", a, rng)[:, 0].std()
    assert sd_plain == pytest.approx(0.04, rel=0.03)
    assert sd_corr == pytest.approx(0.2, rel=0.03)


def test_a_turn_that_moves_the_base_sideways_over_1_cm_spreads_the_cloud_by_its_bearing():
    """amcl's diff model (and Nav2's) takes ``delta_rot1`` as the bearing of the move once it
    is 1 cm or more; a skid steer turning on the spot about a point off its base (the jackal's
    and the pioneer3at's, ~3 cm) moves it sideways, ``delta_rot1`` comes out near 90 deg, and
    ``alpha1 * rot1^2`` and ``alpha4 * (rot1^2 + rot2^2)`` become ~0.5 rad and ~0.9 m of noise
    in one update (docs/multi_robot.md, "Stop 48"). The same turn moving the base less stays
    tight."""
    rng = np.random.default_rng(5)
    p = np.zeros((4000, 3))
    alphas = (0.2, 0.2, 0.2, 0.2, 0.1)  # jackal_navigation's amcl
    spreads = {}
    for side in (0.0085, 0.011):
        out = particles_after_odometry(
            p, np.zeros(3), np.array([0.0, side, 0.2]), "diff", alphas, rng
        )
        spreads[side] = (np.hypot(out[:, 0], out[:, 1]).std(), out[:, 2].std())
    # a4 * rot^2 = 8 mm and a1 * rot^2 = 0.008 rad, both as standard deviations
    assert spreads[0.0085][0] < 0.01 and spreads[0.0085][1] < 0.01
    assert spreads[0.011][0] > 0.4 and spreads[0.011][1] > 0.5


def test_backward_motion_moves_backwards():
    out = particles_after_odometry(
        np.array([[1.0, 1.0, np.pi / 2]]),
        np.zeros(3),
        np.array([-0.5, 0.0, 0.0]),
        "diff",
        (0.0,) * 5,
        np.random.default_rng(0),
    )
    np.testing.assert_allclose(out[0], [1.0, 0.5, np.pi / 2], atol=1e-12)


def test_delta_wraps_yaw():
    d = odometry_delta(np.array([0, 0, 3.1]), np.array([1, 2, -3.1]))
    np.testing.assert_allclose(d, [1, 2, 2 * np.pi - 6.2], atol=1e-12)


def test_unknown_model_raises():
    with pytest.raises(ParameterError, match=r"unknown odom_model_type 'tank'"):
        particles_after_odometry(
            np.zeros((1, 3)), np.zeros(3), np.zeros(3), "tank", (0,) * 5, np.random.default_rng(0)
        )
