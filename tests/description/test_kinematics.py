"""Property tests of the joint-transform kernel against homogeneous matrices."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.description.kinematics import (
    FIXED,
    PRISMATIC,
    REVOLUTE,
    child_transforms_from_joint_positions,
)
from fleetsim.tf.quaternions import matrix_from_quaternion, quaternion_from_euler

angles = st.floats(-np.pi, np.pi)
coords = st.floats(-2, 2)


def rodrigues(axis, angle):
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


@settings(max_examples=60, deadline=None)
@given(
    st.tuples(coords, coords, coords),
    st.tuples(angles, angles, angles),
    st.tuples(coords, coords, coords).filter(lambda a: np.linalg.norm(a) > 0.1),
    st.sampled_from([FIXED, REVOLUTE, PRISMATIC]),
    st.floats(-3, 3),
)
def test_matches_matrix_composition(xyz, rpy, axis, kind, q):
    axis = np.array(axis) / np.linalg.norm(axis)
    oq = quaternion_from_euler(*rpy)
    trans, rot = child_transforms_from_joint_positions(
        np.array([xyz]), oq[None], axis[None], np.array([kind], dtype=np.int8), np.array([q])
    )
    r0 = matrix_from_quaternion(oq)
    motion_r = rodrigues(axis, q) if kind == REVOLUTE else np.eye(3)
    motion_t = axis * q if kind == PRISMATIC else np.zeros(3)
    np.testing.assert_allclose(trans[0], np.array(xyz) + r0 @ motion_t, atol=1e-9)
    np.testing.assert_allclose(matrix_from_quaternion(rot[0]), r0 @ motion_r, atol=1e-9)
