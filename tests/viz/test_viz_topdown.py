"""TopDownFigure: pixel geometry, occupancy greys and bad extents."""

from __future__ import annotations

import numpy as np
import pytest

from fleetsim.errors import FleetsimError
from fleetsim.viz.scene_state import Snapshot
from fleetsim.viz.topdown import UNKNOWN_GREY, TopDownFigure, grey_from_occupancy


def test_greys():
    np.testing.assert_allclose(
        grey_from_occupancy(np.array([-1, 0, 50, 100])), [UNKNOWN_GREY, 1, 0.5, 0]
    )


def test_geometry_and_empty_frame():
    fig = TopDownFigure((-1.0, 3.0, 0.0, 1.0), width=401)
    assert (fig.width, fig.height) == (400, 100)
    assert fig.world_to_pixel(-1.0, 1.0) == (0, 0)
    assert fig.world_to_pixel(1.0, 0.5) == (200, 50)
    frame = fig.draw(Snapshot(2.5))
    assert frame.shape == (100, 400, 3) and frame.dtype == np.uint8


def test_bad_extent():
    with pytest.raises(FleetsimError, match=r"render extent \(0, 0, 0, 1\) is empty"):
        TopDownFigure((0, 0, 0, 1))
    with pytest.raises(FleetsimError, match="render width must be >= 64 pixels, got 10"):
        TopDownFigure((0, 1, 0, 1), width=10)
