"""gmapping's Rao-Blackwellised particle filter (``GridSlamProcessor::processScan``).

Per scan: every particle moves by a noisy copy of the odometry step; once the robot has
travelled ``linearUpdate`` / turned ``angularUpdate`` / waited ``temporalUpdate`` (or at the
first scan) each particle's pose is refined by hill-climbing scan matching against its own map,
weighted by the scan's likelihood, the particles are resampled when the effective sample size
falls below ``resampleThreshold * particles``, and the scan is added to every particle's map.
Each particle holds two copy-on-write tile grids (`CowTiles`, tiles shared across resampled
particles): the matcher's hit map and the visit/hit counts the published map is read from (see
`render`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .motion import poses_after_motion, relative_pose
from .params import GmappingParams
from .render import cast_counts, occupancy_from_counts
from .scan_match import add_hits, endpoint_cells, matched_poses
from .tiles import COUNT_CELL, HIT_CELL, CowTiles

ENLARGE_STEP = 10.0  # m beyond a scan that leaves the map (gmapping's enlargeStep)


@dataclass(frozen=True)
class Beams:
    """One scan's beams in the laser frame (m, rad): every beam up to maxRange."""

    ranges: np.ndarray  # (B,)
    angles: np.ndarray  # (B,)


@dataclass
class UpdateResult:
    updated: bool = False
    resampled: bool = False
    neff: float = 0.0


