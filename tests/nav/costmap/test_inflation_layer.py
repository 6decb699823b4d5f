"""Inflation costs: ROS's exponential decay."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.nav.costmap import INSCRIBED_INFLATED_OBSTACLE, LETHAL_OBSTACLE, LayeredCostmap
from fleetsim.nav.costmap.inflation_layer import costs_from_distances


def test_cost_formula():
    c = costs_from_distances(np.array([0.0, 2.0, 5.0, 12.0]), 0.05, 0.1, 0.55, 10.0)
    assert c[0] == LETHAL_OBSTACLE and c[1] == INSCRIBED_INFLATED_OBSTACLE
    assert c[2] == int(252 * math.exp(-10.0 * (0.25 - 0.1)))
    assert c[3] == 0  # beyond ceil(0.55 / 0.05) = 11 cells


@settings(max_examples=40, deadline=None)
@given(r=st.floats(0.0, 1.0), f=st.floats(0.1, 30.0), d=st.lists(st.floats(0, 30), min_size=2))
def test_costs_never_increase_with_distance(r, f, d):
    d = np.sort(np.array(d))
    c = costs_from_distances(d, 0.05, 0.1, r, f).astype(int)
    assert (np.diff(c) <= 0).all()


def test_layer_inflates_around_a_lethal_cell():
    lc = LayeredCostmap.from_params(
        {
            "static_map": False,
            "width": 3.0,
            "height": 3.0,
            "robot_radius": 0.2,
            "footprint_padding": 0.0,
            "observation_sources": "s",
            "s": {"marking": True},
        },
        "c",
    )
    lc.add_observation("s", [0.1, 0.1, 0.0], [[1.52, 1.52, 0.1]])
    lc.update_map(0.1, 0.1, 0.0)
    m = lc.costmap
    assert m.costs[30, 30] == LETHAL_OBSTACLE
    assert lc.inscribed_radius == pytest.approx(0.2 * math.cos(math.pi / 16))
    assert m.costs[30, 33] == INSCRIBED_INFLATED_OBSTACLE
    d = 5 * 0.05
    assert m.costs[30, 35] == int(252 * math.exp(-10 * (d - lc.inscribed_radius)))
    assert m.costs[30, 43] == 0
