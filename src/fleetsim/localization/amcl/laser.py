"""Laser measurement models (amcl's ``AMCLLaser``), batched over particles x beams.

Three models, as ``laser_model_type``:

- ``likelihood_field`` (default): each beam end point is scored by its distance to the nearest
  obstacle, ``pz = z_hit * exp(-d^2 / (2 sigma_hit^2)) + z_rand / range_max``; amcl combines beams
  with its ad-hoc ``p = 1 + sum(pz^3)``. Max-range readings are ignored.
- ``likelihood_field_prob``: the same ``pz`` combined as a product (``exp(sum(log pz))``), with
  optional beam skipping: once the filter has converged, beams for which too few particles see
  an obstacle near the end point are left out (people, unmapped furniture).
- ``beam``: ray casting in the map (Bresenham, unknown cells block like obstacles, as amcl's
  ``map_calc_range``) and the four-part mixture z_hit / z_short / z_max / z_rand.

The scan is conditioned first by `fleetsim.localization.amcl.scan.beams_from_scan`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .grid_map import AmclMap
from .scan import ScanBeams


def likelihood_field_table(
    grid: AmclMap, max_dist: float, z_hit: float, z_rand: float, sigma_hit: float, range_max: float
) -> tuple[np.ndarray, float]:
    """Per-cell beam-end likelihood ``pz`` (H, W) float64 and its off-map value (cached).

    ``pz = z_hit * exp(-d^2 / (2 sigma_hit^2)) + z_rand / range_max`` with ``d`` the distance
    field clipped at ``max_dist`` (off the map ``d = max_dist``, as amcl).
    """
    denom = 2.0 * sigma_hit * sigma_hit
    rand_term = z_rand / range_max
    off = z_hit * math.exp(-(max_dist * max_dist) / denom) + rand_term
    key = ("pz", max_dist, z_hit, z_rand, sigma_hit, range_max)
    table = grid.cached(
        key, lambda: z_hit * np.exp(-np.square(grid.distance_field(max_dist)) / denom) + rand_term
    )
    return table, off


@njit(cache=True)
def _beam_offsets(ranges, bearings):
    b = ranges.shape[0]
    rc = np.empty(b)
    rs = np.empty(b)
    for m in range(b):
        rc[m] = ranges[m] * math.cos(bearings[m])
        rs[m] = ranges[m] * math.sin(bearings[m])
    return rc, rs


@njit(cache=True, inline="always")
def _laser_in_cells(particles, k, laser_pose, origin_x, origin_y, inv):
    """Particle ``k``'s laser origin in (fractional) map cells and its heading's cosine and
    sine scaled to cells per metre, so a beam endpoint is ``origin + R(heading) (rc, rs)``."""
    c = math.cos(particles[k, 2])
    s = math.sin(particles[k, 2])
    sx = (particles[k, 0] + laser_pose[0] * c - laser_pose[1] * s - origin_x) * inv
    sy = (particles[k, 1] + laser_pose[0] * s + laser_pose[1] * c - origin_y) * inv
    ca = math.cos(particles[k, 2] + laser_pose[2]) * inv
    sa = math.sin(particles[k, 2] + laser_pose[2]) * inv
    return sx, sy, ca, sa


@njit(cache=True)
def endpoint_table_sums(
    particles, laser_pose, ranges, bearings, table, off_value, origin_x, origin_y, resolution
):
    """(P,) sum over beams of ``table`` at each particle's beam end points.

    Parameters
    ----------
    particles : (P, 3) float64
        Robot poses ``(x, y, yaw)`` in the map frame, m, rad.
    laser_pose : (3,) float64
        Laser pose in the robot base frame.
    ranges, bearings : (B,) float64
        Measured ranges (m) and beam angles in the laser frame (rad).
    table : (H, W) float64
        Per-cell value (e.g. ``pz**3`` or ``log pz`` from `likelihood_field_table`).
    off_value : float
        Value for end points off the map.
    origin_x, origin_y, resolution : float
        Map geometry, m.
    """
    n = particles.shape[0]
    h, w = table.shape
    rc, rs = _beam_offsets(ranges, bearings)
    inv = 1.0 / resolution
    out = np.empty(n)
    for k in range(n):
        sx, sy, ca, sa = _laser_in_cells(particles, k, laser_pose, origin_x, origin_y, inv)
        acc = 0.0
        for m in range(rc.shape[0]):
            fx = sx + ca * rc[m] - sa * rs[m]
            fy = sy + sa * rc[m] + ca * rs[m]
            if fx < 0.0 or fy < 0.0:
                acc += off_value
                continue
            i = int(fx)
            j = int(fy)
            if i >= w or j >= h:
                acc += off_value
            else:
                acc += table[j, i]
        out[k] = acc
    return out


@njit(cache=True)
def endpoint_likelihoods(
    particles,
    laser_pose,
    ranges,
    bearings,
    table,
    off_value,
    dist,
    skip_distance,
    origin_x,
    origin_y,
    resolution,
):
    """Per-beam likelihood of each particle's beam end points, and beam agreement counts.

    Shapes and frames as `endpoint_table_sums`; ``table`` (H, W) is ``pz`` from
    `likelihood_field_table`, ``dist`` (H, W) the distance field (m).

    Returns
    -------
    pz : (P, B) float64
        Beam-end likelihoods (``off_value`` off the map).
    near : (B,) int64
        For each beam, the number of particles whose end point is on the map and within
        ``skip_distance`` (m) of an obstacle.
    """
    n = particles.shape[0]
    b = ranges.shape[0]
    h, w = table.shape
    rc, rs = _beam_offsets(ranges, bearings)
    inv = 1.0 / resolution
    pz = np.empty((n, b))
    near = np.zeros(b, dtype=np.int64)
    for k in range(n):
        sx, sy, ca, sa = _laser_in_cells(particles, k, laser_pose, origin_x, origin_y, inv)
        for m in range(b):
            fx = sx + ca * rc[m] - sa * rs[m]
            fy = sy + sa * rc[m] + ca * rs[m]
            if fx < 0.0 or fy < 0.0:
                pz[k, m] = off_value
                continue
            i = int(fx)
            j = int(fy)
            if i >= w or j >= h:
                pz[k, m] = off_value
            else:
                pz[k, m] = table[j, i]
                if dist[j, i] < skip_distance:
                    near[m] += 1
    return pz, near


def likelihood_field_prob_log_weights(
    pz: np.ndarray,
    near: np.ndarray,
    do_beamskip: bool,
    skip_threshold: float,
    skip_error_threshold: float,
) -> tuple[np.ndarray, np.ndarray]:
    """(P,) log-likelihood ``sum_b log pz`` of ``likelihood_field_prob``, and the (B,) beam mask.

    With ``do_beamskip`` (the caller passes it only once the filter has converged), beams seen
    near an obstacle by at most ``skip_threshold`` of the particles are left out, unless that
    leaves out at least ``skip_error_threshold`` of the beams, in which case all are used (the
    filter has probably converged to a wrong pose).
    """
    n, b = pz.shape
    mask = np.ones(b, dtype=bool)
    if do_beamskip and b > 0 and n > 0:
        agree = (near / float(n)) > skip_threshold
        if np.count_nonzero(~agree) < b * skip_error_threshold:
            mask = agree
    return np.log(pz[:, mask]).sum(axis=1), mask


@njit(cache=True)
def ranges_from_map(occ_state, origin_x, origin_y, resolution, x, y, angle, max_range):
    """Range (m) from ``(x, y)`` along ``angle`` to the first non-free cell (amcl map_calc_range).

    Bresenham over the cells of ``occ_state`` ((H, W) int8, -1 free); off-map or unknown cells
    stop the ray like obstacles; returns ``max_range`` when nothing is hit.
    """
    h, w = occ_state.shape
    x0 = math.floor((x - origin_x) / resolution)
    y0 = math.floor((y - origin_y) / resolution)
    x1 = math.floor((x + max_range * math.cos(angle) - origin_x) / resolution)
    y1 = math.floor((y + max_range * math.sin(angle) - origin_y) / resolution)
    steep = abs(y1 - y0) > abs(x1 - x0)
    if steep:
        x0, y0 = y0, x0
        x1, y1 = y1, x1
    deltax = abs(x1 - x0)
    deltay = abs(y1 - y0)
    error = 0
    xstep = 1 if x0 < x1 else -1
    ystep = 1 if y0 < y1 else -1
    cx = x0
    cy = y0
    while True:
        gi, gj = (cy, cx) if steep else (cx, cy)
        if gi < 0 or gj < 0 or gi >= w or gj >= h or occ_state[gj, gi] > -1:
            return math.sqrt((cx - x0) ** 2 + (cy - y0) ** 2) * resolution
        if cx == x1:
            return max_range
        cx += xstep
        error += deltay
        if 2 * error >= deltax:
            cy += ystep
            error -= deltax


@njit(cache=True)
def beam_model_weights(
    particles,
    laser_pose,
    ranges,
    bearings,
    occ_state,
    origin_x,
    origin_y,
    resolution,
    z_hit,
    z_short,
    z_max,
    z_rand,
    sigma_hit,
    lambda_short,
    range_max,
):
    """(P,) amcl's ``beam`` model likelihood ``1 + sum_b pz^3`` of each particle.

    Shapes and frames as `endpoint_likelihoods`; ``occ_state`` (H, W) int8 as in `AmclMap`.
    """
    n = particles.shape[0]
    b = ranges.shape[0]
    out = np.empty(n)
    denom = 2.0 * sigma_hit * sigma_hit
    lx, ly, la = laser_pose[0], laser_pose[1], laser_pose[2]
    for k in range(n):
        c = math.cos(particles[k, 2])
        s = math.sin(particles[k, 2])
        sx = particles[k, 0] + lx * c - ly * s
        sy = particles[k, 1] + lx * s + ly * c
        sa = particles[k, 2] + la
        p = 1.0
        for m in range(b):
            obs = ranges[m]
            expected = ranges_from_map(
                occ_state, origin_x, origin_y, resolution, sx, sy, sa + bearings[m], range_max
            )
            z = obs - expected
            pz = z_hit * math.exp(-(z * z) / denom)
            if z < 0:
                pz += z_short * lambda_short * math.exp(-lambda_short * obs)
            if obs >= range_max:
                pz += z_max
            else:
                pz += z_rand / range_max
            p += pz * pz * pz
        out[k] = p
    return out


def laser_likelihoods(
    particles: np.ndarray,
    beams: ScanBeams,
    laser_pose: np.ndarray,
    grid: AmclMap,
    params,
    converged: bool,
) -> tuple[np.ndarray, bool]:
    """Likelihood of the scan for each particle under ``params.laser_model_type``.

    Returns ``(values, is_log)``: (P,) float64 likelihoods, or log-likelihoods when ``is_log``
    (``likelihood_field_prob``, whose products of many beams can underflow).
    """
    parts = np.ascontiguousarray(particles, dtype=np.float64)
    lp = np.asarray(laser_pose, dtype=np.float64)
    model = params.laser_model_type
    if model == "beam":
        vals = beam_model_weights(
            parts,
            lp,
            beams.ranges,
            beams.bearings,
            grid.occ_state,
            grid.origin_x,
            grid.origin_y,
            grid.resolution,
            params.laser_z_hit,
            params.laser_z_short,
            params.laser_z_max,
            params.laser_z_rand,
            params.laser_sigma_hit,
            params.laser_lambda_short,
            beams.range_max,
        )
        return vals, False
    max_dist = params.laser_likelihood_max_dist
    table, off = likelihood_field_table(
        grid,
        max_dist,
        params.laser_z_hit,
        params.laser_z_rand,
        params.laser_sigma_hit,
        beams.range_max,
    )
    geom = (grid.origin_x, grid.origin_y, grid.resolution)
    if model == "likelihood_field":  # amcl's ad-hoc p = 1 + sum(pz^3)
        cubes = grid.cached(("pz^3", *table_key(params, beams)), lambda: table**3)
        sums = endpoint_table_sums(parts, lp, beams.ranges, beams.bearings, cubes, off**3, *geom)
        return 1.0 + sums, False
    if not (params.do_beamskip and converged):
        logs = grid.cached(("log pz", *table_key(params, beams)), lambda: np.log(table))
        sums = endpoint_table_sums(
            parts, lp, beams.ranges, beams.bearings, logs, math.log(off), *geom
        )
        return sums, True
    pz, near = endpoint_likelihoods(
        parts,
        lp,
        beams.ranges,
        beams.bearings,
        table,
        off,
        grid.distance_field(max_dist),
        params.beam_skip_distance,
        *geom,
    )
    logw, _ = likelihood_field_prob_log_weights(
        pz, near, True, params.beam_skip_threshold, params.beam_skip_error_threshold
    )
    return logw, True


def table_key(params, beams: ScanBeams) -> tuple:
    """Cache key of the likelihood-field tables for these parameters and scan range."""
    return (
        params.laser_likelihood_max_dist,
        params.laser_z_hit,
        params.laser_z_rand,
        params.laser_sigma_hit,
        beams.range_max,
    )
