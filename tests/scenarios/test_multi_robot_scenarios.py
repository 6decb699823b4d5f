"""Multi-robot collision avoidance, whole system (issue 18): the shipped scenarios swap_corridor
and circle in their short versions, the lesson's three lizis swapping starts in Willow, a robot
publishing garbage on /position_share, and the plain planner's failure the new one fixes.

Pass criterion (as the scenarios' own): every robot reaches its goal (ground truth confirms it),
no contact between robots or with a wall (`RunMonitor`), MuJoCo silent.
"""

import logging
import math
import re
from pathlib import Path

import pytest
from nav_harness import WILLOW, lesson_starts

from fleetsim.cli.launch import resolve_launch_file
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.nav.map_io import load_map
from fleetsim.nav.navigator import INITIAL_COV_AA, INITIAL_COV_XX, INITIAL_COV_YY
from fleetsim.runtime import Node

pytestmark = pytest.mark.scenario


def session(name: str, **args: str) -> LaunchSession:
    return LaunchSession(load_plan(resolve_launch_file(name), args), seed=1)


def robot_contacts(s: LaunchSession) -> set[tuple[str, str]]:
    """Pairs of robots touching now."""
    engine = s.monitor.sim.engine
    robots = {m for m, e in engine.models.items() if e.kind == "robot"}
    return {
        tuple(sorted((c.model1, c.model2)))
        for c in engine.contacts()
        if c.model1 in robots and c.model2 in robots
    }


def assert_clean_success(s: LaunchSession, tmp_path) -> None:
    results = s.monitor.results()
    assert s.monitor.success(), results
    for r in results:
        assert r.goals_reached == 1 and r.collisions == 0, r
    engine = s.monitor.sim.engine
    assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


class Garbage(Node):
    """Two broken robots on /position_share: a NaN pose and an empty footprint, at 10 Hz."""

    def __init__(self, runtime):
        super().__init__(runtime, "garbage", "/")
        self.pub = self.create_publisher(collvoid_msgs.PoseTwistWithCovariance, "/position_share")
        self.create_timer(0.1, self.tick)

    def tick(self):
        nan = collvoid_msgs.PoseTwistWithCovariance(robot_id="ghost", radius=0.3)
        nan.header.stamp = self.now_msg()
        nan.pose.pose.position = geometry_msgs.Point(x=math.nan, y=2.0)
        nan.footprint.polygon.points = [geometry_msgs.Point32(x=1.0)] * 4
        hollow = collvoid_msgs.PoseTwistWithCovariance(robot_id="hollow", radius=0.3)
        hollow.header.stamp = self.now_msg()
        hollow.pose.pose.position = geometry_msgs.Point(x=7.0, y=2.0)
        self.pub.publish(nan)
        self.pub.publish(hollow)


def test_swap_corridor_two_robots_pass_despite_a_broken_robot_on_the_topic(
    monkeypatch, tmp_path, caplog
):
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    caplog.set_level(logging.WARNING)
    with session("swap_corridor", robots="2", gui="false") as s:
        Garbage(s.runtime)
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        assert s.runtime.now() < 2.0 + 1.5 * 21.0  # makespan <= 1.5 x the ~21 s alone
    for bad, why in (("ghost", "non-finite pose"), ("hollow", "empty or invalid footprint")):
        said = [r.getMessage() for r in caplog.records if f"'{bad}'" in r.getMessage()]
        assert said and all(why in m for m in said)
        # once in the process, not once per message nor per listening move_base (issue 18)
        assert len(said) == 1, said


