"""Footprints: radius polygon, padding, radii, footprint costs."""

import math

import numpy as np
import pytest

from fleetsim.nav.costmap import Costmap2D
from fleetsim.nav.costmap.footprint import (
    footprint_costs,
    footprint_from_param,
    footprint_from_radius,
    footprint_radii,
    outline_points,
    padded_footprint,
)
from fleetsim.nav.errors import CostmapError


def test_radius_footprint_and_padding():
    fp = footprint_from_radius(0.3)
    assert fp.shape == (16, 2)
    inscribed, circumscribed = footprint_radii(fp)
    assert circumscribed == pytest.approx(0.3)
    assert inscribed == pytest.approx(0.3 * math.cos(math.pi / 16))
    sq = footprint_from_param("[[-0.2, -0.1], [-0.2, 0.1], [0.3, 0.1], [0.3, -0.1]]")
    assert padded_footprint(sq, 0.01)[2].tolist() == pytest.approx([0.31, 0.11])
    assert footprint_radii(sq)[0] == pytest.approx(0.1)


def test_bad_footprint():
    with pytest.raises(CostmapError, match="at least 3 \\[x, y\\] points"):
        footprint_from_param([[0, 0], [1, 1]], "local_costmap/footprint")


def test_footprint_costs_outline_only():
    m = Costmap2D(40, 40, 0.05)
    m.costs[20, 20] = 254  # lethal inside the footprint but not on its outline: legal
    m.costs[20, 27] = 200
    outline = outline_points(footprint_from_radius(0.3), 0.05)
    poses = np.array([[1.025, 1.025, 0.0], [1.025, 0.05, 0.0], [0.7, 1.025, 0.0]])
    c = footprint_costs(m.costs, 0.0, 0.0, 0.05, outline, poses)
    assert c[0] == 0.0 or c[0] == 200.0
    assert c[1] == -1.0  # off the map
    m.costs[20, 14] = 254
    c2 = footprint_costs(m.costs, 0.0, 0.0, 0.05, outline, poses[:1])
    assert c2[0] == -1.0
