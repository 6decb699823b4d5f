"""The tuple fast path agrees with the NumPy reference in fleetsim.tf.transforms."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from tf_strategies import tf_settings, translations, unit_quaternions

from fleetsim.tf import fastmath as fm
from fleetsim.tf import transforms as tm


def as7(t, q) -> tuple:
    return (*map(float, t), *map(float, q))


def close7(a, b, atol=1e-9) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    same_q = np.allclose(a[3:], b[3:], atol=atol) or np.allclose(a[3:], -b[3:], atol=atol)
    return bool(np.allclose(a[:3], b[:3], atol=atol) and same_q)


@tf_settings
@given(translations, unit_quaternions(), translations, unit_quaternions())
def test_compose_and_invert_match_numpy(t1, q1, t2, q2):
    assert close7(fm.compose(as7(t1, q1), as7(t2, q2)), as7(*tm.compose_transforms(t1, q1, t2, q2)))
    assert close7(fm.invert(as7(t1, q1)), as7(*tm.inverse_transform(t1, q1)))
    assert close7(fm.compose(fm.invert(as7(t1, q1)), as7(t1, q1)), fm.IDENTITY, atol=1e-8)


@tf_settings
@given(translations, unit_quaternions(), translations, unit_quaternions(), st.floats(0.0, 1.0))
def test_interpolate_is_lerp_plus_slerp(t1, q1, t2, q2, f):
    got = fm.interpolate(as7(t1, q1), as7(t2, q2), f)
    assert np.allclose(got[:3], t1 + f * (t2 - t1), atol=1e-9)
    assert close7((0, 0, 0, *got[3:]), (0, 0, 0, *tm.slerp(q1, q2, f)), atol=1e-9)
    assert abs(np.linalg.norm(got[3:]) - 1.0) < 1e-12


def test_interpolate_endpoints_and_nearly_equal_rotations():
    a = as7([0, 0, 0], tm.quaternion_from_yaw(0.5))
    b = as7([2, 0, 0], tm.quaternion_from_yaw(0.5 + 1e-12))
    mid = fm.interpolate(a, b, 0.5)
    assert mid[0] == 1.0 and np.all(np.isfinite(mid))
    assert close7(fm.interpolate(a, b, 0.0), a) and close7(fm.interpolate(a, b, 1.0), b)


@tf_settings
@given(translations, unit_quaternions())
def test_matrix_rows_match_numpy(t, q):
    assert np.allclose(np.array(fm.matrix_rows(as7(t, q))), tm.matrix_from_transform(t, q))
