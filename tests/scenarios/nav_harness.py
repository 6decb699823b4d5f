"""Test harness of the navigation scenarios on the Willow Garage map (`willow_nav` package).

The runs are the lesson's launch files (tests/scenarios/willow_nav/launch/), loaded with
`load_plan` and run in process by `LaunchSession` (no Zenoh). This module holds what the
tests compute from the map around them: start cells that fit a footprint (`nearest_free_start`),
the narrowest opening every route between two points must pass (`bottleneck_width`), and a
ground-truth log of each robot (`TruthLog`) for positions and top speeds.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy import ndimage

from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import nav_msgs
from fleetsim.nav.map_io import OccupancyMap
from fleetsim.runtime import Node

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[2].parent / "shared"

WILLOW = Path(SHARED, "data/maps/willow-full.yaml")
PACKAGE = Path(__file__).resolve().parent / "willow_nav"
LAUNCH = PACKAGE / "launch" / "navigation_multi.launch"
CONFIG = PACKAGE / "move_base_config"

#: lizi's footprint in costmap_common_params.yaml (base_link frame, m)
LIZI_FOOTPRINT = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
#: the lesson's start positions (map frame, m)
LESSON_STARTS = ((20.0, 15.0), (22.0, 15.0), (24.0, 15.0))
#: each robot's goal (x, y, yaw): >= 15 m from its start, behind door-wide openings; one west,
#: one north, one east. Their planned routes stay >= 2 m apart (`test_nav_willow` checks): the
#: lizis cannot see each other (their lasers sweep 1 m up, above the other robots' bodies), so
#: routes that share a door would make collisions a matter of timing
GOALS = {
    "lizi1": (5.0, 5.0, math.pi),
    "lizi2": (22.0, 33.0, math.pi / 2),
    "lizi3": (40.0, 12.0, 0.0),
}
XY_GOAL_TOLERANCE = 0.2  # m, base_local_planner_params.yaml of willow_nav
SIM_LIMIT = 120.0  # s of sim time for a three-robot run


def clearances_from_map(grid: OccupancyMap) -> np.ndarray:
    """(H, W) distance (m) from each cell centre to the nearest occupied or unknown cell centre.

    Unknown cells (-1) count as obstacles: nothing is known to be free there.
    """
    blocked = grid.data != 0
    return ndimage.distance_transform_edt(~blocked) * grid.resolution


def nearest_free_start(
    grid: OccupancyMap, xy: tuple[float, float], footprint: np.ndarray, margin: float = 0.1
) -> tuple[float, float]:
    """The free cell centre nearest ``xy`` where the footprint fits at any heading.

    A cell fits when its clearance is at least the footprint's circumscribed radius (the
    largest vertex distance from base_link) plus ``margin`` (m). ``xy`` itself is returned
    unchanged when it fits. Raises ValueError when no cell in the map fits.
    """
    radius = float(np.max(np.hypot(footprint[:, 0], footprint[:, 1]))) + margin
    clear = clearances_from_map(grid)
    ox, oy = grid.origin[0], grid.origin[1]
    res = grid.resolution
    col, row = int((xy[0] - ox) / res), int((xy[1] - oy) / res)
    inside = 0 <= row < grid.height and 0 <= col < grid.width
    if inside and clear[row, col] >= radius:
        return float(xy[0]), float(xy[1])
    rows, cols = np.nonzero(clear >= radius)
    if len(rows) == 0:
        raise ValueError(f"no cell of the map has {radius:.2f} m clearance for the footprint")
    cx, cy = ox + (cols + 0.5) * res, oy + (rows + 0.5) * res
    i = int(np.argmin(np.hypot(cx - xy[0], cy - xy[1])))
    return round(float(cx[i]), 3), round(float(cy[i]), 3)


def bottleneck_width(
    grid: OccupancyMap,
    a: tuple[float, float],
    b: tuple[float, float],
    ends: float = 1.0,
    min_clearance: float = 0.16,
) -> float:
    """Width (m) of the narrowest opening on the widest route between map points ``a`` and ``b``.

    Twice the largest clearance ``c`` such that ``a`` and ``b`` are connected through cells of
    clearance >= ``c``, where cells within ``ends`` m of ``a`` or ``b`` need only
    ``min_clearance`` (m; the robot's inscribed radius): every route from ``a`` to ``b`` passes
    an opening no wider than this on the way (a door, for a value near 1 m), however cramped
    its ends. 0 when they are not connected at all.
    """
    clear = clearances_from_map(grid)
    res, ox, oy = grid.resolution, grid.origin[0], grid.origin[1]
    rows, cols = np.indices(clear.shape)
    cx, cy = ox + (cols + 0.5) * res, oy + (rows + 0.5) * res
    near = (np.hypot(cx - a[0], cy - a[1]) <= ends) | (np.hypot(cx - b[0], cy - b[1]) <= ends)
    near &= clear >= min_clearance
    ca = (int((a[1] - oy) / res), int((a[0] - ox) / res))
    cb = (int((b[1] - oy) / res), int((b[0] - ox) / res))
    levels = np.unique(clear[clear >= min_clearance])
    lo, hi, best = 0, len(levels) - 1, 0.0
    while lo <= hi:  # connectivity only shrinks as the level rises: binary search
        mid = (lo + hi) // 2
        labels, _ = ndimage.label((clear >= levels[mid]) | near)
        if labels[ca] != 0 and labels[ca] == labels[cb]:
            best, lo = float(levels[mid]), mid + 1
        else:
            hi = mid - 1
    return 2.0 * best


def lesson_starts(grid: OccupancyMap) -> list[tuple[float, float, float]]:
    """The lesson's starts moved to free cells for lizi, facing +x as the lesson spawns them."""
    return [(*nearest_free_start(grid, xy, LIZI_FOOTPRINT), 0.0) for xy in LESSON_STARTS]


def planned_routes(
    grid: OccupancyMap, starts, goals: dict[str, tuple[float, float, float]]
) -> dict[str, np.ndarray]:
    """navfn's route (N, 2) for each robot on the static map, with willow_nav's footprint and
    inflation (costmap_common_params.yaml)."""
    from fleetsim.nav.costmap import LayeredCostmap
    from fleetsim.nav.planners import NavFn

    params = {
        "footprint": LIZI_FOOTPRINT.tolist(),
        "inflation_radius": 0.45,
        "observation_sources": "",
    }
    lc = LayeredCostmap.from_params(params, "global")
    lc.set_map(grid)
    lc.update_map(0.0, 0.0, 0.0)
    planner = NavFn(lc.costmap)
    return {
        robot: planner.create_plan(start, goal).poses[:, :2]
        for start, (robot, goal) in zip(starts, goals.items(), strict=True)
    }


def goals_arg(goals: dict[str, tuple[float, float, float]]) -> str:
    """send_goals' ``goals`` as the flow mapping the launch file's ``goals`` arg takes."""
    items = ", ".join(f"{ns}: [[{x}, {y}, {yaw}]]" for ns, (x, y, yaw) in goals.items())
    return "{" + items + "}"


def willow_session(
    starts: list[tuple[float, float, float]],
    goals: dict[str, tuple[float, float, float]] | None = None,
    localization: str = "fake",
    config: Path = CONFIG,
    seed: int = 0,
) -> LaunchSession:
    """The willow_nav scenario with ``len(starts)`` lizis at ``(x, y, yaw)`` each."""
    args = {"robots": str(len(starts)), "localization": localization, "config": str(config)}
    for i, (x, y, yaw) in enumerate(starts, start=1):
        args.update({f"x{i}": str(x), f"y{i}": str(y), f"a{i}": str(yaw)})
    args["goals"] = goals_arg(goals or {})
    return LaunchSession(load_plan(LAUNCH, args, seed=seed), seed=seed, listen=None)


class TruthLog(Node):
    """Each robot's ``base_pose_ground_truth`` (the simulator's p3d): ``(t, x, y)`` samples."""

    def __init__(self, runtime, robots: list[str]) -> None:
        super().__init__(runtime, "truth_log", "/")
        self.samples: dict[str, list[tuple[float, float, float]]] = {r: [] for r in robots}
        for r in robots:
            self.create_subscription(
                nav_msgs.Odometry,
                f"/{r}/base_pose_ground_truth",
                lambda m, r=r: self._on_truth(r, m),
                queue_size=1,
            )

    def _on_truth(self, robot: str, msg) -> None:
        p = msg.pose.pose.position
        self.samples[robot].append((msg.header.stamp.to_sec(), p.x, p.y))

    def xy(self, robot: str) -> np.ndarray:
        """The latest ground-truth position (m) of ``robot``."""
        return np.array(self.samples[robot][-1][1:])

    def top_speed(self, robot: str, window: float = 0.5) -> float:
        """Largest mean ground speed (m/s) over any ``window`` s of the run."""
        s = np.array(self.samples[robot])
        t, xy = s[:, 0], s[:, 1:]
        step = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
        later = np.searchsorted(t, t + window)
        ok = later < len(t)
        dist = step[later[ok]] - step[ok]
        dt = t[later[ok]] - t[ok]
        return float(np.max(dist / dt)) if ok.any() else 0.0


def yaw_towards(a: tuple[float, float], b: tuple[float, float]) -> float:
    """Heading (rad) from point ``a`` to point ``b``."""
    return math.atan2(b[1] - a[1], b[0] - a[0])
