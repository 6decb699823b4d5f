"""Where a robot that yields goes: back along its own plan to a place wide enough for the robot
it yields to to pass, and there aside, to its right.

`DeadlockRule` decides who yields (every robot computes the same verdict); this module decides
how. Backing away from the other robot for a fixed time does not clear a passage too narrow for
two (the reference measurement: RVO2 never finishes a 0.6 m corridor, and a short back-off only
restarts the standoff). The yielding robot therefore retreats along the path it came by (known to
be free) until the passage is wide enough for both, steps aside there and waits until the other
robot has gone by:

* `passage_width`: the free width across a direction at a point, from the costmap's lethal cells
  (the clear distance to each side, each capped);
* `too_narrow`: two robots cannot pass each other here;
* `head_on`: the robots ahead that face us and are not drawing away;
* `narrow_between`: somewhere between two robots facing each other the
  passage is too narrow for both (the deadlock rule decides at once who yields, instead of
  waiting for no progress: ORCA slows a pair in such a passage to a creep that keeps making a
  little progress, and every second of it is one more the yielder has to back out);
* `refuge`: walking back along the plan from the robot's place, the first plan point where the
  width allows both robots, moved aside to its right as far as the walls allow; while no such
  point lies inside the (rolling) local costmap, the farthest plan point back that does, so the
  robot keeps retreating and finds the wide place when it comes into view, or ends at the far
  end of its trail when there is none;
* `has_passed`: the robot yielded to is behind the yielding one along its way to the goal, clear
  of it; `out_of_way`: it is far off to the side of the yielding one's plan ahead;
* `Retreat`: one robot's trail (the way it came, which a replanned path does not keep: it
  starts where the robot stands; kept across goals) and its refuge while it yields.
"""

from __future__ import annotations

import math

import numpy as np

from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE

#: m between the points of a robot's trail, and how many it keeps (the last 40 m)
TRAIL_STEP = 0.1
TRAIL_POINTS = 400
#: m between the probes of `passage_width`
PROBE_STEP = 0.025
#: m/s: a robot drawing away from us faster than this is not met head-on
RECEDING_SPEED = 0.05
#: m a yielding robot waits farther back than the first place wide enough (`refuge`)
REFUGE_SETBACK = 0.6
#: m of the way (plan or trail) over which its direction at a point is taken
HEADING_BASE = 0.3
#: m from the refuge that count as there (closer, a skid steer only turns on the spot)
REFUGE_TOLERANCE = 0.15
#: cells around a probe that count: a wall a laser marks at a grazing angle is a dotted line,
#: and a probe would pass between the dots
PROBE_CELLS = 2


def clear_distance(
    costs: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    point: np.ndarray,
    direction: np.ndarray,
    reach: float,
) -> float:
    """Distance (m) from ``point`` along the unit ``direction`` to the first lethal cell within
    ``PROBE_CELLS`` cells of the line, at most ``reach``; leaving the costmap counts as clear
    (the rolling window ends, not the world).

    costs : (H, W) uint8 costmap; origin : its lower-left corner, m; point, direction : (2,).
    """
    steps = np.arange(PROBE_STEP, reach + 1e-9, PROBE_STEP)
    xs = point[0] + direction[0] * steps
    ys = point[1] + direction[1] * steps
    k = np.arange(-PROBE_CELLS, PROBE_CELLS + 1)
    cols = np.floor((xs - origin[0]) / resolution).astype(int)[:, None, None] + k[None, None, :]
    rows = np.floor((ys - origin[1]) / resolution).astype(int)[:, None, None] + k[None, :, None]
    cols, rows = np.broadcast_arrays(cols, rows)
    inside = (cols >= 0) & (cols < costs.shape[1]) & (rows >= 0) & (rows < costs.shape[0])
    lethal = np.zeros(cols.shape, dtype=bool)
    lethal[inside] = costs[rows[inside], cols[inside]] >= LETHAL_OBSTACLE
    hit = lethal.any(axis=(1, 2))
    if not hit.any():
        return float(reach)
    # the probe met the wall's dilation: the wall itself is PROBE_CELLS cells farther
    return min(float(steps[int(np.argmax(hit))] - PROBE_STEP + PROBE_CELLS * resolution), reach)


def passage_width(
    costs: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    point: np.ndarray,
    heading: np.ndarray,
    reach: float,
) -> tuple[float, float]:
    """(left, right) clear distances (m) across the unit ``heading`` at ``point``, each at most
    ``reach``; their sum is the passage's width there."""
    left = np.array([-heading[1], heading[0]])
    return (
        clear_distance(costs, origin, resolution, point, left, reach),
        clear_distance(costs, origin, resolution, point, -left, reach),
    )