def test_swap_corridor_with_amcl_pads_by_the_spread_across_not_along(monkeypatch, tmp_path):
    """localization:=amcl, amcl started with its default initial covariance (0.5 m standard
    deviation; the scenario tells it the start to 5 cm): the particles spread 0.3-0.5 m along
    the featureless corridor for most of the run; padded by that in every direction the pair
    never passed (0/2 goals in 60 s). Padded by the spread across the velocity obstacle's legs
    (issue 18), both arrive without contact."""
    monkeypatch.chdir(tmp_path)
    plan = load_plan(resolve_launch_file("swap_corridor"),
                     {"robots": "2", "localization": "amcl", "gui": "false"})  # fmt: skip
    defaults = {"initial_cov_xx": INITIAL_COV_XX, "initial_cov_yy": INITIAL_COV_YY,
                "initial_cov_aa": INITIAL_COV_AA}  # fmt: skip
    widened = [op for op in plan.params if op.name.rsplit("/", 1)[-1] in defaults]
    assert len(widened) == 6  # both robots' three
    for op in widened:
        op.value = defaults[op.name.rsplit("/", 1)[-1]]
    with LaunchSession(plan, seed=1) as s:
        s.run(duration=45.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        # the feature was at work: lizi1's planner holds lizi2's shared covariance
        table = s.nodes["/lizi1/move_base"].controller.share.table
        assert table.robots["lizi2"].covariance is not None


def test_circle_of_eight_reaches_the_antipodes(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    with session("circle", robots="8", gui="false") as s:
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)


def test_swap_corridor_four_robots_two_queued_at_each_end(monkeypatch, tmp_path):
    """robots:=4: two lizis queue 1.2 m apart at each end and each goes to its counterpart's
    start at the other end (the issue: two, then four robots)."""
    monkeypatch.chdir(tmp_path)
    with session("swap_corridor", robots="4", gui="false") as s:
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        assert len(s.monitor.results()) == 4


def test_swap_through_a_corridor_too_narrow_for_two(monkeypatch, tmp_path):
    """width:=1.0: the corridor's middle 6 m are too narrow for two lizis. They meet face to
    face; lizi2 (lower priority) sees the passage between them is too narrow, backs out into
    its wide end, waits aside until lizi1 is level with it, then both finish: no contact, no
    abort, and no robot counts as deadlocked by the issue's measure (not within 0.5 m of its
    goal and not 0.2 m closer than its best for 20 s, as benchmarks/multi_robot.py counts)."""
    monkeypatch.chdir(tmp_path)
    with session("swap_corridor", robots="2", width="1.0", gui="false") as s:
        engine, best, longest = s.monitor.sim.engine, {}, {}

        def progress():
            now = s.runtime.now()
            for r in s.monitor.robots.values():
                if not r.model or r.goal is None or r.goals_reached:
                    continue
                d = math.dist(engine.model_pose(r.model)[0][:2], r.goal)
                b = best.get(r.model)
                if b is None or d < b[0] - 0.2:
                    best[r.model] = b = (d, now)
                if d > 0.5:
                    longest[r.model] = max(longest.get(r.model, 0.0), now - b[1])

        s.runtime.create_timer(0.1, progress, priority=-50)
        s.run(duration=90.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        rules = {ns: s.nodes[f"/{ns}/move_base"].controller.deadlock for ns in ("lizi1", "lizi2")}
        assert rules["lizi2"].yields == 1 and rules["lizi1"].yields == 0
        assert max(longest.values()) < 20.0, longest


def test_a_lizi_and_a_pioneer3at_swap_the_corridor(monkeypatch, tmp_path):
    """model:=mixed: robots of two sizes and speeds share /position_share with their own
    footprints (each me_publisher takes its local costmap's) and pass without contact."""
    monkeypatch.chdir(tmp_path)
    with session("swap_corridor", robots="2", model="mixed", gui="false") as s:
        s.run(duration=45.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        assert {r.namespace for r in s.monitor.results()} == {"/lizi1", "/pioneer2"}
        table = s.nodes["/lizi1/move_base"].controller.share.table
        radii = {k: r.body_radius for k, r in table.robots.items()}
        assert radii["pioneer2"] == pytest.approx(math.hypot(0.27, 0.25), abs=1e-3)


def test_pioneers_that_see_each_other_cross_the_circle(monkeypatch, tmp_path):
    """model:=pioneer3at: a pioneer's laser sweeps the other pioneers' bodies, so each one is
    in the others' local costmaps. The planner clears those images where /position_share puts
    the robots (the robot half-planes cover them); taken for walls they had held the pioneers
    face to face for 40-55 s (circle of 8, benchmarks/multi_robot.py, seeds 0-4)."""
    monkeypatch.chdir(tmp_path)
    cleared = []
    with session("circle", robots="8", model="pioneer3at", gui="false") as s:
        planners = [s.nodes[f"/pioneer{k}/move_base"].controller for k in range(1, 9)]

        def seen():
            cleared.append(sum(p.grid is not None and p.grid[0] is not p.costmap.costs
                               for p in planners))  # fmt: skip

        s.runtime.create_timer(0.5, seen, priority=-50)
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        assert len(s.monitor.results()) == 8
        assert s.runtime.now() < 2.0 + 30.0  # makespans 12.4-17.8 s (44-62 s before)
    assert max(cleared) > 0  # the others were in the costmaps, and cleared


def test_two_jackals_with_amcl_swap_the_corridor_off_the_walls(monkeypatch, tmp_path):
    """model:=jackal localization:=amcl: the jackal's local costmap works in odom (its
    skid-steer drive reports the true pose on odom), not in /map, where the robot's pose
    jumped against the walls marked before each amcl correction. Benchmark seeds 1-5 in /map:
    8/10 goals and 4 robot-wall contacts; in odom 10/10 and none. These are seed 2's starts
    (the benchmark's 2 cm jitter), where in /map jackal2, backing out to let jackal1 by (each
    jackal's padded footprint has a 0.41 m circumscribed radius, and once amcl's spread pads
    them the pair needs 2.05 m of the corridor's 1.875 m of free width), ran into the
    corridor's end wall and neither arrived in 60 s. Their velocity obstacles are the two
    footprints' Minkowski sum (``use_polygon_footprint`` in the jackal's YAML): side by side
    they need 0.54 m each, not 0.82: both arrive in 23.5 s, as discs in 46.5 s."""
    monkeypatch.chdir(tmp_path)
    launch_args = {"robots": "2", "model": "jackal", "localization": "amcl", "gui": "false"}
    plan = load_plan(resolve_launch_file("swap_corridor"), launch_args)
    plan.jitter_spawns(2, 0.02)  # benchmarks/multi_robot.py's starts for seed 2
    with LaunchSession(plan, seed=2) as s:
        frames = {s.nodes[f"/jackal{k}/move_base"].local_costmap.global_frame for k in (1, 2)}
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        assert {r.namespace for r in s.monitor.results()} == {"/jackal1", "/jackal2"}
        assert s.runtime.now() < 35.0
    assert frames == {"jackal1/odom", "jackal2/odom"}


def test_three_jackals_in_willow_keep_off_the_walls_their_laser_has_not_seen(monkeypatch, tmp_path):
    """model:=jackal in willow_swap (the starts chosen for lizis): jackal1 starts where it
    cannot turn on the spot, and its front laser (270 degrees) has never seen the wall behind
    it. With only the laser in its collvoid local costmap it backed and turned into that wall
    (seed 3: 2 robot-wall contacts, with amcl and without; seeds 0-9: 2 contacts, 6 robots 20 s
    without progress, up to 40.7 s). With the map's static layer in that costmap, as the
    pioneer3at's has, 0 contacts and 21.9-22.3 s on seeds 0-9."""
    monkeypatch.chdir(tmp_path)
    launch_args = {"robots": "3", "model": "jackal", "gui": "false"}
    plan = load_plan(resolve_launch_file("willow_swap"), launch_args)
    plan.jitter_spawns(3, 0.02)  # benchmarks/multi_robot.py's starts for seed 3
    with LaunchSession(plan, seed=3) as s:
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        assert {r.namespace for r in s.monitor.results()} == {f"/jackal{k}" for k in (1, 2, 3)}


def test_turtlebot3_burgers_cross_the_circle_without_a_ring_of_wakes(monkeypatch, tmp_path):
    """model:=turtlebot3_burger, with turtlebot3_navigation's limits and collvoid's defaults:
    a burger's 360-degree laser sees the others, and every cell it saw a moving robot in stayed
    lethal until a ray swept it again - never, behind the crowd. The burgers stood in a ring
    of those wakes round the centre (5 seeds: 32 robots 20 s without progress, 5.4x the time
    alone). The robots layer now erases the other robots' bodies from the obstacle layer at
    every update (27.6 s alone, 31.6 s for the eight)."""
    from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE
    from fleetsim.nav.costmap.obstacle_layer import ObstacleLayer

    monkeypatch.chdir(tmp_path)
    erased = []
    clear_cells = ObstacleLayer.clear_cells

    def counted(self, rows, cols):
        erased.append(int((self.grid.costs[rows, cols] == LETHAL_OBSTACLE).sum()))
        clear_cells(self, rows, cols)

    monkeypatch.setattr(ObstacleLayer, "clear_cells", counted)
    with session("circle", robots="8", model="turtlebot3_burger", gui="false") as s:
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        assert {r.namespace for r in s.monitor.results()} == {f"/burger{k}" for k in range(1, 9)}
        assert s.runtime.now() < 2.0 + 1.5 * 27.6  # the 1.5x the slowest alone
    assert sum(erased) > 100  # the burgers saw each other, and their images were erased


def test_plain_trajectory_planner_runs_into_the_other_robot(monkeypatch, tmp_path):
    """The failure this issue fixes: lizis cannot see each other (their lasers sweep above the
    other bodies), so with TrajectoryPlannerROS the corridor swap ends in a collision."""
    monkeypatch.chdir(tmp_path)
    with session("swap_corridor", robots="2", planner="trajectory", gui="false") as s:
        s.runtime.run(duration=40.0, until=lambda: bool(robot_contacts(s)))
        assert robot_contacts(s) == {("lizi1", "lizi2")}


def test_lesson_lizis_swap_starts_in_willow(monkeypatch, tmp_path):
    """The shipped willow_swap: the lesson's three lizis (its starts moved to the nearest cells
    a lizi fits in) sent through each other's paths in the Willow Garage map."""
    monkeypatch.chdir(tmp_path)
    starts = lesson_starts(load_map(WILLOW))
    with session("willow_swap", gui="false") as s:
        spawned = {}
        for n in s.plan.nodes:
            if (n.pkg, n.type) == ("gazebo_ros", "spawn_model"):
                a = n.args
                xy = [float(a[a.index("-x") + 1]), float(a[a.index("-y") + 1])]
                spawned[n.namespace.rstrip("/")] = xy
        s.run(duration=60.0, until_goals=True)
        assert_clean_success(s, tmp_path)
        goals = {r.namespace: r.goal for r in s.monitor.results()}
    for k, st in enumerate(starts, 1):
        assert spawned[f"/lizi{k}"] == pytest.approx(st[:2])
    assert goals["/lizi1"] == pytest.approx(starts[2][:2])
    assert goals["/lizi2"] == pytest.approx(starts[0][:2])
    assert goals["/lizi3"] == pytest.approx(starts[1][:2])


@pytest.mark.parametrize(
    "name, args, words",
    [
        ("swap_corridor", {"robots": "3"}, "arg 'robots' is '3'; allowed values: 2, 4"),
        ("circle", {"robots": "5"}, "arg 'robots' is '5'; allowed values: 8, 16"),
        ("willow_swap", {"robots": "2"}, "arg 'robots' is '2'; allowed values: 3"),
        ("swap_corridor", {"width": "1.5"}, "arg 'width' is '1.5'; allowed values: 2.0, 1.0"),
        ("swap_corridor", {"planner": "foo"}, "'planner' is 'foo'; allowed values: collvoid, traj"),
        ("circle", {"planner": "dwa"}, "arg 'planner' is 'dwa'; allowed values: collvoid, traj"),
        ("willow_swap", {"planner": "foo"}, "'planner' is 'foo'; allowed values: collvoid, traj"),
        ("swap_corridor", {"localization": "gps"}, "'localization' is 'gps'; allowed values: fak"),
        ("circle", {"localization": "gps"}, "'localization' is 'gps'; allowed values: fake, amcl"),
        ("circle", {"model": "burger"}, "'model' is 'burger'; allowed values: lizi, pioneer3at, "),
    ],
)
def test_the_scenarios_refuse_args_they_do_not_know(name, args, words):
    """A bad value is named with the allowed ones (planner:=foo ran the plain planner,
    localization:=gps no localization at all)."""
    from fleetsim.errors import LaunchError

    with pytest.raises(LaunchError, match=re.escape(words)):
        load_plan(resolve_launch_file(name), args)


def test_the_shipped_scenarios_are_what_their_generator_writes(tmp_path):
    import runpy

    import fleetsim

    launch = Path(fleetsim.__file__).parent / "assets" / "launch"
    gen = runpy.run_path(str(launch / "make_multi_robot_launch.py"))
    for p in gen["write"](tmp_path):
        assert p.read_text() == (launch / p.name).read_text(), p.name


def test_the_scenarios_are_shipped():
    from fleetsim.cli.launch import scenarios

    assert {"swap_corridor", "circle", "willow_swap"} <= set(scenarios())
    for name in ("swap_corridor", "circle", "willow_swap"):
        load_plan(resolve_launch_file(name), {"planner": "trajectory", "localization": "amcl"})
