"""Tests for fleetsim.localization.amcl.scan: beam subsampling and NaN/inf/short readings."""

import numpy as np
import pytest

from fleetsim.localization.amcl.grid_map import LocalizationError
from fleetsim.localization.amcl.scan import beams_from_scan, scan_beam_indices


def test_beam_subsampling_follows_amcl():
    # likelihood_field / beam: step (n - 1) // (max_beams - 1)
    assert list(scan_beam_indices(360, 30, "likelihood_field")[:3]) == [0, 12, 24]
    assert len(scan_beam_indices(360, 30, "beam")) == 30
    # likelihood_field_prob: step ceil(n / max_beams)
    assert list(scan_beam_indices(360, 30, "likelihood_field_prob")[:3]) == [0, 12, 24]
    assert len(scan_beam_indices(100, 30, "likelihood_field_prob")) == 25
    # fewer readings than beams: every reading
    assert list(scan_beam_indices(5, 30, "likelihood_field")) == [0, 1, 2, 3, 4]


def test_scan_conditioning_nan_inf_and_short_readings():
    r = np.array([1.0, np.nan, np.inf, 0.01, 12.0, 2.0, -np.inf])
    lf = beams_from_scan(r, -1.0, 0.1, 0.05, 10.0, 30, "likelihood_field")
    assert list(lf.ranges) == [1.0, 2.0]  # NaN dropped; inf, short, >max are max range: ignored
    np.testing.assert_allclose(lf.bearings, [-1.0, -0.5])
    beam = beams_from_scan(r, -1.0, 0.1, 0.05, 10.0, 30, "beam")
    assert list(beam.ranges) == [1.0, 10.0, 10.0, 10.0, 2.0, 10.0]  # NaN dropped only
    tight = beams_from_scan(
        r, -1.0, 0.1, 0.05, 10.0, 30, "beam", laser_min_range=1.5, laser_max_range=5.0
    )
    assert tight.range_max == 5.0 and list(tight.ranges) == [5.0, 5.0, 5.0, 5.0, 2.0, 5.0]
    with pytest.raises(LocalizationError, match="range_max nan"):
        beams_from_scan(r, -1.0, 0.1, 0.05, float("nan"), 30, "beam")
