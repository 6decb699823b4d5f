"""Rotation math checked against scipy.spatial.transform.Rotation and algebraic identities."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp
from tf_strategies import angles, tf_settings, unit_quaternions

from fleetsim.tf import quaternions as qm


def same_rotation(q1, q2, atol=1e-9) -> bool:
    return bool(np.allclose(q1, q2, atol=atol) or np.allclose(q1, -np.asarray(q2), atol=atol))


def test_quaternion_from_euler_matches_tf_transformations_values():
    # tf.transformations.quaternion_from_euler(0.1, 0.2, 0.3) (static axes 'sxyz')
    expected = [0.0342708, 0.10602051, 0.14357218, 0.98334744]
    assert np.allclose(qm.quaternion_from_euler(0.1, 0.2, 0.3), expected, atol=1e-8)
    assert np.allclose(qm.quaternion_from_yaw(np.pi / 2), [0, 0, np.sqrt(0.5), np.sqrt(0.5)])


@tf_settings
@given(angles, st.floats(-1.5, 1.5), angles)
def test_quaternion_from_euler_agrees_with_scipy_extrinsic_xyz(roll, pitch, yaw):
    ours = qm.quaternion_from_euler(roll, pitch, yaw)
    ref = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_quat()
    assert same_rotation(ours, ref)


@tf_settings
@given(angles, st.floats(-1.5, 1.5), angles)
def test_euler_round_trip(roll, pitch, yaw):
    r, p, y = qm.euler_from_quaternion(qm.quaternion_from_euler(roll, pitch, yaw))
    assert np.allclose([r, p, y], [roll, pitch, yaw], atol=1e-9) or same_rotation(
        qm.quaternion_from_euler(r, p, y), qm.quaternion_from_euler(roll, pitch, yaw)
    )  # +-pi are the same angle


@tf_settings
@given(unit_quaternions())
def test_euler_from_quaternion_reconstructs_the_rotation_even_in_gimbal_lock(q):
    assert same_rotation(qm.quaternion_from_euler(*qm.euler_from_quaternion(q)), q, atol=1e-7)
    locked = qm.quaternion_from_euler(0.3, np.pi / 2, 0.2)
    r, p, y = qm.euler_from_quaternion(locked)
    assert y == 0.0 and p == pytest.approx(np.pi / 2)
    assert same_rotation(qm.quaternion_from_euler(r, p, y), locked, atol=1e-7)


@tf_settings
@given(unit_quaternions())
def test_yaw_and_matrix_agree_with_scipy(q):
    rot = Rotation.from_quat(q)
    assert np.allclose(qm.matrix_from_quaternion(q), rot.as_matrix(), atol=1e-12)
    heading = np.arctan2(rot.as_matrix()[1, 0], rot.as_matrix()[0, 0])
    assert qm.yaw_from_quaternion(q) == pytest.approx(heading, abs=1e-9)
    r, p, y = qm.euler_from_quaternion(q)
    if abs(p) < 1.5:  # away from gimbal lock the decomposition is unique
        assert np.allclose(np.cos([r, p, y] - rot.as_euler("xyz")), 1.0, atol=1e-9)


@tf_settings
@given(unit_quaternions(), unit_quaternions(), st.lists(st.floats(-5, 5), min_size=3, max_size=3))
def test_multiply_rotate_inverse_agree_with_scipy(q1, q0, v):
    prod = qm.quaternion_multiply(q1, q0)
    ref = (Rotation.from_quat(q1) * Rotation.from_quat(q0)).as_quat()
    assert same_rotation(prod, ref)
    assert np.allclose(qm.rotate_vector(q1, v), Rotation.from_quat(q1).apply(v), atol=1e-9)
    assert same_rotation(qm.quaternion_multiply(q1, qm.quaternion_inverse(q1)), [0, 0, 0, 1])
    assert np.allclose(qm.quaternion_conjugate(q1), qm.quaternion_inverse(q1), atol=1e-12)


def test_quaternion_inverse_of_a_scaled_quaternion_is_the_multiplicative_inverse():
    q = np.array([0.0, 0.0, 2.0, 0.0])
    assert np.allclose(qm.quaternion_multiply(q, qm.quaternion_inverse(q)), [0, 0, 0, 1])


@tf_settings
@given(unit_quaternions())
def test_quaternion_from_matrix_round_trip_and_w_non_negative(q):
    back = qm.quaternion_from_matrix(qm.matrix_from_quaternion(q))
    assert back[3] >= 0.0
    assert same_rotation(back, q, atol=1e-9)


def test_quaternion_from_matrix_handles_half_turns_about_each_axis():
    for axis in np.eye(3):
        q = np.append(axis, 0.0)
        assert same_rotation(qm.quaternion_from_matrix(qm.matrix_from_quaternion(q)), q)


@tf_settings
@given(unit_quaternions(), unit_quaternions(), st.floats(0.0, 1.0))
def test_slerp_agrees_with_scipy_and_stays_unit(q0, q1, t):
    ours = qm.slerp(q0, q1, t)
    assert np.linalg.norm(ours) == pytest.approx(1.0, abs=1e-12)
    ref = Slerp([0.0, 1.0], Rotation.from_quat([q0, q1]))([t]).as_quat()[0]
    assert same_rotation(ours, ref, atol=1e-8)


@tf_settings
@given(unit_quaternions(), unit_quaternions())
def test_slerp_endpoints(q0, q1):
    assert np.allclose(qm.slerp(q0, q1, 0.0), q0, atol=1e-12)
    assert same_rotation(qm.slerp(q0, q1, 1.0), q1, atol=1e-12)


def test_slerp_takes_the_short_way_and_handles_parallel_inputs():
    q0 = qm.quaternion_from_yaw(0.1)
    q1 = -qm.quaternion_from_yaw(0.3)  # same rotation as yaw 0.3, opposite hemisphere
    assert qm.yaw_from_quaternion(qm.slerp(q0, q1, 0.5)) == pytest.approx(0.2)
    same = qm.slerp(q0, q0 * (1 + 1e-15), 0.3)
    assert np.all(np.isfinite(same)) and np.allclose(same, q0)
    tiny = qm.slerp(qm.quaternion_from_yaw(0.0), qm.quaternion_from_yaw(1e-9), 0.5)
    assert qm.yaw_from_quaternion(tiny) == pytest.approx(5e-10, rel=1e-6)


def test_batch_versions_match_single_calls():
    rng = np.random.default_rng(3)
    yaws = rng.uniform(-np.pi, np.pi, 7)
    qs = qm.quaternions_from_yaws(yaws)
    assert qs.shape == (7, 4)
    assert np.allclose(qm.yaws_from_quaternions(qs), yaws)
    rpy = rng.uniform(-1.0, 1.0, (2, 5, 3))
    qq = qm.quaternions_from_eulers(rpy)
    assert qq.shape == (2, 5, 4)
    assert np.allclose(qm.eulers_from_quaternions(qq), rpy)
    assert np.allclose(qq[1, 2], qm.quaternion_from_euler(*rpy[1, 2]))
    mats = qm.matrix_from_quaternion(qq)
    assert mats.shape == (2, 5, 3, 3)
    assert same_rotation(qm.quaternion_from_matrix(mats)[1, 3], qq[1, 3])
    ts = np.linspace(0, 1, 5)
    s = qm.slerp(qs[0], qs[1], ts)
    assert s.shape == (5, 4)
    assert np.allclose(s[2], qm.slerp(qs[0], qs[1], 0.5))
    assert np.allclose(qm.quaternion_normalize([[0, 0, 0, 2.0]]), [[0, 0, 0, 1.0]])
    assert np.array_equal(qm.identity_quaternion(), [0, 0, 0, 1])
