"""Gauss-Newton refinement of a scan match on the continuous score: the fast matcher's last
stage (``climb_skip``, a fleetsim addition; see `fleetsim.slam.scan_match`).

With the continuous score (``reach = kernelSize * delta``) a beam scores
``exp(-min(d, reach)^2 / sigma)``, ``d`` its endpoint's distance to the nearest mean hit
position: any hit within ``reach`` lies in the kernel's window, so this is the distance to the
nearest hit in the whole map, capped. The score is smooth wherever the nearest hits stay the
same, and its maximum is where the weighted point-to-point residuals balance. One step here
holds each beam's nearest hit fixed and weighs it by ``w = exp(-d^2 / sigma)`` (its score;
beams beyond ``reach`` have no gradient and drop out), then solves the weighted least-squares
rigid fit of endpoints onto their hits in closed form (2-D weighted Procrustes, as Umeyama's
method without scale): iteratively reweighted least squares, whose fixed points are the
score's stationary points. From the climber's pose (a few millimetres from the top) a few
steps converge; a step that lowers the score is not taken.

This is ICP with Gaussian weights, the same objective gmapping's climber samples on a grid;
a library ICP (Open3D, a k-d tree over points) would rebuild its nearest-neighbour structure
from the particle's map at every update, while the map's tiles already answer "nearest hit
near this cell" in nine look-ups.
"""

from __future__ import annotations

import math

import numba

from .tiles import MASK as _MASK
from .tiles import SHIFT as _SHIFT

#: most Gauss-Newton steps per particle; the steps stop earlier once they move less than
#: `STEP_TOLERANCE` (m + rad summed), about a hundredth of a cell
MAX_STEPS = 6
STEP_TOLERANCE = 5e-4


@numba.njit(cache=True, fastmath=True, error_model="numpy")
def _nearest_hit(pool, table, p, hx, hy, ihx, ihy, kernel):
    """``(d^2, x, y)``: the mean hit nearest to ``(hx, hy)`` (m) within ``kernel`` cells of
    cell ``(ihx, ihy)`` in particle p's map; ``d^2`` huge when the window holds none."""
    best, bx, by = 1e36, 0.0, 0.0
    x0, x1 = ihx - kernel, ihx + kernel
    y0, y1 = ihy - kernel, ihy + kernel
    ty_n, tx_n = table.shape[1], table.shape[2]
    if x0 < 0 or y0 < 0 or (y1 >> _SHIFT) >= ty_n or (x1 >> _SHIFT) >= tx_n:
        return best, bx, by  # the window leaves the map: nothing was ever hit there
    for cy in range(y0, y1 + 1):
        for cx in range(x0, x1 + 1):
            t = table[p, cy >> _SHIFT, cx >> _SHIFT]
            if t < 0:
                continue
            mx = pool[t, cy & _MASK, cx & _MASK, 1]
            my = pool[t, cy & _MASK, cx & _MASK, 2]
            d = (hx - mx) * (hx - mx) + (hy - my) * (hy - my)
            if d < best:
                best, bx, by = d, mx, my
    return best, bx, by


@numba.njit(cache=True, fastmath=True, error_model="numpy")
def aligned_pose(pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, reach):
    """One Gauss-Newton step of particle p's base pose on the continuous score.

    Parameters
    ----------
    pool, table : particle p's hit map (see `fleetsim.slam.scan_match`).
    pose : (3,) base pose in the map frame (m, m, rad).
    laser : (3,) laser in the base frame; ex, ey : (B,) beam endpoints in the laser frame (m).
    geom : (origin x, origin y, delta) of the map (m, m, m/cell).
    kernel : cells searched round an endpoint's cell; sigma : m^2; reach : the score's cap (m).

    Returns
    -------
    new : (3,) the pose after the step (``pose`` when no beam lies within ``reach``);
    score : the continuous score at ``pose`` (not at ``new``).
    """
    ox, oy, delta = geom[0], geom[1], geom[2]
    inv = 1.0 / delta
    c, s = math.cos(pose[2]), math.sin(pose[2])
    lx = pose[0] + c * laser[0] - s * laser[1]
    ly = pose[1] + s * laser[0] + c * laser[1]
    cl, sl = math.cos(pose[2] + laser[2]), math.sin(pose[2] + laser[2])
    inv_sigma = 1.0 / sigma
    cap = reach * reach
    far = math.exp(-cap * inv_sigma)
    sw = shx = shy = smx = smy = 0.0
    sxx = sxy = syx = syy = 0.0
    score = 0.0
    for b in range(ex.shape[0]):
        hx = lx + cl * ex[b] - sl * ey[b]
        hy = ly + sl * ex[b] + cl * ey[b]
        ihx = math.floor((hx - ox) * inv)
        ihy = math.floor((hy - oy) * inv)
        d, mx, my = _nearest_hit(pool, table, p, hx, hy, ihx, ihy, kernel)
        if d >= cap:
            score += far
            continue
        w = math.exp(-d * inv_sigma)
        score += w
        sw += w
        shx += w * hx
        shy += w * hy
        smx += w * mx
        smy += w * my
        sxx += w * hx * mx
        sxy += w * hx * my
        syx += w * hy * mx
        syy += w * hy * my
    new = pose.copy()
    if sw <= 0.0:
        return new, score
    # weighted centroids and cross-covariance of endpoints (h) and hits (m)
    hcx, hcy, mcx, mcy = shx / sw, shy / sw, smx / sw, smy / sw
    cxx = sxx / sw - hcx * mcx
    cxy = sxy / sw - hcx * mcy
    cyx = syx / sw - hcy * mcx
    cyy = syy / sw - hcy * mcy
    turn = math.atan2(cxy - cyx, cxx + cyy)  # the rotation taking the endpoints onto the hits
    ct, st = math.cos(turn), math.sin(turn)
    px, py = pose[0] - hcx, pose[1] - hcy
    new[0] = ct * px - st * py + mcx
    new[1] = st * px + ct * py + mcy
    new[2] = pose[2] + turn
    return new, score


@numba.njit(cache=True)
def refined_pose(pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, reach):
    """(3,) particle p's pose after up to `MAX_STEPS` Gauss-Newton steps of `aligned_pose`,
    stopping when a step moves less than `STEP_TOLERANCE`; a step that lowered the score is
    taken back."""
    cur = pose.copy()
    prev = pose.copy()
    last = -1.0
    for _ in range(MAX_STEPS):
        new, score = aligned_pose(pool, table, p, cur, laser, ex, ey, geom, kernel, sigma, reach)
        if score < last:  # the last step went down: back to where it started
            return prev
        last = score
        moved = abs(new[0] - cur[0]) + abs(new[1] - cur[1]) + abs(new[2] - cur[2])
        prev[:] = cur
        cur[:] = new
        if moved < STEP_TOLERANCE:
            break
    return cur
