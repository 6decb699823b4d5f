"""NavFn's compiled kernels: cost translation, potential propagation, gradient descent.

These follow navfn's NavFn class. Arrays are flat, row-major over an (ny, nx) grid
(index ``y * nx + x``), as navfn stores them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

COST_UNKNOWN_ROS = 255  # costmap NO_INFORMATION
COST_OBS_ROS = 253  # costmap INSCRIBED_INFLATED_OBSTACLE and above are obstacles
COST_OBS = 254  # navfn's obstacle cost
COST_NEUTRAL = 50  # cost of a free cell
COST_FACTOR = 0.8  # weight of costmap costs
POT_HIGH = np.float32(1.0e10)  # unassigned potential
PRIORITY_INCREMENT = 2 * COST_NEUTRAL  # navfn's priInc
INV_SQRT2 = np.float32(0.707106781)


@njit(cache=True)
def navfn_costs(costs, allow_unknown):
    """navfn's cost array from a costmap (NavFn::setCostmap with isROS, then its border).

    costs : (ny, nx) uint8 costmap (uint8 only: each value indexes a 256-entry table). Free
    cells become ``COST_NEUTRAL + COST_FACTOR * cost`` (at most 253); cells at or above
    INSCRIBED become COST_OBS, unknown cells COST_OBS - 1 when ``allow_unknown`` else
    COST_OBS; the outermost ring is COST_OBS.
    Returns (ny * nx,) uint8.
    """
    # one table lookup a cell, the border after: a branch a cell cost 2-4x as much on a
    # planner window of a SLAM map (about 1 ms of each 5 Hz plan)
    lut = np.empty(256, dtype=np.uint8)
    for c in range(256):
        v = COST_OBS
        if c < COST_OBS_ROS:
            v = min(int(COST_NEUTRAL + COST_FACTOR * c), COST_OBS - 1)
        elif c == COST_UNKNOWN_ROS and allow_unknown:
            v = COST_OBS - 1
        lut[c] = v
    ny, nx = costs.shape
    out = np.empty(ny * nx, dtype=np.uint8)
    for y in range(ny):
        row = costs[y]
        base = y * nx
        for x in range(nx):
            out[base + x] = lut[row[x]]
    out[:nx] = COST_OBS
    out[(ny - 1) * nx :] = COST_OBS
    for y in range(ny):
        out[y * nx] = COST_OBS
        out[y * nx + nx - 1] = COST_OBS
    return out


def known_bounds(costs: np.ndarray) -> tuple[int, int, int, int]:
    """(x0, y0, xn, yn): the bounds (end exclusive) of the cells of the (ny, nx) uint8 costmap
    that are not unknown (255); (0, 0, 0, 0) when every cell is.

    On a SLAM map mostly unknown (the hunter's 2000 x 2000 cells, 98 % unknown early on) the
    unknown rows are the work: a C-contiguous map whose rows are whole 8-byte words is read a
    word at a time (2.4 -> ~0.7 ms a call); the known rows' sides stop at the first known cell."""
    ny, nx = costs.shape
    if costs.flags.c_contiguous and nx % 8 == 0 and nx > 0:
        y0, yn = _known_rows(costs.view(np.uint64), _ALL_UNKNOWN)
    else:
        y0, yn = _known_rows(costs, np.uint8(COST_UNKNOWN_ROS))
    if y0 >= yn:
        return 0, 0, 0, 0
    x0, xn = _known_columns(costs, y0, yn)
    return x0, y0, xn, yn


#: eight unknown cells read as one word
_ALL_UNKNOWN = np.uint64(0xFFFFFFFFFFFFFFFF)


@njit(cache=True)
def _known_rows(rows, unknown):
    """(y0, yn): the first row holding a value other than ``unknown`` and one past the last
    (y0 == yn when there is none); ``rows`` (ny, m) the map's cells (uint8, unknown 255) or its
    words (uint64, eight unknown cells all ones)."""
    ny = rows.shape[0]
    y0 = 0
    while y0 < ny and _all_equal(rows[y0], unknown):
        y0 += 1
    yn = ny
    while yn > y0 and _all_equal(rows[yn - 1], unknown):
        yn -= 1
    return y0, yn


@njit(cache=True)
def _all_equal(row, value):
    # a loop that stops at the first other value: numba compiles no all() over a generator
    for k in range(row.shape[0]):  # noqa: SIM110
        if row[k] != value:
            return False
    return True


@njit(cache=True)
def _known_columns(costs, y0, yn):
    """(x0, xn): the known cells' columns over rows y0..yn, each row read from both sides only
    as far as the bounds so far."""
    nx = costs.shape[1]
    x0 = nx
    xn = 0
    for y in range(y0, yn):
        row = costs[y]
        for x in range(min(x0, nx)):
            if row[x] != COST_UNKNOWN_ROS:
                x0 = x
                break
        for x in range(nx - 1, xn - 1, -1):
            if row[x] != COST_UNKNOWN_ROS:
                xn = x + 1
                break
    return x0, xn


@njit(cache=True, error_model="numpy")  # no zero-division checks: costs are >= 50
def navfn_potential(costarr, nx, goal, start, at_start, cycles):
    """Potential from ``goal`` by navfn's Dijkstra-like wavefront (propNavFnDijkstra).

    Each cell's potential comes from its 4-neighbours by navfn's quadratic approximation of the
    Eikonal update (updateCell); cells are processed in bands of ``PRIORITY_INCREMENT``: the
    current buffer, the next buffer (below the band threshold) and the overflow buffer, three
    flat index arrays with a ``pending`` flag per cell, as navfn keeps them. The update is
    written out inline (one pass over the current buffer, the neighbour's cost read once),
    which gives navfn's potentials bit for bit at about twice the speed of a helper per push.

    Parameters
    ----------
    costarr : (ns,) uint8 from `navfn_costs` (its outer ring is COST_OBS, so the 4-neighbours
        of any processed cell are inside the grid).
    nx : grid width in cells.
    goal : flat index where the potential is 0 (navfn's goal: the robot for NavfnROS).
    start : flat index whose potential ends the search when ``at_start``.
    cycles : maximum number of band-processing cycles.

    Returns
    -------
    potential : (ns,) float32, POT_HIGH where unreached.
    finished : False when the cycle budget ran out.
    """
    ns = costarr.shape[0]
    pot = np.full(ns, POT_HIGH, dtype=np.float32)
    pending = np.zeros(ns, dtype=np.bool_)
    cur = np.empty(ns, dtype=np.int32)
    nxt = np.empty(ns, dtype=np.int32)
    over = np.empty(ns, dtype=np.int32)
    n_cur = 0
    n_next = 0
    n_over = 0
    cur_t = np.float32(COST_OBS)
    inc = np.float32(PRIORITY_INCREMENT)
    c_a = np.float32(-0.2301)
    c_b = np.float32(0.5307)
    c_c = np.float32(0.7040)
    pot[goal] = 0.0
    for n in (goal + 1, goal - 1, goal - nx, goal + nx):
        if 0 <= n < ns and not pending[n] and costarr[n] < COST_OBS:
            cur[n_cur] = n
            pending[n] = True
            n_cur += 1
    cycle = 0
    while cycle < cycles:
        if n_cur == 0 and n_next == 0:
            break
        for i in range(n_cur):
            pending[cur[i]] = False
        for i in range(n_cur):
            n = cur[i]
            cn = costarr[n]
            if cn >= COST_OBS:
                continue
            left = pot[n - 1]
            right = pot[n + 1]
            up = pot[n - nx]
            down = pot[n + nx]
            tc = left if left < right else right
            ta = up if up < down else down
            hf = np.float32(cn)
            dc = tc - ta
            if dc < 0:
                dc = -dc
                ta = tc
            if dc >= hf:
                p = ta + hf
            else:
                d = dc / hf
                p = ta + hf * (c_a * d * d + c_b * d + c_c)
            if p < pot[n]:
                pot[n] = p
                # neighbours whose potential this cell can lower go to the next band (below
                # the threshold) or the overflow band
                low = p < cur_t
                buf = nxt if low else over
                nb = n_next if low else n_over
                m = n - 1
                cm = costarr[m]
                if cm < COST_OBS and not pending[m] and left > p + INV_SQRT2 * np.float32(cm):
                    buf[nb] = m
                    pending[m] = True
                    nb += 1
                m = n + 1
                cm = costarr[m]
                if cm < COST_OBS and not pending[m] and right > p + INV_SQRT2 * np.float32(cm):
                    buf[nb] = m
                    pending[m] = True
                    nb += 1
                m = n - nx
                cm = costarr[m]
                if cm < COST_OBS and not pending[m] and up > p + INV_SQRT2 * np.float32(cm):
                    buf[nb] = m
                    pending[m] = True
                    nb += 1
                m = n + nx
                cm = costarr[m]
                if cm < COST_OBS and not pending[m] and down > p + INV_SQRT2 * np.float32(cm):
                    buf[nb] = m
                    pending[m] = True
                    nb += 1
                if low:
                    n_next = nb
                else:
                    n_over = nb
        # swap current and next bands; when both are empty, raise the threshold
        cur, nxt = nxt, cur
        n_cur = n_next
        n_next = 0
        if n_cur == 0:
            cur_t += inc
            cur, over = over, cur
            n_cur = n_over
            n_over = 0
        cycle += 1
        if at_start and pot[start] < POT_HIGH:
            break
    return pot, cycle < cycles


@njit(cache=True)
def _grad_cell(pot, nx, ns, n):
    """navfn's normalised gradient at cell ``n`` (NavFn::gradCell): (0, 0) on the grid's first
    and last rows.

    navfn caches each cell's gradient in two arrays of the grid's size; the descent touches a
    few thousand cells, so computing the four it needs at each step costs less than zeroing
    those arrays for every plan (~1 ms on a 1000 x 800 window), and gives the same values."""
    if n < nx or n > ns - nx:
        return 0.0, 0.0
    cv = pot[n]
    dx = 0.0
    dy = 0.0
    if cv >= POT_HIGH:
        if pot[n - 1] < POT_HIGH:
            dx = -COST_OBS
        elif pot[n + 1] < POT_HIGH:
            dx = COST_OBS
        if pot[n - nx] < POT_HIGH:
            dy = -COST_OBS
        elif pot[n + nx] < POT_HIGH:
            dy = COST_OBS
    else:
        if pot[n - 1] < POT_HIGH:
            dx += pot[n - 1] - cv
        if pot[n + 1] < POT_HIGH:
            dx += cv - pot[n + 1]
        if pot[n - nx] < POT_HIGH:
            dy += pot[n - nx] - cv
        if pot[n + nx] < POT_HIGH:
            dy += cv - pot[n + nx]
    norm = math.hypot(dx, dy)
    if norm > 0:
        # stored as float32 in navfn's arrays
        return np.float32(dx / norm), np.float32(dy / norm)
    return 0.0, 0.0


#: steps of the gradient descent in one base cell taken as an oscillation (`navfn_path`): along
#: a steady gradient 0.5-cell steps cross the cell's offset window (+-1) within 5 steps
#: straight and 6 diagonally
STUCK_STEPS = 8


@njit(cache=True)
def navfn_path(pot, nx, start_x, start_y, goal_x, goal_y, max_steps, step):
    """Descend the potential from (start_x, start_y) to the zero-potential goal (calcPath).

    Follows the bilinearly interpolated normalised gradient in steps of ``step`` cells; near
    unreached cells or on oscillation it moves to the lowest 8-neighbour instead. Oscillation
    is navfn's (a point repeated two steps later, exactly) or, a fleetsim addition, a descent
    that stays in one cell for `STUCK_STEPS` steps: on the edge of a plateau (a parked robot's
    252 cells from the robots layer, no inflation round them) the interpolated gradient turns
    back and forth inside one cell, never exactly repeating a point, until ``max_steps`` runs
    out and the plan fails (a jackal on the circle of 16 had its goal aborted so).

    Returns
    -------
    (N, 2) float64 path in cell coordinates (x, y), start first, ending at the goal cell;
    (0, 2) when the descent fails (no gradient, unreached potential, too many steps).
    """
    ns = pot.shape[0]
    path = np.empty((max_steps + 1, 2))
    npath = 0
    stc = start_y * nx + start_x
    dx = 0.0
    dy = 0.0
    cell = -1
    stay = 0  # points of the path in this cell after the first
    for _ in range(max_steps):
        near = stc + round(dx) + nx * round(dy)
        near = max(0, min(ns - 1, near))
        if pot[near] < 50:  # COST_NEUTRAL: reached the goal's cell
            path[npath, 0] = goal_x
            path[npath, 1] = goal_y
            return path[: npath + 1].copy()
        if stc < nx or stc > ns - nx:
            return path[:0].copy()
        path[npath, 0] = stc % nx + dx
        path[npath, 1] = stc // nx + dy
        npath += 1  # noqa: SIM113
        if stc == cell:
            stay += 1
        else:
            cell = stc
            stay = 0
        oscillation = stay >= STUCK_STEPS or (
            npath > 2
            and path[npath - 1, 0] == path[npath - 3, 0]
            and path[npath - 1, 1] == path[npath - 3, 1]
        )
        stcnx = stc + nx
        stcpx = stc - nx
        if (
            pot[stc] >= POT_HIGH
            or pot[stc + 1] >= POT_HIGH
            or pot[stc - 1] >= POT_HIGH
            or pot[stcnx] >= POT_HIGH
            or pot[stcnx + 1] >= POT_HIGH
            or pot[stcnx - 1] >= POT_HIGH
            or pot[stcpx] >= POT_HIGH
            or pot[stcpx + 1] >= POT_HIGH
            or pot[stcpx - 1] >= POT_HIGH
            or oscillation
        ):
            minc = stc
            minp = pot[stc]
            for cand in (
                stcpx - 1, stcpx, stcpx + 1, stc - 1, stc + 1, stcnx - 1, stcnx, stcnx + 1
            ):  # fmt: skip
                if pot[cand] < minp:
                    minp = pot[cand]
                    minc = cand
            stc = minc
            dx = 0.0
            dy = 0.0
            if pot[stc] >= POT_HIGH:
                return path[:0].copy()
        else:
            gx00, gy00 = _grad_cell(pot, nx, ns, stc)
            gx10, gy10 = _grad_cell(pot, nx, ns, stc + 1)
            gx01, gy01 = _grad_cell(pot, nx, ns, stcnx)
            gx11, gy11 = _grad_cell(pot, nx, ns, stcnx + 1)
            x1 = (1.0 - dx) * gx00 + dx * gx10
            x2 = (1.0 - dx) * gx01 + dx * gx11
            x = (1.0 - dy) * x1 + dy * x2
            y1 = (1.0 - dx) * gy00 + dx * gy10
            y2 = (1.0 - dx) * gy01 + dx * gy11
            y = (1.0 - dy) * y1 + dy * y2
            if x == 0.0 and y == 0.0:
                return path[:0].copy()
            ss = step / math.hypot(x, y)
            dx += x * ss
            dy += y * ss
            if dx > 1.0:
                stc += 1
                dx -= 1.0
            if dx < -1.0:
                stc -= 1
                dx += 1.0
            if dy > 1.0:
                stc += nx
                dy -= 1.0
            if dy < -1.0:
                stc -= nx
                dy += 1.0
    return path[:0].copy()
