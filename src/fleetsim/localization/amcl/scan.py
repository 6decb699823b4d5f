"""Scan conditioning for amcl (amcl_node's ``laserReceived``), before any laser model.

``laser_max_range`` / ``laser_min_range`` tighten the scan's own limits; readings at or below
the minimum become max-range readings (amcl has no min-range concept); NaN readings are dropped;
+inf readings are max-range readings (REP 117), which the likelihood models ignore and the beam
model scores as z_max. ``laser_max_beams`` picks evenly spaced beams as amcl does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .grid_map import LocalizationError


@dataclass(frozen=True)
class ScanBeams:
    """The beams of one scan that take part in an update.

    Attributes
    ----------
    ranges : (B,) float64
        Measured ranges, m, finite and within ``(0, range_max]``.
    bearings : (B,) float64
        Beam angles in the laser frame, rad.
    range_max : float
        Effective maximum range, m.
    """

    ranges: np.ndarray
    bearings: np.ndarray
    range_max: float


def scan_beam_indices(count: int, max_beams: int, model: str) -> np.ndarray:
    """Indices of the beams amcl uses out of ``count`` (``laser_max_beams`` subsampling).

    ``likelihood_field`` and ``beam`` step by ``(count - 1) // (max_beams - 1)``;
    ``likelihood_field_prob`` by ``ceil(count / max_beams)``; the step is at least 1.
    """
    if count <= 0:
        return np.zeros(0, dtype=np.int64)
    if model == "likelihood_field_prob":
        step = math.ceil(count / max_beams)
    else:
        step = (count - 1) // max(max_beams - 1, 1)
    return np.arange(0, count, max(step, 1), dtype=np.int64)


def beams_from_scan(
    ranges: np.ndarray,
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    max_beams: int,
    model: str,
    laser_min_range: float | None = None,
    laser_max_range: float | None = None,
) -> ScanBeams:
    """Condition a ``sensor_msgs/LaserScan`` into the beams used by ``model``.

    Parameters
    ----------
    ranges : (N,) float
        Scan ranges, m (NaN and +/-inf allowed).
    angle_min, angle_increment : float
        Scan geometry, rad.
    range_min, range_max : float
        The scan's limits, m.
    max_beams, model, laser_min_range, laser_max_range
        amcl parameters of the same names (None: use the scan's limit).
    """
    r = np.asarray(ranges, dtype=np.float64).ravel()
    rmax = float(range_max)
    if laser_max_range is not None and laser_max_range > 0:
        rmax = min(rmax, float(laser_max_range))
    rmin = float(range_min)
    if laser_min_range is not None and laser_min_range > 0:
        rmin = max(rmin, float(laser_min_range))
    if not (np.isfinite(rmax) and rmax > 0):
        raise LocalizationError(
            f"amcl: scan range_max {range_max!r} (laser_max_range {laser_max_range!r}) "
            "must be a positive finite number"
        )
    idx = scan_beam_indices(len(r), max_beams, model)
    sel = r[idx]
    bearings = angle_min + idx * float(angle_increment)
    sel = np.where(sel <= rmin, rmax, sel)  # amcl maps short readings to max range
    keep = ~np.isnan(sel)
    sel = np.minimum(sel[keep], rmax)  # +inf -> max range
    bearings = bearings[keep]
    if model != "beam":  # the likelihood models ignore max-range readings
        hit = sel < rmax
        sel, bearings = sel[hit], bearings[hit]
    return ScanBeams(np.ascontiguousarray(sel), np.ascontiguousarray(bearings), rmax)
