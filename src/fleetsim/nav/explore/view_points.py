"""Where a robot can see a frontier from: its view point (fleetsim addition, explore's
``view_points``).

explore_lite sends move_base to a frontier's centroid. The centroid of an L-shaped frontier
round a desk lies inside the desk's inflation, and of a thin strip beside it in unknown cells;
and explore_lite measures progress by the straight line to the frontier, which grows while the
robot drives out of one room, along the corridor and into the next. Office, one hunter, seed 1
(traced: every frontier blacklisted, the map it had then, where the robot stood): the last two
frontiers were the 0.75 m mouths of the strips behind two rooms' desks, each next to drivable
cells a 10 m laser sees them from, each blacklisted by the progress check while the hunter was
on its way there, from the next room (7.1, 1.0) and from the corridor (24.9, 1.0): not cells
it could not see, but goals it could not be seen heading for by a straight line.

So, as next-best-view exploration does, each frontier's goal is a *view point*: the cell
nearest its centroid that the robot can drive to (known, cost below the inscribed cost, reached
by `fleetsim.nav.explore.path_costs.path_distance_field` from the robot) from which one of
its cells is within ``view_range`` and in the laser's line of sight (no lethal cell of the
costmap between; unknown cells do not block it, the laser maps them on the way). Where the
centroid is such a cell the view point is the centroid's cell. Progress is then measured by
the wavefront move_base's navfn plans with (``allow_unknown``: through unknown cells too, at
their cost), from the robot to that point, which shrinks all the way there while the robot
follows the plan. When the map shows that a way planned through unknown cells is blocked,
that measure jumps up; the route, not the robot, failed, and the progress clock restarts from
the new measure (office seed 1, with view points measured along known cells only: sent from
inside room 5's door to room 4's desk strip, the hunter drove 3.5 m south into room 5 and the
goal was blacklisted after 30 s; not traced further than that).

A frontier still on the map after the robot has stood at its view point (move_base
reached it) is *observed as far as it can be*: what is left of it no drivable pose in its
neighbourhood sees (the inside of a desk, a gap under a shelf) and driving there again would
not change that; explore then leaves it, and does not count it as given up.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .frontier_search import INSCRIBED, Frontier

#: candidates checked in order of distance before falling back to sorting them all
_NEAREST_FIRST = 64


@numba.njit(cache=True)
def _sees(blocked: np.ndarray, y0: int, x0: int, y1: int, x1: int) -> bool:
    """Whether the cell (y1, x1) is in line of sight of (y0, x0): no blocked cell on the
    Bresenham line between them (the ends excluded)."""
    dx, dy = abs(x1 - x0), -abs(y1 - y0)
    sx = 1 if x0 < x1 else -1
    sy = 1 if y0 < y1 else -1
    err = dx + dy
    x, y = x0, y0
    while True:
        if x == x1 and y == y1:
            return True
        if (x != x0 or y != y0) and blocked[y, x]:
            return False
        e2 = 2 * err
        if e2 >= dy:
            err += dy
            x += sx
        if e2 <= dx:
            err += dx
            y += sy


@numba.njit(cache=True)
def _first_seeing(
    blocked: np.ndarray,
    cand_y: np.ndarray,
    cand_x: np.ndarray,
    cell_y: np.ndarray,
    cell_x: np.ndarray,
    range_cells: float,
) -> int:
    """Index of the first candidate (in the given order) that sees one of the cells within
    ``range_cells``; -1 if none does."""
    r2 = range_cells * range_cells
    for i in range(cand_y.shape[0]):
        for j in range(cell_y.shape[0]):
            ddy = cell_y[j] - cand_y[i]
            ddx = cell_x[j] - cand_x[i]
            if ddy * ddy + ddx * ddx <= r2 and _sees(
                blocked, cand_y[i], cand_x[i], cell_y[j], cell_x[j]
            ):
                return i
    return -1


def view_point(
    field: np.ndarray,
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    frontier: Frontier,
    view_range: float,
) -> tuple[float, float] | None:
    """The frontier's view point (m, the grid's frame), or None when no cell the robot can
    drive to sees one of its cells within ``view_range`` m.

    Parameters
    ----------
    field : (H, W) float, metres of driving from the robot to each cell, inf where it cannot
        go (`fleetsim.nav.explore.path_costs.path_distance_field` of ``data``); view points are
        known cells of cost below the inscribed cost where it is finite.
    data : (H, W) int8, the published costmap (100 lethal: blocks the line of sight).
    resolution, origin : the grid's cell size (m) and lower-left corner (m).
    frontier : one frontier of ``data``; its cells are ``frontier.points`` (N, 2) m.
    view_range : m, at most the laser's range.
    """
    h, w = data.shape
    cx = np.floor((frontier.points[:, 0] - origin[0]) / resolution).astype(np.int64)
    cy = np.floor((frontier.points[:, 1] - origin[1]) / resolution).astype(np.int64)
    reach = math.ceil(view_range / resolution)
    x0, x1 = max(int(cx.min()) - reach, 0), min(int(cx.max()) + reach + 1, w)
    y0, y1 = max(int(cy.min()) - reach, 0), min(int(cy.max()) + reach + 1, h)
    if x0 >= x1 or y0 >= y1:
        return None
    # every line of sight within range runs inside the window: work in its cells
    known = data[y0:y1, x0:x1]
    drivable = np.isfinite(field[y0:y1, x0:x1]) & (known >= 0) & (known < INSCRIBED)
    ys, xs = np.nonzero(drivable)
    if len(ys) == 0:
        return None
    blocked = data[y0:y1, x0:x1] == 100
    cy, cx = cy - y0, cx - x0
    gx = (frontier.centroid[0] - origin[0]) / resolution - 0.5 - x0
    gy = (frontier.centroid[1] - origin[1]) / resolution - 0.5 - y0
    d2 = (xs - gx) ** 2 + (ys - gy) ** 2
    cells = float(view_range / resolution)
    k = min(_NEAREST_FIRST, len(d2))
    near = np.argpartition(d2, k - 1)[:k]
    near = near[np.lexsort((near, d2[near]))]  # ties in the grid's order: a goal that stays
    i = _first_seeing(blocked, ys[near], xs[near], cy, cx, cells)
    if i < 0 and k < len(d2):
        rest = np.argsort(d2, kind="stable")[k:]
        i, near = _first_seeing(blocked, ys[rest], xs[rest], cy, cx, cells), rest
    if i < 0:
        return None
    y, x = int(ys[near[i]]) + y0, int(xs[near[i]]) + x0
    return (origin[0] + (x + 0.5) * resolution, origin[1] + (y + 0.5) * resolution)


def cell_value(
    field: np.ndarray, resolution: float, origin: tuple[float, float], point: tuple[float, float]
) -> float:
    """``field`` at the cell holding ``point`` (m); inf off the grid."""
    h, w = field.shape
    x = int(np.floor((point[0] - origin[0]) / resolution))
    y = int(np.floor((point[1] - origin[1]) / resolution))
    if 0 <= x < w and 0 <= y < h:
        return float(field[y, x])
    return math.inf
