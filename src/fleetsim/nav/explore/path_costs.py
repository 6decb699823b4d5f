"""How far a robot drives to each frontier: move_base's own wavefront over the costmap
(fleetsim addition, explore's ``path_costs``).

explore_lite measures a frontier's distance as the straight line from the robot to its nearest
cell. In an office of rooms off a corridor that line goes through walls: a frontier in the next
room is 5 m away in a straight line and 15-20 m by the door, so two explorers sharing a map by
straight-line distance gave the next room's frontiers to the robot on the wrong side of the wall
(office, two hunters, seed 2: hunter1 in one bottom room spent 88 s on two frontiers of the next
one, both blacklisted, and at the end waited in the far corner of the office, 29 m of driving
from the last frontier, while the other robot, 20 m from it, waited for it to get there).

The distances here are those of navfn's potential (`fleetsim.nav.planners.navfn_kernels`, the
same wavefront move_base plans with), spread from the robot's cell over the cells a robot's
centre may occupy (cost below the inscribed cost; unknown cells are not entered) and read at the
free 4-neighbours of each frontier's cells. navfn charges ``COST_NEUTRAL`` per free cell and
more near obstacles, so ``potential / COST_NEUTRAL * resolution`` is metres of free driving,
somewhat more where the way passes close to walls, as the planner's own paths do.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from scipy import ndimage

from fleetsim.nav.costmap.layered_costmap import costs_from_published
from fleetsim.nav.planners.navfn_kernels import (
    COST_NEUTRAL,
    POT_HIGH,
    navfn_costs,
    navfn_potential,
)

from .frontier_search import INSCRIBED, Frontier

#: navfn's cycle budget for a whole field (it stops earlier when every cell is reached)
_CYCLES = 10**8


def path_distance_field(
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    start: tuple[float, float],
    allow_unknown: bool = False,
) -> np.ndarray:
    """(H, W) float: metres of driving from ``start`` (m, in the grid's frame) to every cell of
    the published costmap grid ``data`` (H, W) int8, inf where the robot cannot go.

    A start off the grid reaches nothing; a start on a cell of inscribed cost or more (a robot
    brushing a wall in the costmap) starts from the nearest cell below it, as explore_lite's
    frontier search does. ``allow_unknown``: through unknown cells too, at navfn's cost for
    them (``COST_OBS - 1``, about five free cells' worth each), as move_base's navfn with its
    ``allow_unknown`` plans: the field then ranks ways as the planner does, in free-driving
    metres where the way is known."""
    data = np.asarray(data)
    h, w = data.shape
    out = np.full((h, w), np.inf)
    sx = int(np.floor((start[0] - origin[0]) / resolution))
    sy = int(np.floor((start[1] - origin[1]) / resolution))
    passable = (data >= 0) & (data < INSCRIBED)
    if not (0 <= sx < w and 0 <= sy < h) or not passable.any():
        return out
    if not passable[sy, sx]:
        _, (iy, ix) = ndimage.distance_transform_edt(~passable, return_indices=True)
        sy, sx = int(iy[sy, sx]), int(ix[sy, sx])
    costarr = navfn_costs(costs_from_published(data), allow_unknown)
    pot, _ = navfn_potential(costarr, w, sy * w + sx, 0, False, _CYCLES)
    pot = pot.reshape(h, w).astype(np.float64)
    reached = pot < POT_HIGH
    out[reached] = pot[reached] / COST_NEUTRAL * resolution
    return out


def frontier_distances(
    field: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    frontiers: Sequence[Frontier],
) -> np.ndarray:
    """(F,) metres from the field's start to each frontier: the least of ``field`` (from
    `path_distance_field`) over the 4-neighbours of the frontier's cells, plus one cell (the
    step onto the frontier); inf for a frontier the field does not reach."""
    h, w = field.shape
    out = np.full(len(frontiers), np.inf)
    for i, f in enumerate(frontiers):
        cx = np.floor((f.points[:, 0] - origin[0]) / resolution).astype(int)
        cy = np.floor((f.points[:, 1] - origin[1]) / resolution).astype(int)
        best = np.inf
        for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
            ny, nx = cy + dy, cx + dx
            inside = (ny >= 0) & (ny < h) & (nx >= 0) & (nx < w)
            if inside.any():
                best = min(best, float(field[ny[inside], nx[inside]].min()))
        out[i] = best + resolution
    return out


def by_path(
    data: np.ndarray,
    resolution: float,
    origin: tuple[float, float],
    frontiers: Sequence[Frontier],
    robots: Sequence[tuple[float, float]],
    potential_scale: float,
    gain_scale: float,
    own_field: np.ndarray | None = None,
) -> tuple[list[Frontier], np.ndarray]:
    """The frontiers ranked by explore_lite's cost with the distance the first of ``robots``
    drives in place of the straight line, and the (F, R) metres each robot drives to each (in
    the new order; inf: cannot reach it).

    The returned frontiers are copies whose ``cost`` is the path cost; ``min_distance`` stays
    explore_lite's straight line (explore's ``view_points`` measures progress along the path to
    the frontier's view point instead, `fleetsim.nav.explore.view_points`). A frontier the
    robot's own field does not reach keeps its straight-line cost. ``own_field``: the first
    robot's `path_distance_field`, when the caller has it already."""
    fields = [
        own_field if i == 0 and own_field is not None
        else path_distance_field(data, resolution, origin, r)
        for i, r in enumerate(robots)
    ]  # fmt: skip
    dist = np.column_stack(
        [frontier_distances(f, resolution, origin, frontiers) for f in fields]
    ).reshape(len(frontiers), len(robots))
    own = np.array([f.min_distance for f in frontiers])
    own = np.where(np.isfinite(dist[:, 0]), dist[:, 0], own)
    sizes = np.array([f.size for f in frontiers])
    costs = potential_scale * own * resolution - gain_scale * sizes * resolution
    order = np.argsort(costs, kind="stable")
    ranked = [replace(frontiers[i], cost=float(costs[i])) for i in order]
    return ranked, dist[order]
