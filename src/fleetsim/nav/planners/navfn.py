"""NavFn (navfn/NavfnROS): potential-field global planner on the global costmap.

As NavfnROS::makePlan: the potential is propagated from the robot's cell (potential 0) until
it reaches the goal cell; with ``default_tolerance`` the reachable point nearest the goal
within a square of that half-size is used instead; the path is extracted by gradient descent
from the goal down to the robot and returned robot-first, ending with the goal pose.
Path points are cell centres (navfn places them at cell corners, half a cell off).

``circumscribed_clearance`` (a fleetsim addition, off by default as in ROS): navfn treats only
cells at or above the inscribed cost as obstacles, so with a rectangular footprint its path may
run through a gap the body passes straight but cannot turn in (a lizi, 0.32 m wide, through
0.4 m between Willow's clutter, where the path bends): the local planner then meets a wedge that
ROS's recoveries (clear, rotate in place) cannot undo. With the option the planner first plans
on cells below costmap_2d's circumscribed cost (the cost at the footprint's circumscribed
radius, where the body clears obstacles in any heading), except within that radius of the start
and the goal (the robot may stand, and a goal may lie, nearer a wall); only where no such path
exists does it plan as ROS does, through the narrower gaps.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fleetsim.nav.costmap.costmap_2d import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from fleetsim.nav.errors import pose_text
from fleetsim.nav.planners.base import (
    GlobalPlanner,
    GoalOccupied,
    GoalOutsideMap,
    NoPathFound,
    Path,
    PlannerTimeout,
    StartOccupied,
    StartOutsideMap,
)
from fleetsim.nav.planners.navfn_kernels import (
    COST_OBS,
    POT_HIGH,
    known_bounds,
    navfn_costs,
    navfn_path,
    navfn_potential,
)
from fleetsim.runtime import param


@dataclass(frozen=True)
class NavfnParams:
    """Parameters of ``navfn/NavfnROS`` (in move_base's ``NavfnROS/`` namespace)."""

    allow_unknown: bool = param(True, help="plan through unknown cells (at high cost)")
    default_tolerance: float = param(
        0.0, unit="m", range=(0.0, None), help="accept the reachable point nearest the goal"
    )
    visualize_potential: bool = param(False, help="publish the potential field")
    planner_window_x: float = param(
        0.0, unit="m", range=(0.0, None), help="plan only in a window this wide (0: whole map)"
    )
    planner_window_y: float = param(
        0.0, unit="m", range=(0.0, None), help="plan only in a window this tall (0: whole map)"
    )
    circumscribed_clearance: bool = param(
        False,
        help="fleetsim: plan first where the footprint can turn (below the circumscribed cost), "
        "through narrower gaps only if no such path exists",
    )


#: unknown cells around the known part of the costmap navfn plans in first, m, and per metre
#: of straight line from the robot to the goal (`NavFn._known_part`)
PART_MARGIN = 2.0
PART_REACH = 0.5


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class NavFn(GlobalPlanner):
    """navfn's planner. After each plan, ``potential`` holds the (ny, nx) field (float32)."""

    Params = NavfnParams

    def __init__(
        self, costmap: Costmap2D, params: NavfnParams | None = None, frame_id: str = "map"
    ) -> None:
        super().__init__(costmap, frame_id)
        self.params = params or NavfnParams()
        self.potential: np.ndarray | None = None
        self.window: tuple[int, int, int, int] = (0, 0, costmap.size_x, costmap.size_y)
        #: (cost, radius in m) at the footprint's circumscribed radius, set by the costmap's
        #: owner (`set_circumscribed`); cost 0: unknown, ``circumscribed_clearance`` is inert
        self.circumscribed: tuple[int, float] = (0, 0.0)
        #: the costmap's update count, when its owner gives one (`Costmap2DROS.update_count`):
        #: the known cells' bounds are then read once per update, not once per plan (a 5 Hz
        #: planner on a 1 Hz costmap; ~1.2 ms a read of a 2000 x 2000 SLAM map). A write
        #: between updates (a recovery's clearing) can leave them stale, which costs time only:
        #: a plan on the known part is kept only where the whole window gives it bit for bit
        self.costmap_revision: Callable[[], int] | None = None
        self._known: tuple[tuple, tuple[int, int, int, int]] | None = None

    def set_circumscribed(self, cost: int, radius: float) -> None:
        """costmap_2d's circumscribed cost and radius (m), for ``circumscribed_clearance``."""
        self.circumscribed = (int(cost), float(radius))

    def _window(self, sx: int, sy: int) -> tuple[int, int, int, int]:
        m, p = self.costmap, self.params
        x0, y0, xn, yn = 0, 0, m.size_x, m.size_y
        if p.planner_window_x > 0:
            half = m.cell_distance(p.planner_window_x / 2)
            x0, xn = max(0, sx - half), min(m.size_x, sx + half + 1)
        if p.planner_window_y > 0:
            half = m.cell_distance(p.planner_window_y / 2)
            y0, yn = max(0, sy - half), min(m.size_y, sy + half + 1)
        return x0, y0, xn, yn

    def create_plan(self, start: tuple[float, ...], goal: tuple[float, ...]) -> Path:
        m, p = self.costmap, self.params
        sx_w, sy_w = float(start[0]), float(start[1])
        gx_w, gy_w = float(goal[0]), float(goal[1])
        goal_yaw = float(goal[2]) if len(goal) > 2 else 0.0
        s_cell = m.world_to_map(sx_w, sy_w)
        if s_cell is None:
            raise StartOutsideMap(
                f"navfn: the robot's start {pose_text(sx_w, sy_w)} is off the global costmap "
                f"({self._extent()}); is the robot localized?"
            )
        if m.costs[s_cell[1], s_cell[0]] == LETHAL_OBSTACLE:
            raise StartOccupied(
                f"navfn: the robot's start {pose_text(sx_w, sy_w)} is inside an obstacle "
                "(lethal cell); clear the costmaps or move the robot"
            )
        if m.world_to_map(gx_w, gy_w) is None:
            raise GoalOutsideMap(
                f"navfn: the goal {pose_text(gx_w, gy_w)} is off the global costmap "
                f"({self._extent()})"
            )
        full = self._window(*s_cell)
        x0, y0, xn, yn = full
        res = m.resolution
        # the reachable point nearest the goal within the tolerance square (cells, not metres)
        tol = p.default_tolerance
        n_tol = math.floor(tol / res + 1e-9)
        offsets = np.arange(-n_tol, n_tol + 1) * res
        cand = np.stack(np.meshgrid(gx_w + offsets, gy_w + offsets), axis=-1).reshape(-1, 2)
        cells, inside = m.cells_of(cand)
        inside &= (
            (cells[:, 0] >= x0) & (cells[:, 0] < xn) & (cells[:, 1] >= y0) & (cells[:, 1] < yn)
        )
        if not inside.any():
            raise GoalOutsideMap(
                f"navfn: the goal {pose_text(gx_w, gy_w)} is outside the planner window "
                f"(planner_window_x/y {p.planner_window_x:g} x {p.planner_window_y:g} m)"
            )
        cand, cells = cand[inside], cells[inside]
        order = np.argsort(((cand - [gx_w, gy_w]) ** 2).sum(axis=1), kind="stable")
        cand, cells = cand[order], cells[order]
        goal_cell = cells[0]

        # navfn's own cycle budget, of the whole window (NavFn::calcNavFnDijkstra)
        cycles = max((xn - x0) * (yn - y0) // 20, (xn - x0) + (yn - y0))
        pot, finished = None, False
        part = self._known_part(full, s_cell, cells)
        if part != full:
            # None: a wavefront reached the part's edge; then the whole window, as ROS plans
            pot, finished = self._potential(part, s_cell, goal_cell, cells, cycles, full)
        if pot is None:
            pot, finished = self._potential(full, s_cell, goal_cell, cells, cycles, full)
        x0, y0, xn, yn = self.window
        nx = xn - x0
        reached = pot[(cells[:, 1] - y0) * nx + (cells[:, 0] - x0)] < POT_HIGH
        if not reached.any() and finished and self._in_inscribed(s_cell):
            # the robot stands where its centre is in inscribed space: a way out first
            self.window = x0, y0, xn, yn = full
            nx = xn - x0
            pot, finished = self._escape_potential(s_cell, goal_cell, cycles)
            reached = pot[(cells[:, 1] - y0) * nx + (cells[:, 0] - x0)] < POT_HIGH
        if not reached.any():
            if not finished:
                raise PlannerTimeout(
                    f"navfn: the potential did not reach the goal {pose_text(gx_w, gy_w)} "
                    f"within {cycles} propagation cycles"
                )
            self._raise_unreachable(cells, gx_w, gy_w, sx_w, sy_w)
        best = int(np.argmax(reached))
        bx, by = int(cells[best, 0]) - x0, int(cells[best, 1]) - y0
        # NavfnROS uses 4 * size_x, too short for tall maps; of the whole window, as cycles
        steps = 4 * ((full[2] - full[0]) + (full[3] - full[1]))
        cells_path = navfn_path(pot, nx, bx, by, s_cell[0] - x0, s_cell[1] - y0, steps, 0.5)
        if cells_path.shape[0] == 0:
            raise NoPathFound(
                f"navfn: no path from {pose_text(sx_w, sy_w)} to {pose_text(gx_w, gy_w)}: the "
                "gradient descent on the potential failed"
            )
        xy = np.empty((cells_path.shape[0] + 1, 2))
        xy[:-1, 0] = m.origin_x + (cells_path[::-1, 0] + x0 + 0.5) * res
        xy[:-1, 1] = m.origin_y + (cells_path[::-1, 1] + y0 + 0.5) * res
        xy[0] = (sx_w, sy_w)
        xy[-1] = cand[best]
        if best == 0:
            xy[-1] = (gx_w, gy_w)
        poses = np.empty((xy.shape[0], 3))
        poses[:, :2] = xy
        d = np.diff(xy, axis=0)
        poses[:-1, 2] = np.arctan2(d[:, 1], d[:, 0])
        poses[-1, 2] = _wrap(goal_yaw)
        return Path(poses, self.frame_id)

    def _potential(
        self, window, s_cell, goal_cell, cells, cycles, full
    ) -> tuple[np.ndarray | None, bool]:
        """navfn's potential over ``window`` (x0, y0, xn, yn cells, which becomes
        ``self.window``) from the robot's cell to ``goal_cell``, first on the roomy costs with
        ``circumscribed_clearance``; (flat potential, finished within ``cycles``). In a part
        of the whole window ``full``: (None, False) when a wavefront ran out of cycles or
        reached the part's cut edges (`_inside`), so that only a run the whole window would
        repeat bit for bit is kept."""
        p = self.params
        x0, y0, xn, yn = self.window = window
        nx = xn - x0
        costarr, start_idx, goal_idx = self._costs(s_cell, goal_cell)
        if p.circumscribed_clearance and self.circumscribed[0] > 0:
            roomy = self._roomy_costs(costarr, s_cell, goal_cell)
            pot, finished = navfn_potential(roomy, nx, start_idx, goal_idx, True, cycles)
            if window != full and not (finished and self._inside(pot, window, full)):
                return None, False
            if (pot[(cells[:, 1] - y0) * nx + (cells[:, 0] - x0)] < POT_HIGH).any():
                self.potential = pot.reshape(yn - y0, nx)
                return pot, finished
            # no roomy path: plan as ROS does
        pot, finished = navfn_potential(costarr, nx, start_idx, goal_idx, True, cycles)
        if window != full and not (finished and self._inside(pot, window, full)):
            return None, False
        self.potential = pot.reshape(yn - y0, nx)
        return pot, finished

    def _known_part(self, full, s_cell, cells) -> tuple[int, int, int, int]:
        """The part of the window ``full`` worth planning in first: the known cells' bounds
        (with the robot's and the goal's cells), widened by `PART_MARGIN` m plus `PART_REACH`
        times the straight line from the robot to the goal (a wavefront runs into unknown cells
        about a fifth as far as through free ones; 0.5 covers ways twice the straight line)."""
        m = self.costmap
        x0, y0, xn, yn = full
        kx0, ky0, kxn, kyn = self._known_bounds(full)
        if kxn <= kx0:
            return full
        bx0, by0, bxn, byn = kx0 + x0, ky0 + y0, kxn + x0, kyn + y0
        xs = (int(s_cell[0]), *cells[:, 0].tolist())
        ys = (int(s_cell[1]), *cells[:, 1].tolist())
        bx0, bxn = min(bx0, *xs), max(bxn, max(xs) + 1)
        by0, byn = min(by0, *ys), max(byn, max(ys) + 1)
        reach = math.hypot(int(cells[0, 0]) - int(s_cell[0]), int(cells[0, 1]) - int(s_cell[1]))
        pad = math.ceil(PART_MARGIN / m.resolution + PART_REACH * reach)
        return (max(x0, bx0 - pad), max(y0, by0 - pad), min(xn, bxn + pad), min(yn, byn + pad))

    def _known_bounds(self, full) -> tuple[int, int, int, int]:
        """`known_bounds` of the window ``full``, kept until the costmap's next update."""
        costs = self.costmap.costs
        if self.costmap_revision is None:
            x0, y0, xn, yn = full
            return known_bounds(costs[y0:yn, x0:xn])
        key = (self.costmap_revision(), id(costs), costs.shape, full)
        if self._known is None or self._known[0] != key:
            x0, y0, xn, yn = full
            self._known = (key, known_bounds(costs[y0:yn, x0:xn]))
        return self._known[1]

    @staticmethod
    def _inside(pot: np.ndarray, part, full) -> bool:
        """Whether the wavefront over ``part`` left untouched the cells next to its cut edges
        (those not edges of ``full``): then the whole window's run processes the same cells in
        the same order, and gives this potential bit for bit (cells outside ``part`` unreached)."""
        x0, y0, xn, yn = part
        grid = pot.reshape(yn - y0, xn - x0)
        edges = []
        if x0 > full[0]:
            edges.append(grid[:, 1])
        if xn < full[2]:
            edges.append(grid[:, -2])
        if y0 > full[1]:
            edges.append(grid[1, :])
        if yn < full[3]:
            edges.append(grid[-2, :])
        return all(bool((e >= POT_HIGH).all()) for e in edges)

    def _costs(self, s_cell, goal_cell) -> tuple[np.ndarray, int, int]:
        """navfn's cost array over ``self.window`` with the robot's cell cleared
        (clearRobotCell), and the start's and the goal's flat indices in it."""
        x0, y0, xn, yn = self.window
        nx = xn - x0
        costarr = navfn_costs(self.costmap.costs[y0:yn, x0:xn], self.params.allow_unknown)
        start_idx = (s_cell[1] - y0) * nx + (s_cell[0] - x0)
        if 0 < s_cell[0] - x0 < nx - 1 and 0 < s_cell[1] - y0 < yn - y0 - 1:
            costarr[start_idx] = navfn_costs(np.zeros((3, 3), np.uint8), True)[4]
        return costarr, start_idx, (goal_cell[1] - y0) * nx + (goal_cell[0] - x0)

    def _within_reach(self, cell) -> np.ndarray:
        """(ny, nx) bool over ``self.window``: the cells within the footprint's circumscribed
        radius plus a cell of ``cell`` (x, y)."""
        x0, y0, xn, yn = self.window
        reach = self.circumscribed[1] / self.costmap.resolution + 1.0
        ys, xs = np.ogrid[y0:yn, x0:xn]
        return (xs - int(cell[0])) ** 2 + (ys - int(cell[1])) ** 2 <= reach * reach

    def _in_inscribed(self, s_cell) -> bool:
        """Whether the robot's cell is inscribed (not lethal) and the planner knows how far the
        footprint reaches (`set_circumscribed`)."""
        c = self.costmap.costs[s_cell[1], s_cell[0]]
        return c == INSCRIBED_INFLATED_OBSTACLE and self.circumscribed[1] > 0

    def _escape_potential(self, s_cell, goal_cell, cycles) -> tuple[np.ndarray, bool]:
        """navfn's potential over ``self.window`` with the inscribed (not lethal) cells within
        the footprint's circumscribed radius of the robot passable at navfn's highest cost
        (a fleetsim addition, tried only where ROS's plan found no way).

        Why: NavfnROS clears the robot's own cell (clearRobotCell) and nothing else. A robot
        whose centre has come into inscribed space (a polygon footprint is checked on its
        outline, so the local planner may drive it there: by a desk, in a door) has only
        inscribed cells round that one, so every plan fails, rotate_recovery cannot turn the
        body, and move_base aborts every goal until the run ends (office, two hunters with
        their padded outline, seeds 1-4 at stop 31). The body is where it is without touching,
        so the cells its centre crosses within the circumscribed radius lead out of that
        space; the local planner checks the footprint along the way as always."""
        x0, y0, xn, yn = self.window
        nx = xn - x0
        costarr, start_idx, goal_idx = self._costs(s_cell, goal_cell)
        near = self._within_reach(s_cell)
        near &= self.costmap.costs[y0:yn, x0:xn] == INSCRIBED_INFLATED_OBSTACLE
        near[[0, -1], :] = False  # navfn's border stays an obstacle
        near[:, [0, -1]] = False
        costarr[near.ravel()] = COST_OBS - 1
        pot, finished = navfn_potential(costarr, nx, start_idx, goal_idx, True, cycles)
        self.potential = pot.reshape(yn - y0, nx)
        return pot, finished

    def _roomy_costs(self, costarr: np.ndarray, s_cell, goal_cell) -> np.ndarray:
        """``costarr`` with the cells at or above the circumscribed cost made obstacles, except
        within the circumscribed radius (plus a cell) of the start and the goal cells."""
        x0, y0, xn, yn = self.window
        window = self.costmap.costs[y0:yn, x0:xn]
        tight = (window >= self.circumscribed[0]) & (window != NO_INFORMATION)  # allow_unknown's
        tight &= ~self._within_reach(s_cell) & ~self._within_reach(goal_cell)
        out = costarr.copy()
        out[tight.ravel()] = COST_OBS
        return out

    def _raise_unreachable(self, cells: np.ndarray, gx: float, gy: float, sx: float, sy: float):
        costs = self.costmap.costs[cells[:, 1], cells[:, 0]]
        blocked = costs >= INSCRIBED_INFLATED_OBSTACLE
        if not self.params.allow_unknown:
            blocked |= costs == NO_INFORMATION
        else:
            blocked &= costs != NO_INFORMATION
        tol = self.params.default_tolerance
        within = f" or within default_tolerance {tol:g} m" if tol > 0 else ""
        if blocked.all():
            what = (
                "unknown space (allow_unknown is false)"
                if (costs == NO_INFORMATION).all()
                else "an obstacle (lethal or inscribed cost)"
            )
            raise GoalOccupied(
                f"navfn: the goal {pose_text(gx, gy)} is in {what}, and no free cell{within}"
            )
        raise NoPathFound(
            f"navfn: no path from {pose_text(sx, sy)} to the goal {pose_text(gx, gy)}{within}: "
            "the goal is not connected to the robot through free space"
        )

    def _extent(self) -> str:
        m = self.costmap
        return (
            f"x {m.origin_x:g}..{m.origin_x + m.size_x * m.resolution:g}, "
            f"y {m.origin_y:g}..{m.origin_y + m.size_y * m.resolution:g} m"
        )