def width_needed(own_radius: float, other_radius: float, margin: float = 0.1) -> float:
    """m of free width for two robots (safety radii, m) to pass each other, ``margin`` apart."""
    return 2.0 * (own_radius + other_radius) + margin


def too_narrow(
    costs: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    point: np.ndarray,
    heading: np.ndarray,
    own_radius: float,
    other_radius: float,
) -> bool:
    """The passage across the unit ``heading`` at ``point`` is too narrow for two robots."""
    need = width_needed(own_radius, other_radius)
    return sum(passage_width(costs, origin, resolution, point, heading, need)) < need


def narrow_between(
    costs: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    point: np.ndarray,
    other: np.ndarray,
    own_radius: float,
    other_radius: float,
    step: float = 0.25,
) -> bool:
    """The passage is too narrow for two robots somewhere on the straight way from ``point``
    to ``other`` (both (2,), m; ``step`` m between the probes), measured across that way."""
    way = np.asarray(other, dtype=np.float64) - point
    n = float(np.hypot(*way))
    if n < 1e-9:
        return False
    heading = way / n
    for s in np.arange(0.0, n + 1e-9, step):
        if too_narrow(
            costs, origin, resolution, point + s * heading, heading, own_radius, other_radius
        ):
            return True
    return False


def head_on(
    way: np.ndarray,
    rel: np.ndarray,
    velocities: np.ndarray,
    yaws: np.ndarray,
    navigating: np.ndarray,
) -> list[int]:
    """The robots we meet head-on: navigating, ahead of us (along ``way``), facing us and not
    drawing away. Those with `narrow_between` us meet us across a passage too narrow for two.

    way : (2,) our direction of travel; rel : (N, 2) their positions relative to us, m;
    velocities : (N, 2) m/s; yaws : (N,) rad; navigating : (N,) bool. Returns indices into rel.
    """
    if float(np.hypot(*way)) < 1e-6 or rel.shape[0] == 0:
        return []
    d = np.maximum(np.hypot(rel[:, 0], rel[:, 1]), 1e-9)
    facing = -(np.cos(yaws) * rel[:, 0] + np.sin(yaws) * rel[:, 1]) > 0.0
    receding = np.einsum("ij,ij->i", rel, velocities) / d > RECEDING_SPEED
    ahead = rel @ way > 0.0
    return np.flatnonzero(navigating & ahead & facing & ~receding).tolist()


def refuge(
    plan_xy: np.ndarray,
    index: int,
    costs: np.ndarray,
    origin: tuple[float, float],
    resolution: float,
    own_radius: float,
    other_radius: float,
    margin: float = 0.1,
    setback: float = 0.0,
) -> tuple[np.ndarray, bool]:
    """Where a robot at plan point ``index`` waits for another to pass (see the module doc).

    plan_xy : (N, 2) the robot's plan (to its goal), costmap frame, m; own_radius,
    other_radius : m, the two robots' safety radii; margin : m of clearance between them;
    setback : m farther back along the plan than the first wide place, while the plan stays
    wide (a robot backing out reaches a point aside on a shallower slant: the skid steer slows
    to turn for a heading error above ~25 degrees).
    Returns (the point (2,), m; True when it is the wide place, False when it is only the
    farthest plan point back inside the costmap).
    """
    h, w = costs.shape
    need = width_needed(own_radius, other_radius, margin)

    def inside(p: np.ndarray) -> bool:
        c, r = (p[0] - origin[0]) / resolution, (p[1] - origin[1]) / resolution
        return 0 <= c < w and 0 <= r < h

    # the way's direction at a point: over HEADING_BASE m of it, not one step (a trail wiggles
    # by a few cm where the robot was pushed aside; a sideways step read as the way's direction
    # measured the passage along its length and took a corridor for a wide place)
    arc = np.r_[0.0, np.cumsum(np.hypot(*np.diff(plan_xy, axis=0).T))]

    def widths(i: int) -> tuple[np.ndarray, float, float] | None:
        """(heading, left, right) at plan point i, None outside the costmap or degenerate."""
        p = plan_xy[i]
        if not inside(p):
            return None
        # the last point at least HEADING_BASE back (else the first): k <= i - 1
        k = max(int(np.searchsorted(arc, arc[i] - HEADING_BASE, side="right")) - 1, 0)
        ahead = plan_xy[i] - plan_xy[k]
        norm = float(np.hypot(*ahead))
        if norm < 1e-9:
            return np.zeros(2), 0.0, 0.0
        heading = ahead / norm
        return heading, *passage_width(costs, origin, resolution, p, heading, need)

    last_inside = plan_xy[index]
    for i in range(index, -1, -1):
        if i == 0:  # the far end (no width there: no way in to measure across)
            if inside(plan_xy[0]):
                last_inside = plan_xy[0]
            break
        got = widths(i)
        if got is None:
            break
        last_inside = plan_xy[i]
        heading, left, right = got
        if left + right < need:
            continue
        back, seen = 0.0, True
        for k in range(i - 1, 0, -1):
            back += float(np.hypot(*(plan_xy[k + 1] - plan_xy[k])))
            if back > setback:
                break
            further = widths(k)
            if further is None:  # the setback runs out of the rolling window: not yet final
                seen = False
                break
            if sum(further[1:]) < need:
                break
            if float(np.hypot(*further[0])) > 0.0:
                i, (heading, left, right) = k, further
        # aside to the right (the robot faces its goal) as far as the wall allows, at most
        # half the width needed; the other robot passes on its left, where the rest is
        aside = max(0.0, min(right - own_radius - 0.5 * margin, need / 2.0))
        return plan_xy[i] + np.array([heading[1], -heading[0]]) * aside, seen
    return np.asarray(last_inside, dtype=np.float64).copy(), False


