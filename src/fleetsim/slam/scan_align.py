"""Gauss-Newton refinement of a scan match: the fast matcher's last stage (``climb_skip``, a
fleetsim addition; see `fleetsim.slam.scan_match`).

The hill climber with every fourth beam gets within a few millimetres of the top of the
continuous score; scoring all beams on gmapping's ever finer grid to get the rest of the way
cost half the matcher's time (each halving of the steps costs 2-3 rounds of 6 scores). Here
the last millimetres are solved for instead: a few Gauss-Newton steps of a point-to-line fit
(the residual of a beam is its endpoint's distance to the line through the mean hit positions
in its kernel window, along that line's normal; a window with one hit gives a point-to-point
residual), each hit weighted by its beam's score ``exp(-d^2/sigma)``, beams whose nearest hit
lies beyond ``reach`` (no gradient in the continuous score) left out, and Levenberg-Marquardt
damping so that a direction the scan does not constrain (along a corridor) stays where the
climber left it. A point-to-point fit (ICP on the mean hits, the continuous score's own
residual) was tried first: it slides along walls a third of the remaining way per step and
left 1-2 mrad of yaw after six steps, where point-to-line converges in two. Tried and dropped
too: a window whose hits do not lie along a line (a corner) fitted point-to-point and the
residual taken to the window's centroid (no better on tests/slam's room; on Willow measured
only together with the score's parabola after the fit, seeds 1 and 2 precision 0.90, 0.88).

The fit's optimum is not exactly the continuous score's: the score measures distances to the
cells' mean hits, points 5 cm apart along a wall, so its top moves with where the points fall
along the walls by up to a millimetre; the fit measures distances to the walls through them
(on tests/slam's synthetic room: 0.02 mm and 0.01 mrad from the true pose, against the exact
climber's 1.3 mm and 0.5 mrad).

A library ICP (Open3D, a k-d tree over points) would rebuild its neighbour structure from the
particle's map at every update; the map's tiles already answer "hits near this cell" with
nine look-ups, and the fit is a 3 x 3 system.
"""

from __future__ import annotations

import math

import numba

from .tiles import MASK as _MASK
from .tiles import SHIFT as _SHIFT

#: most Gauss-Newton steps per particle; they stop earlier when a step moves less than
#: `STEP_TOLERANCE` (m and rad summed)
MAX_STEPS = 4
STEP_TOLERANCE = 1e-5
#: Levenberg-Marquardt damping, a fraction of the normal matrix's trace added to its diagonal
DAMPING = 1e-4


@numba.njit(cache=True, inline="always")
def laser_origin(x, y, th, laser):
    """Where the laser is, ``(lx, ly, heading)`` in the map frame, for a robot at (x, y, th)
    (``laser``: its (x, y, yaw) in the base frame); shared by the matcher's kernels."""
    c, s = math.cos(th), math.sin(th)
    return x + c * laser[0] - s * laser[1], y + s * laser[0] + c * laser[1], th + laser[2]


