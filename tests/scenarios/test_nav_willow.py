"""The navigation issue's "must show" scenarios: lizis on the Willow Garage map with move_base.

The runs are the lesson's launch files in the `willow_nav` test package (navigation_multi.launch
-> robots.launch -> one_robot.launch per ``<group ns>`` with ``tf_prefix``; map_server and the
simulator on ``willow-full.yaml``; send_goals), run in process by `LaunchSession`. Pass criteria
use the simulator's ground truth (``base_pose_ground_truth``) and the `RunMonitor`'s contact
count, never the robots' own estimates.

Starts: the lesson's (20, 15), (22, 15), (24, 15), each moved to the nearest cell where lizi's
footprint fits (`nearest_free_start`; (20, 15) is 0.2 m from a wall and moves). Goals are
>= 15 m away in a straight line and behind openings no wider than a door (`bottleneck_width`),
one to the south-west, one to the north and one to the east, on routes >= 2 m apart, so that
they do not meet at one door.
"""

import math
import re

import numpy as np
import pytest
from nav_harness import (
    CONFIG,
    GOALS,
    LESSON_STARTS,
    LIZI_FOOTPRINT,
    SIM_LIMIT,
    WILLOW,
    XY_GOAL_TOLERANCE,
    TruthLog,
    bottleneck_width,
    clearances_from_map,
    lesson_starts,
    nearest_free_start,
    planned_routes,
    willow_session,
)

from fleetsim.msgs import actionlib_msgs, move_base_msgs
from fleetsim.nav.map_io import OccupancyMap, load_map
from fleetsim.nav.navigator import Navigator, TaskResult
from fleetsim.runtime import Node


@pytest.fixture(scope="module")
def willow() -> OccupancyMap:
    return load_map(WILLOW)


# -- the map helpers ------------------------------------------------------------------------
def _grid(rows: list[str], resolution: float = 0.1) -> OccupancyMap:
    """A grid from text rows, top row first: '#' occupied, '.' free, '?' unknown."""
    code = {"#": 100, ".": 0, "?": -1}
    data = np.array([[code[c] for c in r] for r in reversed(rows)], dtype=np.int8)
    return OccupancyMap(data, resolution, (0.0, 0.0, 0.0))


def test_nearest_free_start_keeps_a_fitting_cell_and_moves_a_cramped_one():
    rows = ["#" * 20] + ["#" + "." * 18 + "#"] * 10 + ["#" * 20]
    grid = _grid(rows, resolution=0.1)  # a 1.8 x 1.0 m free room
    fp = np.array([[-0.1, -0.1], [-0.1, 0.1], [0.1, 0.1], [0.1, -0.1]])  # r = 0.141 m
    assert nearest_free_start(grid, (1.0, 0.6), fp, margin=0.05) == (1.0, 0.6)
    x, y = nearest_free_start(grid, (0.15, 0.6), fp, margin=0.05)
    clear = clearances_from_map(grid)
    assert clear[int(y / 0.1), int(x / 0.1)] >= math.hypot(0.1, 0.1) + 0.05
    assert 0.15 < x < 0.45 and abs(y - 0.6) < 0.1  # the nearest fitting cell, east of the wall
    with pytest.raises(ValueError, match="clearance for the footprint"):
        nearest_free_start(grid, (1.0, 0.6), fp * 5)


def test_unknown_cells_do_not_count_as_free():
    rows = ["?" * 12] * 12
    rows[6] = "?" + "." * 10 + "?"
    with pytest.raises(ValueError, match="no cell of the map"):
        nearest_free_start(_grid(rows), (0.6, 0.6), LIZI_FOOTPRINT)


