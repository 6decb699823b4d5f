"""gmapping's scan matcher (``scanmatcher.cpp``) as numba kernels batched over particles and beams.

Each particle's map is a tiled hit map (see `fleetsim.slam.tiles`): ``table[p, ty, tx]`` is the
index of a tile in a shared ``pool`` of shape ``(T, TILE, TILE, 3)`` holding per cell the hit
count and the mean hit position (x, y in m, map frame; `FAR` where never hit), or -1 for a
tile never hit. This is gmapping with ``setgenerateMap(false)``, what slam_gmapping runs: the
matching maps store endpoints only. (gmapping keeps sums and divides at every look-up; the
mean, with FAR for an empty cell, leaves the matcher's inner loop without a division or a
branch.)

A cell is "full" when it holds a hit. gmapping also asks that a "free" cell be empty
(``cell > fullnessThreshold && fcell < fullnessThreshold``), but it finds that cell at
``world2map(pfree - phit)``: a vector of a few millimetres taken through ``world2map``, which
adds the map's half size, so the free cell lies half a map away from the hit, in space the
robot has not seen, and the test never rejects. What gmapping runs is therefore "any cell with a
hit", and so is this. Taking the free cell one step back along the beam, as the code seems to
intend, biases every match: only the front-most hit cell of a wall counts, and its mean lies
in front of the wall, so each match pulls the robot away from what it sees by a few
millimetres. A 360-degree laser sees walls on all sides and the pulls cancel; a forward-facing
180-degree laser (the hunter's) drifts backwards, by 1 m over the office (tests/slam/
test_filter.py, a robot circling with a 180-degree laser).

The continuous score (``continuous_score``, a fleetsim addition, on by default). gmapping adds
``exp(-d^2/sigma)`` for a beam with a hit within ``kernelSize`` cells of its endpoint's cell and
0 for one without. With the usual sigma (0.05 m^2) a found beam scores 0.82-1, so the score is
mostly a count of the beams that find a hit, and that count jumps whenever an endpoint crosses a
cell edge: the maximum the hill climber finds sits off the true pose by a random 1-2 cm and
0.003 rad at each update even with a consistent map and exact odometry, and those errors add
up along a corridor (Willow replay, noise-free motion model: 0.83 m at worst, the walls mapped
twice). With the distance capped at ``kernelSize * delta`` (the distance the window always
covers, whatever the endpoint's place in its cell) a beam without a hit within that distance
scores what one at the cap does: the score is continuous in the pose (a truncated least
squares), and the same replay stays within 1.5 cm. With the continuous score the climber's
pose is also refined below its last step: its last round scored both neighbours on each axis
lower, and the pose moves to the top of the parabola through the three scores (at most half a
step). gmapping stops on the grid of its last step (``astep / 2^iterations``, 0.004 rad with
the manual's parameters, 4 cm at 10 m), and those errors add up too (Willow replay with the
manual's noise: ATE 0.06 / 0.04 / 0.03 m without the refinement, 0.01 / 0.05 / 0.03 m with,
precision 0.91-0.96 -> 0.97-0.99, seeds 1-3). The likelihood (the particles' weights) is
gmapping's: beams without a hit still cost ``nullLikelihood``.

The fast matcher (``climb_skip``, a fleetsim addition, on by default with the continuous
score). Each halving of the climber's steps costs 2-3 rounds of 6 scores of every beam, ~66-86
scores a particle in all, most of an update's time. With ``climb_skip`` 3 the climber scores
every 4th beam (of those ``lskip`` leaves) all the way down, as gmapping's own ``lskip`` would,
which gets it within a few millimetres of the top; then a few Gauss-Newton steps of a
point-to-line fit of every beam finish the match (`fleetsim.slam.scan_align`), replacing the
parabola; the score and the likelihood are those of every beam at that pose. What it
approximates: the pose is the top of the fit of the endpoints to the walls through the cells'
mean hits, not the top of the score over those mean hits (they differ by a millimetre or two
along walls). Cost on 30 particles x 360 beams: the matcher ~0.4 of the exact climber's time.
Quality, Willow seeds 1-3 with the manual's parameters (benchmarks/slam_quality.py): precision
0.941 / 0.994 / 0.988, recall 0.886 / 0.915 / 0.910, ATE 0.033 / 0.019 / 0.017 m, against the
exact climber's 0.955 / 0.960 / 0.943, 0.889 / 0.893 / 0.891, 0.026 / 0.032 / 0.066 m. Tried
and dropped: the quarter-beam climb finished by its last round scored again with every beam
and the parabola through it (0.975 / 0.886 / 0.924, recall 0.895 / 0.854 / 0.877: a quarter
of the beams puts the climber's top a few millimetres off, more than a step of the last
round corrects), and that round after the fit (with scan_align's corner test; seeds 1, 2:
precision 0.90, 0.88).

Geometry arguments shared by the kernels:
``geom = (origin_x, origin_y, delta)`` (m, m, m/cell) of cell (0, 0)'s corner;
``laser = (x, y, yaw)`` of the laser in the base frame; ``ranges, angles`` (B,) in m and rad
(laser frame), already restricted to usable beams (``0 < r <= maxUrange``).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .scan_align import constrained_pose, laser_origin, refined_pose
from .tiles import FAR, writable_tile
from .tiles import MASK as _MASK
from .tiles import SHIFT as _SHIFT

NULL_LIKELIHOOD = -0.5  # gmapping's nullLikelihood
NO_HIT = 1e30  # squared distances (m^2) from here on mean "no hit in the window"


@numba.njit(cache=True, inline="always")
def _hits_at(pool, table, p, ix, iy):
    """Tile index and in-tile cell of (ix, iy) in particle p's map; tile -1 outside or unset."""
    tx = ix >> _SHIFT
    ty = iy >> _SHIFT
    if ix < 0 or iy < 0 or ty >= table.shape[1] or tx >= table.shape[2]:
        return -1
    return table[p, ty, tx]


