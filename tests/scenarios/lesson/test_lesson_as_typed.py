"""The lesson's package as a student types it (issue 13): runs unchanged, robots reach their goals.

``gazebo_navigation_multi/`` holds the lesson's files with its own names:
``navigation_multi.launch``
with ``map_server ... willow-full.png 0.1`` and an ``rviz`` node, ``willowgarage_world.launch``
including ``gazebo_ros/empty_world.launch`` with ``worlds/willowgarage.world`` (``model://
willowgarage`` at ``<pose>-3 54 0 0 0 30</pose>``), ``robots.launch`` with three lizis, each
``<group ns>`` with its ``tf_prefix`` and amcl initial pose, ``one_robot.launch`` with
``$(find xacro)/xacro.py $(find lizi_description)/urdf/lizi.urdf``, move_base, fake_localization
and the static ``base_link -> laser_link`` publisher, and ``move_base_config/`` with the lesson's
speed limits (old parameter names) and ROS's standard ``amcl_diff`` parameters.

The building is a mesh model of our own (``make_willowgarage_model.py``: the map's walls as one
non-convex mesh, placed by the lesson's pose). The amcl run makes the lesson's own edit to
``one_robot.launch``: fake_localization commented out, ``amcl_node.xml`` included.

Pass criteria come from the simulator's ground truth, never from the robots' own estimates: each
robot ends within its goal tolerance plus 0.25 m of its goal, with no collision, and the run's
results table agrees.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest
from make_willowgarage_model import write_model

from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import geometry_msgs, nav_msgs
from fleetsim.nav.navigator import Navigator, TaskResult
from fleetsim.runtime import Node

PACKAGE = Path(__file__).resolve().parent / "gazebo_navigation_multi"
#: goals behind doors, one north-west, one south (sent from the terminal as in the lesson, to
#: move_base_simple/goal) and one east, on routes >= 2.5 m apart: the lizis cannot see each
#: other (their lasers sweep 1 m up), as in the lesson, which leaves that to multi-robot avoidance
GOALS = {"lizi1": (14.0, 30.0), "lizi2": (30.0, 5.0), "lizi3": (40.0, 12.0)}
#: xy_goal_tolerance of the yaml (0.3: see its comment) + 0.1 m for the localizer's error
REACHED = 0.3 + 0.1
SIM_LIMIT = 120.0  # s


@pytest.fixture(scope="module")
def package(tmp_path_factory) -> Path:
    """The student's package in a folder of its own, with the willowgarage model written."""
    with pytest.MonkeyPatch.context() as mp:  # decompositions cached in the test's folder
        mp.setenv("FLEETSIM_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
        yield _copy_package(tmp_path_factory)


def _copy_package(tmp_path_factory) -> Path:
    dest = tmp_path_factory.mktemp("catkin_ws") / "src" / "gazebo_navigation_multi"
    shutil.copytree(PACKAGE, dest)
    write_model(dest)
    return dest


def lesson_amcl_edit(package: Path) -> None:
    """The lesson's slide 'AMCL': comment fake_localization out, include amcl_node.xml."""
    path = package / "launch" / "one_robot.launch"
    text = path.read_text()
    start = text.index('  <node pkg="fake_localization"')
    end = text.index("</node>", start) + len("</node>")
    amcl = '\n  <include file="$(find gazebo_navigation_multi)/move_base_config/amcl_node.xml"/>'
    path.write_text(text[:start] + "<!--" + text[start:end] + "-->" + amcl + text[end:])


class Truth(Node):
    """The latest ground-truth position of each robot (its p3d ``base_pose_ground_truth``)."""

    def __init__(self, runtime, robots) -> None:
        super().__init__(runtime, "truth", "/")
        self.xy: dict[str, tuple[float, float]] = {}
        for r in robots:
            self.create_subscription(
                nav_msgs.Odometry, f"/{r}/base_pose_ground_truth", self._cb(r), queue_size=1
            )

    def _cb(self, robot):
        def on(msg) -> None:
            p = msg.pose.pose.position
            self.xy[robot] = (p.x, p.y)

        return on


def run_lesson(package: Path, seed: int = 0):
    plan = load_plan(package / "launch" / "navigation_multi.launch", {}, seed=seed)
    session = LaunchSession(plan, seed=seed, listen=None)
    try:
        rt = session.runtime
        truth = Truth(rt, GOALS)
        rt.run(duration=1.0)
        # lizi1 and lizi3 from code (the lesson's send_goals), lizi2 from the terminal
        navs = {r: Navigator(rt, f"/{r}") for r in ("lizi1", "lizi3")}
        for r, nav in navs.items():
            nav.go_to_pose(*GOALS[r], 0.0)
        term = Node(rt, "rostopic_pub", "/")
        pub = term.create_publisher(geometry_msgs.PoseStamped, "/lizi2/move_base_simple/goal", 1)
        goal = geometry_msgs.PoseStamped()
        goal.header.frame_id = "map"
        goal.pose.position.x, goal.pose.position.y = GOALS["lizi2"]
        goal.pose.orientation.w = 1.0
        pub.publish(goal)
        session.run(duration=SIM_LIMIT, until_goals=True)
        results = {r.namespace.strip("/"): r for r in session.monitor.results()}
        return truth.xy, navs, results
    finally:
        session.close()


def check(xy, navs, results) -> None:
    for robot, goal in GOALS.items():
        dist = math.dist(xy[robot], goal)
        assert dist <= REACHED, (robot, xy[robot], goal, dist)
        res = results[robot]
        assert res.goals_reached == 1 and res.goals_failed == 0, (robot, res)
        assert res.collisions == 0, (robot, res)
    for robot, nav in navs.items():
        assert nav.get_result() is TaskResult.SUCCEEDED, (robot, nav.get_status_text())


@pytest.mark.scenario
def test_the_lesson_with_fake_localization_reaches_every_goal(package):
    check(*run_lesson(package))


@pytest.mark.scenario
def test_the_lesson_with_amcl_reaches_every_goal(package, tmp_path):
    amcl_pkg = tmp_path / "src" / "gazebo_navigation_multi"
    shutil.copytree(package, amcl_pkg)
    lesson_amcl_edit(amcl_pkg)
    assert (
        '<!--  <node pkg="fake_localization"' in (amcl_pkg / "launch/one_robot.launch").read_text()
    )
    check(*run_lesson(amcl_pkg))