def has_passed(rel_other: np.ndarray, to_goal: np.ndarray, clearance: float) -> bool:
    """The other robot (at ``rel_other``, m, relative to us) is more than ``clearance`` m behind
    us along ``to_goal`` (our direction to the goal): it has gone by."""
    n = float(np.hypot(*to_goal))
    if n < 1e-9:
        return True
    return float(rel_other @ to_goal) / n < -clearance


def out_of_way(
    xy: np.ndarray, other: np.ndarray, ahead: np.ndarray, near: float, clearance: float
) -> bool:
    """The other robot (at ``other``, m, in the frame of our position ``xy`` and of ``ahead``)
    is farther than ``near`` m from us and more than ``clearance`` m from every point of
    ``ahead`` (K, 2), our plan still to drive: out of our way, though not behind us."""
    if float(np.hypot(*(other - xy))) <= near:
        return False
    return float(np.min(np.hypot(*(ahead - other).T))) > clearance


def retreat_velocity(
    xy: np.ndarray, target: np.ndarray, max_speed: float, deceleration: float
) -> np.ndarray:
    """(2,) m/s towards ``target`` at ``max_speed``, slowing to stop there (``deceleration``
    m/s^2)."""
    to = np.asarray(target, dtype=np.float64) - xy
    d = float(np.hypot(*to))
    if d < REFUGE_TOLERANCE:
        return np.zeros(2)
    return to / d * min(max_speed, math.sqrt(2.0 * deceleration * d))


class Retreat:
    """One robot's way back: its trail and, while it yields, its refuge (costmap frame)."""

    def __init__(self) -> None:
        self.trail: list[tuple[float, float]] = []
        self.refuge: np.ndarray | None = None
        self.refuge_final = False  # the refuge is the wide place, not just the way back
        self.retreated = False  # backing out since the trail last grew: cut it when it does

    def reset(self) -> None:
        """A new goal: the refuge is forgotten, the trail kept: the way the robot came stays
        free whatever its goal. (A goal only nudged by a localization correction is not a new
        goal at all: the planner's ``set_plan`` tells them apart,
        `fleetsim.nav.controllers.collvoid_planner.SAME_GOAL_SHIFT`.)"""
        self.refuge, self.refuge_final = None, False

    def extend(self, xy: np.ndarray) -> None:
        """The robot is at ``xy`` (2,), not yielding: the trail grows every TRAIL_STEP m; back
        from a yield, it first ends where the robot now is (the retreat is cut off)."""
        if self.retreated:
            self.retreated = False
            self.refuge, self.refuge_final = None, False
            if self.trail:
                back = np.asarray(self.trail)
                k = int(np.argmin(np.hypot(back[:, 0] - xy[0], back[:, 1] - xy[1])))
                del self.trail[k + 1 :]
        if not self.trail or math.dist(self.trail[-1], xy) >= TRAIL_STEP:
            self.trail.append((float(xy[0]), float(xy[1])))
            del self.trail[:-TRAIL_POINTS]

    def velocity(
        self,
        grid: tuple[np.ndarray, tuple[float, float], float],
        xy: np.ndarray,
        own_radius: float,
        other_radius: float,
        max_speed: float,
        deceleration: float,
    ) -> np.ndarray:
        """(2,) m/s to the refuge (found the first time, kept once it is the wide place) on
        ``grid``, the local costmap as (costs (H, W) uint8, origin (2,) m, resolution m)."""
        self.retreated = True
        if not self.refuge_final:
            # the trail only: its last point is within TRAIL_STEP of the robot, and a shorter
            # last step would give the way's direction there by noise
            way = np.array(self.trail or [tuple(xy)])
            self.refuge, self.refuge_final = refuge(
                way,
                way.shape[0] - 1,
                *grid,
                own_radius,
                other_radius,
                setback=REFUGE_SETBACK,
            )
        return retreat_velocity(xy, self.refuge, max_speed, deceleration)