@numba.njit(cache=True, fastmath=True, error_model="numpy")
def _match(pool, table, p, pose, laser, ex, ey, geom, kernel, sigma, lsigma, skip, reach, want_l):
    """gmapping's score (and, when want_l, likelihood) of ``pose`` for particle p.

    ``ex``/``ey`` (B,) are the beam endpoints in the laser frame (m). ``reach`` (m): with
    ``reach > 0`` a beam scores ``exp(-min(d, reach)^2 / sigma)`` whether or not its window
    holds a hit (the continuous score, see the module docstring); 0: gmapping's score.
    """
    ox, oy, delta = geom[0], geom[1], geom[2]
    inv = 1.0 / delta
    lx, ly, lt = laser_origin(pose[0], pose[1], pose[2], laser)
    cl, sl = math.cos(lt), math.sin(lt)
    no_hit = NULL_LIKELIHOOD / lsigma
    inv_sigma = 1.0 / sigma
    cap = reach * reach if reach > 0.0 else NO_HIT
    far = math.exp(-cap * inv_sigma)  # what a beam with no hit within reach scores (0 in gmapping)
    ty_n, tx_n = table.shape[1], table.shape[2]
    score = 0.0
    like = 0.0
    for b in range(0, ex.shape[0], skip + 1):
        hx = lx + cl * ex[b] - sl * ey[b]
        hy = ly + sl * ex[b] + cl * ey[b]
        ihx = math.floor((hx - ox) * inv)
        ihy = math.floor((hy - oy) * inv)
        x0, x1 = ihx - kernel, ihx + kernel
        y0, y1 = ihy - kernel, ihy + kernel
        tx0, tx1 = x0 >> _SHIFT, x1 >> _SHIFT
        ty0, ty1 = y0 >> _SHIFT, y1 >> _SHIFT
        best = FAR * FAR  # an empty cell's mean lies FAR away: no test for emptiness
        if tx0 == tx1 and ty0 == ty1 and x0 >= 0 and y0 >= 0 and ty0 < ty_n and tx0 < tx_n:
            # the window lies in one tile: look it up once (a tile never hit: no match)
            t = table[p, ty0, tx0]
            if t >= 0:
                for cy in range(y0 & _MASK, (y1 & _MASK) + 1):
                    for cx in range(x0 & _MASK, (x1 & _MASK) + 1):
                        mx = hx - pool[t, cy, cx, 1]
                        my = hy - pool[t, cy, cx, 2]
                        d = mx * mx + my * my
                        if d < best:
                            best = d
        else:
            for cy in range(y0, y1 + 1):
                for cx in range(x0, x1 + 1):
                    t = _hits_at(pool, table, p, cx, cy)
                    if t < 0:
                        continue
                    mx = hx - pool[t, cy & _MASK, cx & _MASK, 1]
                    my = hy - pool[t, cy & _MASK, cx & _MASK, 2]
                    best = min(best, mx * mx + my * my)
        if best < NO_HIT:
            score += math.exp(-min(best, cap) * inv_sigma)
            if want_l:
                like -= best / lsigma
        else:
            score += far
            if want_l:
                like += no_hit
    return score, like


