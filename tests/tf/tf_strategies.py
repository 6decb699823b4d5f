"""Hypothesis strategies shared by the tf tests: unit quaternions, translations, angles."""

from __future__ import annotations

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st

finite = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False, allow_infinity=False)


@st.composite
def unit_quaternions(draw) -> np.ndarray:
    """A unit quaternion (x, y, z, w): four components in [-1, 1], normalised."""
    q = np.array([draw(finite) for _ in range(4)])
    n = np.linalg.norm(q)
    return np.array([0.0, 0.0, 0.0, 1.0]) if n < 1e-3 else q / n


translations = st.lists(
    st.floats(min_value=-100.0, max_value=100.0, allow_nan=False), min_size=3, max_size=3
).map(np.array)

angles = st.floats(min_value=-np.pi, max_value=np.pi, allow_nan=False)

#: Settings for every tf property test: deterministic (derandomised) and quick.
tf_settings = settings(max_examples=60, deadline=None, derandomize=True)