@numba.njit(cache=True, fastmath=True, error_model="numpy")
def _normal_equations(pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, reach):
    """The point-to-line fit's normal equations of particle p at ``pose`` (arguments as
    `aligned_pose`): ``(h00, h01, h02, h11, h12, h22, g0, g1, g2, score)``, H symmetric over
    (x, y, yaw), g the gradient, score the continuous score at ``pose``."""
    ox, oy, delta = geom[0], geom[1], geom[2]
    inv = 1.0 / delta
    lx, ly, lt = laser_origin(pose[0], pose[1], pose[2], laser)
    cl, sl = math.cos(lt), math.sin(lt)
    inv_sigma = 1.0 / sigma
    cap = reach * reach
    far = math.exp(-cap * inv_sigma)
    ty_n, tx_n = table.shape[1], table.shape[2]
    # the normal equations H d = -g, H symmetric
    h00 = h01 = h02 = h11 = h12 = h22 = 0.0
    g0 = g1 = g2 = 0.0
    score = 0.0
    for b in range(ex.shape[0]):
        hx = lx + cl * ex[b] - sl * ey[b]
        hy = ly + sl * ex[b] + cl * ey[b]
        ihx = math.floor((hx - ox) * inv)
        ihy = math.floor((hy - oy) * inv)
        x0, x1, y0, y1 = ihx - kernel, ihx + kernel, ihy - kernel, ihy + kernel
        best, bx, by = 1e36, 0.0, 0.0
        k = 0
        sx = sy = sxx = sxy = syy = 0.0  # the window's hits, relative to the endpoint
        # a window leaving the map holds no hit (the map grows 10 m beyond every scan)
        if x0 >= 0 and y0 >= 0 and (y1 >> _SHIFT) < ty_n and (x1 >> _SHIFT) < tx_n:
            for cy in range(y0, y1 + 1):
                for cx in range(x0, x1 + 1):
                    t = table[p, cy >> _SHIFT, cx >> _SHIFT]
                    if t < 0 or pool[t, cy & _MASK, cx & _MASK, 0] <= 0.0:
                        continue
                    ux = pool[t, cy & _MASK, cx & _MASK, 1] - hx
                    uy = pool[t, cy & _MASK, cx & _MASK, 2] - hy
                    d = ux * ux + uy * uy
                    if d < best:
                        best, bx, by = d, ux, uy
                    k += 1
                    sx += ux
                    sy += uy
                    sxx += ux * ux
                    sxy += ux * uy
                    syy += uy * uy
        if best >= cap:
            score += far
            continue
        w = math.exp(-best * inv_sigma)
        score += w
        ax, ay = pose[1] - hy, hx - pose[0]  # d(endpoint) / d(yaw)
        rx, ry = -bx, -by  # endpoint minus its nearest hit
        if k >= 2:
            mx, my = sx / k, sy / k
            cxx, cxy, cyy = sxx / k - mx * mx, sxy / k - mx * my, syy / k - my * my
            phi = 0.5 * math.atan2(2.0 * cxy, cxx - cyy)  # the hits' principal direction
            nx, ny = -math.sin(phi), math.cos(phi)
            r = nx * rx + ny * ry
            j2 = nx * ax + ny * ay
            h00 += w * nx * nx
            h01 += w * nx * ny
            h02 += w * nx * j2
            h11 += w * ny * ny
            h12 += w * ny * j2
            h22 += w * j2 * j2
            g0 += w * nx * r
            g1 += w * ny * r
            g2 += w * j2 * r
        else:
            h00 += w
            h11 += w
            h02 += w * ax
            h12 += w * ay
            h22 += w * (ax * ax + ay * ay)
            g0 += w * rx
            g1 += w * ry
            g2 += w * (ax * rx + ay * ry)
    return h00, h01, h02, h11, h12, h22, g0, g1, g2, score


@numba.njit(cache=True, fastmath=True, error_model="numpy")
def aligned_pose(pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, reach):
    """One damped Gauss-Newton step of particle p's base pose (point-to-line, see the module).

    Parameters
    ----------
    pool, table : the particles' hit maps (see `fleetsim.slam.scan_match`); p : the particle.
    pose : (3,) base pose in the map frame (m, m, rad).
    laser : (3,) laser in the base frame; ex, ey : (B,) beam endpoints in the laser frame (m).
    geom : (origin x, origin y, delta) of the map (m, m, m/cell).
    kernel : cells searched round an endpoint's cell; sigma : m^2; reach : the continuous
        score's cap (m), > 0.

    Returns
    -------
    new : (3,) the pose after the step (``pose`` when no beam has a hit within ``reach``);
    score : the continuous score at ``pose`` (not at ``new``).
    """
    h00, h01, h02, h11, h12, h22, g0, g1, g2, score = _normal_equations(
        pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, reach
    )
    new = pose.copy()
    lam = DAMPING * (h00 + h11 + h22)
    a00, a11, a22 = h00 + lam, h11 + lam, h22 + lam
    m00 = a11 * a22 - h12 * h12  # cofactors of the symmetric 3 x 3 matrix
    m01 = h01 * a22 - h12 * h02
    m02 = h01 * h12 - a11 * h02
    det = a00 * m00 - h01 * m01 + h02 * m02
    if not det > 0.0:  # no beam within reach
        return new, score
    # Cramer's rule for H d = -g
    new[0] -= (g0 * m00 - h01 * (g1 * a22 - h12 * g2) + h02 * (g1 * h12 - a11 * g2)) / det
    new[1] -= (a00 * (g1 * a22 - h12 * g2) - g0 * m01 + h02 * (h01 * g2 - g1 * h02)) / det
    new[2] -= (a00 * (a11 * g2 - g1 * h12) - h01 * (h01 * g2 - g1 * h02) + g0 * m02) / det
    return new, score