@numba.njit(cache=True, inline="always")
def _vertex(below, centre, above, step):
    """Offset (in step's unit) of the top of the parabola through the scores ``below``,
    ``centre``, ``above`` at -step, 0, +step; within half a step when centre is the highest,
    0 when the three are flat."""
    curve = below - 2.0 * centre + above
    if curve >= 0.0:
        return 0.0
    return 0.5 * step * (below - above) / curve


@numba.njit(cache=True, inline="always")
def _moved(pose, move, ld, ad, out):
    """``out`` = ``pose`` after the climber's move (+x, -x, -y, +y, +yaw, -yaw by ld, ad)."""
    out[0], out[1], out[2] = pose[0], pose[1], pose[2]
    if move == 0:
        out[0] += ld
    elif move == 1:
        out[0] -= ld
    elif move == 2:
        out[1] -= ld
    elif move == 3:
        out[1] += ld
    elif move == 4:
        out[2] += ad
    else:
        out[2] -= ad


def matched_poses(
    pool, table, poses, laser, ranges, angles, geom, kernel, sigma, lsigma, skip,
    lstep, astep, iterations, minimum_score, reach=0.0, climb_skip=0, constrained=0.0,
):  # fmt: skip
    """Hill-climbed poses, scores and log-likelihoods of every particle (``ScanMatcher::optimize``
    then ``likelihoodAndScore``).

    Parameters
    ----------
    pool : (T, TILE, TILE, 3) float32, the shared tiles; table : (P, TY, TX) int32.
    poses : (P, 3) float64, the particles' sampled base poses in the map frame (m, m, rad).
    reach : m; > 0 scores with the continuous score (a beam's distance to its nearest hit
        capped at ``reach``) and refines the climber's last pose by a parabola through the last
        round's scores; 0: gmapping's score and climber (a beam without a hit in its window
        scores 0). The likelihood is gmapping's either way.
    climb_skip : with ``reach > 0`` and ``climb_skip > 0`` (the fast matcher, see the module
        docstring) the climber scores every ``(climb_skip + 1)``-th of the beams ``skip``
        leaves, and its pose is then refined on all of those by Gauss-Newton steps
        (`fleetsim.slam.scan_align`) instead of the parabola; the score is the continuous
        score at the refined pose.
    constrained : with ``reach > 0``, > 0: the matched translation is kept only along the
        directions on which the scan gives at least this much information, the sampled pose
        along the others (`fleetsim.slam.scan_align.constrained_pose`); 0: off (gmapping).

    Returns
    -------
    out : (P, 3) float64, the matched poses (the sampled pose where the score <= minimum_score);
    scores : (P,) the match scores; likes : (P,) the log-likelihoods at ``out``.
    """
    # one compiled signature: numba compiles the kernel anew (~5 s) for each set of argument
    # types, and an omitted default or an int passed for a float is another set
    return _matched_poses(
        pool, table, poses, laser, ranges, angles, geom, int(kernel), float(sigma),
        float(lsigma), int(skip), float(lstep), float(astep), int(iterations),
        float(minimum_score), float(reach), int(climb_skip), float(constrained),
    )  # fmt: skip