def systematic_resample(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """(N,) indices drawn by low-variance resampling of normalised ``weights`` (N,)."""
    n = len(weights)
    cum = np.cumsum(weights)
    cum[-1] = 1.0
    points = (rng.random() + np.arange(n)) / n
    return np.searchsorted(cum, points, side="right").clip(0, n - 1)


class GmappingFilter:
    """The filter of one robot; poses are of the base frame in the map frame."""

    def __init__(
        self,
        params: GmappingParams,
        rng: np.random.Generator,
        laser: np.ndarray,
        max_range: float,
        usable_range: float,
    ) -> None:
        p = params
        self.p = p
        self.rng = rng
        self.laser = np.asarray(laser, dtype=float)
        self.max_range = float(max_range)
        self.usable_range = float(usable_range)
        n = p.particles
        extent = (p.xmin, p.ymin, p.xmax, p.ymax, p.delta)
        self.maps = CowTiles(n, *extent, HIT_CELL)  # what the matcher matches against
        self.counts = CowTiles(n, *extent, COUNT_CELL)  # what the published map shows
        self.poses = np.zeros((n, 3))
        self.weights = np.zeros(n)  # log, since the last resampling
        self.weight_sums = np.zeros(n)  # log, over the whole run (best particle)
        self.last_odom: np.ndarray | None = None
        self.linear = 0.0
        self.angular = 0.0
        self.last_update_time = -math.inf
        self.updates = 0
        self.neff = float(n)
        # the continuous score's cap: the distance the kernel's window always covers
        self.reach = p.kernelSize * p.delta if p.continuous_score else 0.0

    # ----- per scan -----
    def process(self, odom: np.ndarray, stamp: float, beams: Beams) -> UpdateResult:
        """Run the filter on one scan taken at odometry pose ``odom`` (base in odom frame)."""
        p = self.p
        odom = np.asarray(odom, dtype=float)
        if self.last_odom is None:
            self.poses[:] = odom  # gmapping starts the map frame at the first odometry pose
            self.last_odom = odom
        else:
            self.poses = poses_after_motion(
                self.poses, odom, self.last_odom, p.srr, p.srt, p.str, p.stt, self.rng
            )
            d = relative_pose(odom, self.last_odom)
            self.linear += math.hypot(d[0], d[1])
            self.angular += abs(d[2])
            self.last_odom = odom
        first = self.updates == 0
        timed = p.temporalUpdate is not None and stamp - self.last_update_time > p.temporalUpdate
        if not (first or self.linear >= p.linearUpdate or self.angular >= p.angularUpdate or timed):
            return UpdateResult()
        result = UpdateResult(updated=True, neff=self.neff)
        usable = beams.ranges <= self.usable_range
        ranges = np.ascontiguousarray(beams.ranges[usable], dtype=np.float64)
        angles = np.ascontiguousarray(beams.angles[usable], dtype=np.float64)
        self._grow_for(ranges, angles)
        if not first:
            self.poses, _, likes = matched_poses(
                self.maps.pool, self.maps.table, self.poses, self.laser, ranges, angles,
                self.maps.geom, p.kernelSize, p.sigma, p.lsigma, p.lskip, p.lstep, p.astep,
                p.iterations, p.minimumScore, self.reach, p.climb_skip,
                p.degeneracy_threshold if p.continuous_score else 0.0,
            )  # fmt: skip
            self.weights += likes
            self.weight_sums += likes
            norm = self.normalized_weights()
            self.neff = float(1.0 / np.sum(norm**2))
            result.neff = self.neff
            if self.neff < p.resampleThreshold * p.particles:
                idx = systematic_resample(norm, self.rng)
                self._resample(idx)
                result.resampled = True
        # the scan is written from the matched poses, which the hill climber moved (up to
        # ~0.4 m): the maps grow for them too (gmapping's computeActiveArea runs at
        # registerScan, after matching); the writes do not check bounds
        self._grow_for(ranges, angles)
        # the first scan: every particle is at the same pose, register it once and share it
        poses = self.poses[:1] if first else self.poses
        cells, hits = endpoint_cells(poses, self.laser, ranges, angles, self.maps.geom)
        self.maps.write(add_hits, cells, hits)
        self.counts.write(
            cast_counts, poses, self.laser,
            np.ascontiguousarray(beams.ranges, dtype=np.float64),
            np.ascontiguousarray(beams.angles, dtype=np.float64),
            self.usable_range, self.counts.geom,
        )  # fmt: skip
        if first:
            self.maps.resample(np.zeros(p.particles, dtype=int))
            self.counts.resample(np.zeros(p.particles, dtype=int))
        self.linear = self.angular = 0.0
        self.last_update_time = stamp
        self.updates += 1
        return result

    def normalized_weights(self) -> np.ndarray:
        """(P,) ``exp((l - l_max) / (ogain * P))`` normalised (gmapping's ``normalize``)."""
        gain = 1.0 / (self.p.ogain * len(self.weights))
        w = np.exp(gain * (self.weights - self.weights.max()))
        return w / w.sum()

    def _resample(self, idx: np.ndarray) -> None:
        self.poses = self.poses[idx]
        self.weight_sums = self.weight_sums[idx]
        self.weights = np.zeros(len(idx))
        self.maps.resample(idx)
        self.counts.resample(idx)

    def _grow_for(self, ranges: np.ndarray, angles: np.ndarray) -> None:
        """Enlarge every map when this scan (from any particle) reaches beyond it: as far as
        a beam writes, ``maxUrange`` (gmapping's ScanMatcher::computeActiveArea clips its
        end points to the usable range and skips beams beyond ``maxRange``). By ``maxRange``,
        a hunter's map (maxUrange 16 m, a 30 m laser) had grown ~5x the cells it needed."""
        usable = min(self.max_range, self.usable_range)
        reach = max(usable, 0.0) + float(np.hypot(*self.laser[:2]))
        x, y = self.poses[:, 0], self.poses[:, 1]
        pads = self.maps.growth_for(
            x.min() - reach, y.min() - reach, x.max() + reach, y.max() + reach, ENLARGE_STEP
        )
        if any(pads):
            self.maps.grow(*pads)
            self.counts.grow(*pads)

    # ----- outputs -----
    @property
    def best_index(self) -> int:
        return int(np.argmax(self.weight_sums))

    @property
    def best_pose(self) -> np.ndarray:
        return self.poses[self.best_index].copy()

    def entropy(self) -> float:
        """Entropy of the normalised weights (gmapping's ``computePoseEntropy``)."""
        w = self.normalized_weights()
        w = w[w > 0]
        return float(-np.sum(w * np.log(w)))

    def occupancy(self) -> tuple[np.ndarray, np.ndarray]:
        """The best particle's map: ``(data (H, W) int8, geom (origin x, origin y, delta))``.

        Read out of its counts: the cost is the map's size, not the length of the run.
        """
        thresh = self.p.occ_thresh
        data = self.counts.dense_of(
            self.best_index,
            lambda c: occupancy_from_counts(c[..., 0], c[..., 1], thresh),
            np.int8,
        )
        return data, self.counts.geom.copy()
