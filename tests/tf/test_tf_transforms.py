"""Rigid transforms: group laws, matrices, points and planar poses."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from tf_strategies import angles, tf_settings, translations, unit_quaternions

from fleetsim.tf import transforms as tm


def close_transform(a, b, atol=1e-9) -> bool:
    (ta, qa), (tb, qb) = a, b
    same_q = np.allclose(qa, qb, atol=atol) or np.allclose(qa, -np.asarray(qb), atol=atol)
    return bool(np.allclose(ta, tb, atol=atol) and same_q)


@tf_settings
@given(translations, unit_quaternions())
def test_inverse_composed_with_transform_is_identity(t, q):
    ti, qi = tm.inverse_transform(t, q)
    ident = (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))
    assert close_transform(tm.compose_transforms(ti, qi, t, q), ident, atol=1e-8)
    assert close_transform(tm.compose_transforms(t, q, ti, qi), ident, atol=1e-8)


@tf_settings
@given(translations, unit_quaternions(), translations, unit_quaternions(), translations,
       unit_quaternions())  # fmt: skip
def test_composition_is_associative_and_matches_matrices(t1, q1, t2, q2, t3, q3):
    left = tm.compose_transforms(*tm.compose_transforms(t1, q1, t2, q2), t3, q3)
    right = tm.compose_transforms(t1, q1, *tm.compose_transforms(t2, q2, t3, q3))
    assert close_transform(left, right, atol=1e-8)
    m = tm.matrix_from_transform(t1, q1) @ tm.matrix_from_transform(t2, q2)
    assert close_transform(tm.transform_from_matrix(m), tm.compose_transforms(t1, q1, t2, q2), 1e-8)


@tf_settings
@given(translations, unit_quaternions())
def test_matrix_round_trip_and_point_mapping(t, q):
    m = tm.matrix_from_transform(t, q)
    assert m.shape == (4, 4) and np.allclose(m[3], [0, 0, 0, 1])
    assert close_transform(tm.transform_from_matrix(m), (t, q))
    pts = np.random.default_rng(0).normal(size=(6, 3))
    mapped = tm.transform_points(t, q, pts)
    homog = (m @ np.c_[pts, np.ones(6)].T).T[:, :3]
    assert np.allclose(mapped, homog, atol=1e-9)
    ti, qi = tm.inverse_transform(t, q)
    assert np.allclose(tm.transform_points(ti, qi, mapped), pts, atol=1e-8)


def test_transform_points_maps_child_points_into_the_parent():
    # laser 0.1 m ahead of base_link, base_link at (1, 2) facing +y
    t, q = tm.compose_transforms(*tm.transform_from_pose2d(1.0, 2.0, np.pi / 2), [0.1, 0, 0],
                                [0, 0, 0, 1])  # fmt: skip
    assert np.allclose(tm.transform_points(t, q, [[1.0, 0.0, 0.0]]), [[1.0, 3.1, 0.0]])
    assert np.allclose(tm.transform_points(t, q, np.array([[1.0, 0.0]])), [[1.0, 3.1]])
    with pytest.raises(ValueError, match=r"shape \(N, 2\) or \(N, 3\)"):
        tm.transform_points(t, q, np.zeros((2, 4)))


@tf_settings
@given(st.floats(-50, 50), st.floats(-50, 50), angles)
def test_pose2d_round_trip(x, y, theta):
    t, q = tm.transform_from_pose2d(x, y, theta)
    px, py, pth = tm.pose2d_from_transform(t, q)
    assert (px, py) == pytest.approx((x, y))
    assert np.cos(pth - theta) == pytest.approx(1.0)


def test_batch_pose2d_and_broadcasting():
    poses = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, np.pi / 2], [-1.0, 0.5, -np.pi / 4]])
    t, q = tm.transforms_from_poses2d(poses)
    assert t.shape == (3, 3) and q.shape == (3, 4)
    assert np.allclose(tm.poses2d_from_transforms(t, q), poses)
    # compose one transform with a batch of three (leading dimensions broadcast)
    tc, qc = tm.compose_transforms(t[1], q[1], t, q)
    assert tc.shape == (3, 3) and qc.shape == (3, 4)
    for i in range(3):
        assert close_transform((tc[i], qc[i]), tm.compose_transforms(t[1], q[1], t[i], q[i]))
    mats = tm.matrix_from_transform(t, q)
    assert mats.shape == (3, 4, 4)
    assert np.allclose(tm.transform_from_matrix(mats)[0], t)


def test_reexports_rotation_functions_like_tf_transformations():
    assert tm.quaternion_from_euler is not None and "slerp" in tm.__all__
    assert np.allclose(tm.euler_from_quaternion(tm.quaternion_from_euler(0.1, 0.2, 0.3)),
                       (0.1, 0.2, 0.3))  # fmt: skip


xy = st.floats(-50, 50)


@tf_settings
@given(st.tuples(xy, xy, angles), st.tuples(xy, xy, angles))
def test_planar_pose_composition_matches_the_3d_transforms(a, b):
    c = tm.compose_pose2d(a, b)
    t, q = tm.compose_transforms(*tm.transform_from_pose2d(*a), *tm.transform_from_pose2d(*b))
    np.testing.assert_allclose(c[:2], t[:2], atol=1e-9)
    assert np.cos(c[2] - tm.pose2d_from_transform(t, q)[2]) == pytest.approx(1.0)
    np.testing.assert_allclose(tm.compose_pose2d(a, tm.inverse_pose2d(a)), 0.0, atol=1e-9)