def test_bottleneck_width_is_the_door_between_two_rooms():
    rows = ["#" * 43]
    for r in range(20):
        door = 8 <= r < 16  # an 0.8 m opening in the middle wall
        rows.append("#" + "." * 20 + ("." if door else "#") + "." * 20 + "#")
    rows.append("#" * 43)
    grid = _grid(rows)
    width = bottleneck_width(grid, (1.0, 1.0), (3.4, 1.0), ends=0.5, min_clearance=0.1)
    assert 0.6 <= width <= 0.9, width
    # within one room the widest route is as wide as the room
    assert bottleneck_width(grid, (1.0, 1.0), (1.0, 1.5), ends=0.2, min_clearance=0.1) > 1.5
    shut = _grid([r[:21] + "#" + r[22:] for r in rows])  # the door walled up
    assert bottleneck_width(shut, (1.0, 1.0), (3.4, 1.0), ends=0.5, min_clearance=0.1) == 0.0


def test_lesson_starts_fit_lizi_and_the_goals_are_far_behind_doors(willow):
    starts = lesson_starts(willow)
    assert starts[0][:2] != LESSON_STARTS[0]  # (20, 15) is too close to the wall for lizi
    radius = float(np.max(np.hypot(*LIZI_FOOTPRINT.T)))
    clear = clearances_from_map(willow)
    for (x, y, _), lesson, goal in zip(starts, LESSON_STARTS, GOALS.values(), strict=True):
        assert math.dist((x, y), lesson) <= 0.5
        assert clear[int(y / 0.1), int(x / 0.1)] >= radius
        assert math.dist((x, y), goal[:2]) >= 15.0
        assert bottleneck_width(willow, (x, y), goal[:2]) <= 1.2 + 1e-9  # door-wide


def test_the_goals_routes_keep_apart(willow):
    # the lizis cannot see each other (lasers 1 m up): routes must not share a door
    starts = lesson_starts(willow)
    routes = planned_routes(willow, starts, GOALS)
    away = {  # leave out the first 1.2 m, where the starts themselves are 2 m apart
        r: p[np.hypot(*(p - np.array(s[:2])).T) > 1.2]
        for (r, p), s in zip(routes.items(), starts, strict=True)
    }
    names = list(away)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            gap = np.hypot(*(away[a][:, None] - away[b][None]).transpose(2, 0, 1)).min()
            assert gap >= 2.0, (a, b, gap)


# -- the scenarios ----------------------------------------------------------------------------
@pytest.mark.scenario
def test_three_lizis_reach_goals_through_doors_without_collisions(willow):
    starts = lesson_starts(willow)
    session = willow_session(starts, GOALS)
    try:
        log = TruthLog(session.runtime, list(GOALS))
        session.runtime.run(duration=SIM_LIMIT, until=session.monitor.all_goals_done)
        results = {r.namespace.strip("/"): r for r in session.monitor.results()}
        for robot, (gx, gy, _) in GOALS.items():
            r = results[robot]
            assert (r.goals_sent, r.goals_reached) == (1, 1), (robot, r)
            assert math.dist(log.xy(robot), (gx, gy)) <= XY_GOAL_TOLERANCE + 0.02, robot
            assert r.collisions == 0, (robot, r)
            assert r.path_length >= 15.0, (robot, r)
        assert session.monitor.success()
    finally:
        session.close()


def _top_speed(tmp_path, max_vel_x: float, start, goal) -> float:
    config = tmp_path / f"config_{max_vel_x}"
    config.mkdir()
    for f in CONFIG.iterdir():
        text = f.read_text()
        if f.name == "base_local_planner_params.yaml":
            text = text.replace("max_vel_x: 0.5", f"max_vel_x: {max_vel_x}")
            assert f"max_vel_x: {max_vel_x}" in text
        (config / f.name).write_text(text)
    session = willow_session([start], {"lizi1": goal}, config=config)
    try:
        log = TruthLog(session.runtime, ["lizi1"])
        session.runtime.run(duration=14.0)
        travelled = session.monitor.results()[0].path_length
        assert travelled > 2.0, travelled  # it drove
        return log.top_speed("lizi1")
    finally:
        session.close()