@numba.njit(cache=True)
def _matched_poses(
    pool, table, poses, laser, ranges, angles, geom, kernel, sigma, lsigma, skip,
    lstep, astep, iterations, minimum_score, reach, climb_skip, constrained,
):  # fmt: skip
    n = poses.shape[0]
    out = poses.copy()
    scores = np.zeros(n)
    likes = np.zeros(n)
    cand = np.empty(3)
    move_scores = np.empty(6)  # the round's score of each move (+x, -x, -y, +y, +yaw, -yaw)
    ex, ey = ranges * np.cos(angles), ranges * np.sin(angles)
    fast = reach > 0.0 and climb_skip > 0
    # the climber's beams: every (skip+1)-th, or in the fast matcher a (climb_skip+1)-th of those
    climb = (skip + 1) * (climb_skip + 1) - 1 if fast else skip
    used_x, used_y = ex[:: skip + 1].copy(), ey[:: skip + 1].copy()  # what scan_align fits
    for p in range(n):
        cur = poses[p].copy()
        cur_score, _ = _match(
            pool, table, p, cur, laser, ex, ey, geom, kernel, sigma, lsigma, climb, reach, False
        )
        best_score = -1.0
        ld, ad = lstep, astep
        refinement = 0
        back = -1  # the move leading back to the last round's pose (no better: not scored)
        back_score = -1.0
        while True:
            if best_score >= cur_score:
                refinement += 1
                ld *= 0.5
                ad *= 0.5
            best_score = cur_score
            best_local = cur.copy()
            taken = -1
            for move in range(6):
                if move == back:
                    move_scores[move] = back_score
                    continue
                _moved(cur, move, ld, ad, cand)
                sc, _ = _match(
                    pool, table, p, cand, laser, ex, ey, geom, kernel, sigma,
                    lsigma, climb, reach, False,
                )  # fmt: skip
                move_scores[move] = sc
                if sc > cur_score:
                    cur_score = sc
                    best_local[:] = cand
                    taken = move
            cur[:] = best_local
            if taken >= 0:
                back_score = best_score  # the pose left behind
            back = taken ^ 1 if taken >= 0 else -1  # moves come in opposite pairs
            if not (cur_score > best_score or refinement < iterations):
                break
        if fast:
            # the point-to-line fit of every beam from the climber's pose (scan_align)
            cur = refined_pose(
                pool, table, p, cur, laser, used_x, used_y, geom, kernel, sigma, reach, lstep,
                astep,
            )  # fmt: skip
            if constrained > 0.0:
                cur = constrained_pose(
                    pool, table, p, cur, poses[p], laser, used_x, used_y, geom, kernel, sigma,
                    reach, constrained,
                )  # fmt: skip
            # score and likelihood of every used beam in one pass
            best_score, like = _match(
                pool, table, p, cur, laser, ex, ey, geom, kernel, sigma, lsigma, skip, reach, True
            )
            if best_score > minimum_score:
                out[p] = cur
                scores[p], likes[p] = best_score, like
                continue
        elif best_score > minimum_score:
            out[p] = cur
            if reach > 0.0:
                # the last round scored every neighbour lower: the top of the parabola through
                # each axis' three scores (within half a step of the climber's pose)
                out[p, 0] += _vertex(move_scores[1], best_score, move_scores[0], ld)
                out[p, 1] += _vertex(move_scores[2], best_score, move_scores[3], ld)
                out[p, 2] += _vertex(move_scores[5], best_score, move_scores[4], ad)
                if constrained > 0.0:
                    out[p] = constrained_pose(
                        pool, table, p, out[p], poses[p], laser, used_x, used_y, geom, kernel,
                        sigma, reach, constrained,
                    )  # fmt: skip
        scores[p] = best_score
        _, likes[p] = _match(
            pool,
            table,
            p,
            out[p],
            laser,
            ex,
            ey,
            geom,
            kernel,
            sigma,
            lsigma,
            skip,
            reach,
            True,
        )
    return out, scores, likes


@numba.njit(cache=True)
def endpoint_cells(poses, laser, ranges, angles, geom):
    """(P, B, 2) int64 cells ``(ix, iy)`` of every beam's endpoint for every particle."""
    n, b = poses.shape[0], ranges.shape[0]
    out = np.empty((n, b, 2), dtype=np.int64)
    hits = np.empty((n, b, 2))
    ox, oy, delta = geom[0], geom[1], geom[2]
    for p in range(n):
        lx, ly, lt = laser_origin(poses[p, 0], poses[p, 1], poses[p, 2], laser)
        for i in range(b):
            hx = lx + ranges[i] * math.cos(lt + angles[i])
            hy = ly + ranges[i] * math.sin(lt + angles[i])
            hits[p, i, 0], hits[p, i, 1] = hx, hy
            out[p, i, 0] = math.floor((hx - ox) / delta)
            out[p, i, 1] = math.floor((hy - oy) / delta)
    return out, hits


@numba.njit(cache=True)
def add_hits(pool, table, refs, free, top, blank, start, cells, hits):
    """Add each particle's endpoints (from ``start`` on) to its own tiles; a `CowTiles` kernel.

    ``cells`` (P, B, 2) int cells and ``hits`` (P, B, 2) m, all inside the map. A cell holds
    its hit count and the mean hit position. Returns ``(next particle, free-stack top, tiles
    needed)``: early when fewer than B tiles are free.
    """
    nb = cells.shape[1]
    for p in range(start, cells.shape[0]):
        if top < nb:  # at most one new tile per endpoint
            return p, top, nb
        key = -1
        t = -1
        for i in range(nb):
            ix, iy = cells[p, i, 0], cells[p, i, 1]
            k = (iy >> _SHIFT) * table.shape[2] + (ix >> _SHIFT)
            if k != key:
                t, top = writable_tile(
                    pool, table, refs, free, top, blank, p, iy >> _SHIFT, ix >> _SHIFT
                )
                key = k
            c = pool[t, iy & _MASK, ix & _MASK]
            c[0] += 1.0
            if c[0] == 1.0:
                c[1], c[2] = hits[p, i, 0], hits[p, i, 1]
            else:
                c[1] += (hits[p, i, 0] - c[1]) / c[0]
                c[2] += (hits[p, i, 1] - c[2]) / c[0]
    return cells.shape[0], top, 0
