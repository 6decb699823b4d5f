"""Costmap2D geometry and rolling window."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.nav.costmap import Costmap2D
from fleetsim.nav.errors import CostmapError


def test_world_map_round_trip_and_bounds():
    m = Costmap2D(10, 5, 0.5, -1.0, 2.0)
    assert m.world_to_map(-1.0, 2.0) == (0, 0)
    assert m.world_to_map(3.99, 4.49) == (9, 4)
    assert m.world_to_map(4.0, 3.0) is None
    assert m.world_to_map(-1.01, 3.0) is None
    assert m.map_to_world(3, 2) == (0.75, 3.25)
    assert m.cell_distance(1.2) == 3


@settings(max_examples=60, deadline=None)
@given(
    dx=st.floats(-3, 3),
    dy=st.floats(-3, 3),
    seed=st.integers(0, 2**16),
)
def test_rolling_window_keeps_overlapping_cells(dx, dy, seed):
    rng = np.random.default_rng(seed)
    m = Costmap2D(20, 16, 0.1, 5.0, 5.0, default_value=255)
    m.costs[:] = rng.integers(0, 254, m.costs.shape)
    before = m.copy()
    m.update_origin(5.0 + dx, 5.0 + dy)
    # origin moved by a whole number of cells
    assert (m.origin_x - 5.0) / 0.1 == pytest.approx(round((m.origin_x - 5.0) / 0.1))
    for my in range(m.size_y):
        for mx in range(m.size_x):
            old = before.world_to_map(*m.map_to_world(mx, my))
            expect = 255 if old is None else before.costs[old[1], old[0]]
            assert m.costs[my, mx] == expect


def test_bad_resolution():
    with pytest.raises(CostmapError, match="resolution must be > 0"):
        Costmap2D(3, 3, 0.0)