@pytest.mark.scenario
def test_max_vel_x_in_base_local_planner_params_limits_the_top_speed(tmp_path):
    # down the long corridor west of Willow's central block, facing north
    start, goal = (32.3, 24.5, math.pi / 2), (31.6, 36.5, math.pi / 2)
    slow = _top_speed(tmp_path, 0.3, start, goal)
    fast = _top_speed(tmp_path, 0.6, start, goal)
    assert 0.2 <= slow <= 0.3 * 1.1, slow
    assert 0.45 <= fast <= 0.6 * 1.1, fast
    assert fast >= 1.5 * slow


def _unreachable_goal(grid: OccupancyMap, start: tuple[float, float]) -> tuple[float, float]:
    """The centre of the roomiest pocket where lizi fits but which no route from ``start``
    reaches: cells within lizi's inscribed radius (0.16 m) of an occupied cell are obstacles
    to navfn (inscribed cost), so pockets of ``clearance > 0.16`` m are cut off from the rest.
    """
    from scipy import ndimage

    clear = ndimage.distance_transform_edt(grid.data != 100) * grid.resolution
    labels, n = ndimage.label(clear > 0.16, structure=np.ones((3, 3)))
    own = labels[int(start[1] / grid.resolution), int(start[0] / grid.resolution)]
    roomiest = ndimage.maximum(clear, labels, np.arange(1, n + 1))
    roomiest[own - 1] = 0.0
    pocket = int(np.argmax(roomiest)) + 1
    assert roomiest[pocket - 1] >= 0.25  # lizi's circumscribed radius: it would fit there
    rows, cols = np.nonzero((labels == pocket) & (clear == roomiest[pocket - 1]))
    return (cols[0] + 0.5) * grid.resolution, (rows[0] + 0.5) * grid.resolution


class ResultLog(Node):
    """Every ``/lizi1/move_base/result``: (status, text)."""

    def __init__(self, runtime) -> None:
        super().__init__(runtime, "result_log", "/")
        self.results: list[tuple[int, str]] = []
        self.create_subscription(
            move_base_msgs.MoveBase.ActionResult,
            "/lizi1/move_base/result",
            lambda m: self.results.append((m.status.status, m.status.text)),
            queue_size=10,
        )


@pytest.mark.scenario
def test_unreachable_and_in_obstacle_goals_abort_with_a_reason(willow):
    start = (22.0, 15.0, 0.0)
    session = willow_session([start])
    try:
        log = ResultLog(session.runtime)
        truth = TruthLog(session.runtime, ["lizi1"])
        session.runtime.run(duration=1.0)
        nav = Navigator(session.runtime, "/lizi1")
        occupied = np.argwhere(willow.data == 100)
        wall = occupied[np.argmin(np.hypot(occupied[:, 1] * 0.1 - 25, occupied[:, 0] * 0.1 - 20))]
        cases = {
            "in a wall": (((wall[1] + 0.5) * 0.1, (wall[0] + 0.5) * 0.1), "in an obstacle"),
            "unreachable": (_unreachable_goal(willow, start[:2]), "not connected"),
            "outside the map": ((80.0, 15.0), "off the global costmap"),
        }
        for i, (what, ((gx, gy), reason)) in enumerate(cases.items()):
            t0 = session.runtime.now()
            nav.go_to_pose(gx, gy, 0.0)
            assert nav.spin_until_complete(timeout=90.0), what
            assert session.runtime.now() - t0 < 80.0, what  # ends, never hangs
            assert nav.get_result() is TaskResult.FAILED, (what, nav.get_result())
            status, text = log.results[i]
            assert status == actionlib_msgs.GoalStatus.ABORTED, (what, status, text)
            assert re.search(reason, text, re.I), (what, text)
            assert text == nav.get_status_text()
        assert session.monitor.results()[0].goals_failed == 3
        assert math.dist(truth.xy("lizi1"), start[:2]) < 1.0  # it did not set off anywhere
    finally:
        session.close()