@numba.njit(cache=True)
def refined_pose(pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, reach, lstep, astep):
    """(3,) particle p's pose after up to `MAX_STEPS` steps of `aligned_pose`, stopping when a
    step moves less than `STEP_TOLERANCE`. A fit that moves more than ``lstep`` or ``astep``
    (the climber's first steps) from ``pose`` left the climber's basin: ``pose`` is kept."""
    cur = pose.copy()
    for _ in range(MAX_STEPS):
        new, _ = aligned_pose(pool, table, p, cur, laser, ex, ey, geom, kernel, sigma, reach)
        moved = abs(new[0] - cur[0]) + abs(new[1] - cur[1]) + abs(new[2] - cur[2])
        cur = new
        if moved < STEP_TOLERANCE:
            break
    if math.hypot(cur[0] - pose[0], cur[1] - pose[1]) > lstep or abs(cur[2] - pose[2]) > astep:
        return pose.copy()
    return cur


@numba.njit(cache=True)
def constrained_pose(
    pool, table, p, pose, sampled, laser, ex, ey, geom, kernel, sigma, reach, threshold
):  # fmt: skip
    """(3,) the matched ``pose`` with its translation from ``sampled`` (the particle's pose
    from the motion model) kept only along the directions the scan constrains.

    The information the fit has on the translation, with the yaw free (the Schur complement of
    the normal matrix's yaw block, in beams' worth of a fully weighted hit on a wall square to
    the move), is checked along its two principal directions; along one with less than
    ``threshold`` the scan cannot tell where the robot is (a single wall in range, a corridor
    with its ends out of range), the score is flat but for the ends of what the map holds of
    the walls and the cells' noise, and the climber drifts along it. There the sampled pose is
    kept, as the motion model put it (solution remapping, Zhang, Kaess and Singh, "On
    degeneracy of optimization-based state estimation problems", ICRA 2016).
    """
    h00, h01, h02, h11, h12, h22, _, _, _, _ = _normal_equations(
        pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, reach
    )
    s00, s01, s11 = h00, h01, h11
    if h22 > 0.0:
        s00 -= h02 * h02 / h22
        s01 -= h02 * h12 / h22
        s11 -= h12 * h12 / h22
    half = math.sqrt(0.25 * (s00 - s11) ** 2 + s01 * s01)
    small, large = 0.5 * (s00 + s11) - half, 0.5 * (s00 + s11) + half
    out = pose.copy()
    if small >= threshold:
        return out
    if large < threshold:  # nothing in range constrains it: the motion model's translation
        out[0], out[1] = sampled[0], sampled[1]
        return out
    # the eigenvector of the small eigenvalue: from the matrix row with the larger entries
    vx, vy = s01, small - s00
    if abs(s00 - small) < abs(s11 - small):
        vx, vy = small - s11, s01
    norm = math.hypot(vx, vy)
    if norm == 0.0:
        return out
    vx, vy = vx / norm, vy / norm
    along = (pose[0] - sampled[0]) * vx + (pose[1] - sampled[1]) * vy
    out[0] -= along * vx
    out[1] -= along * vy
    return out
