"""slam_explore's arguments (assets/launch/slam_explore.launch) as the plan reads them: bad
``robot``/``robots`` values refused with the allowed ones, absolute world paths, and the first
robot's start (x1, y1) reaching the hunter's spawn through hunter_run, run2, gazebo2, gazebo."""

import pytest

import fleetsim
from fleetsim.cli.launch import resolve_launch_file
from fleetsim.errors import LaunchError
from fleetsim.launch.runner import load_plan

OPEN_ROOM = (fleetsim.__path__[0] + "/assets/maps/open_room.yaml").replace("//", "/")


def plan(**args):
    return load_plan(resolve_launch_file("slam_explore"), args)


def spawns(p) -> dict[str, tuple[float, float]]:
    out = {}
    for n in p.nodes:
        if n.type == "spawn_model":
            a = n.args
            out[a[a.index("-model") + 1]] = (
                float(a[a.index("-x") + 1]),
                float(a[a.index("-y") + 1]),
            )
    return out


def world_of(p) -> str:
    (sim,) = [n for n in p.nodes if n.type == "gzserver"]
    return sim.args[0]


@pytest.mark.parametrize("value", ["0", "3", "two"])
def test_robots_other_than_1_or_2_is_refused(value):
    with pytest.raises(LaunchError, match=rf"arg 'robots' is '{value}'; allowed values: 1, 2"):
        plan(robots=value)


@pytest.mark.parametrize("value", ["burger", "turtlebot"])
def test_a_robot_slam_explore_has_no_setup_for_is_refused(value):
    with pytest.raises(
        LaunchError, match=rf"arg 'robot' is '{value}'; allowed values: hunter, lizi"
    ):
        plan(robot=value)


def test_an_absolute_world_path_is_taken_as_it_is():
    assert world_of(plan(world=OPEN_ROOM)) == OPEN_ROOM
    assert world_of(plan(world=OPEN_ROOM, robots="2")) == OPEN_ROOM
    assert world_of(plan(world=OPEN_ROOM, robot="lizi")) == OPEN_ROOM
    assert world_of(plan(world="open_room.yaml")) == OPEN_ROOM  # a name: in world_path


def test_x1_y1_place_the_hunter_and_its_amcl_start_in_every_setup():
    assert spawns(plan()) == {"robocluedo_robot": (4.0, 10.0)}
    assert spawns(plan(x1="2.5", y1="3.5")) == {"robocluedo_robot": (2.5, 3.5)}
    assert spawns(plan(x1="2.5", y1="3.5", robots="2", x2="9", y2="4")) == {
        "hunter1": (2.5, 3.5),
        "hunter2": (9.0, 4.0),
    }
    assert spawns(plan(x1="2.5", y1="3.5", robot="lizi")) == {"lizi1": (2.5, 3.5)}


def test_hunter_run_passes_x_y_to_the_spawn_and_to_amcl():
    p = load_plan(
        resolve_launch_file("hunter_run"),
        {"launch_nav_stack": "false", "launch_amcl": "true", "x": "6", "y": "9"},
    )
    assert spawns(p) == {"robocluedo_robot": (6.0, 9.0)}
    params = p.param_tree()
    assert (params.get("/amcl/initial_pose_x"), params.get("/amcl/initial_pose_y")) == (6, 9)


def test_the_global_costmap_check_is_on_only_for_a_robot_on_its_own_slam_map():
    key = "move_base/TrajectoryPlannerROS/global_costmap_check"
    # the hunter mapping alone (slam_explore, hunter_run's nav stack): on, from params/hunter
    assert plan().param_tree().get(f"/{key}") is True
    nav = load_plan(resolve_launch_file("hunter_run"), {"launch_nav_stack": "true"})
    assert nav.param_tree().get(f"/{key}") is True
    # on the merged map of two SLAM estimates, and on amcl's pose: off
    pair = plan(robots="2").param_tree()
    assert pair.get(f"/hunter1/{key}") is False and pair.get(f"/hunter2/{key}") is False
    amcl = load_plan(
        resolve_launch_file("hunter_run"), {"launch_nav_stack": "false", "launch_amcl": "true"}
    )
    assert amcl.param_tree().get(f"/{key}") is False


def test_an_exploring_lizi_weighs_its_plan_direction_where_the_lessons_lizi_does_not():
    key = "move_base/TrajectoryPlannerROS/alignment_scale"
    # slam_explore's lizi, alone or paired: the alignment cost (and with it backing along the
    # plan where it cannot turn), as the hunter's own file has it
    assert plan(robot="lizi").param_tree().get(f"/lizi1/{key}") == 0.6
    pair = plan(robot="lizi", robots="2").param_tree()
    assert pair.get(f"/lizi1/{key}") == 0.6 and pair.get(f"/lizi2/{key}") == 0.6
    assert plan().param_tree().get(f"/{key}") == 0.6  # the hunter's, from params/hunter
    back = "move_base/TrajectoryPlannerROS/back_along_plan"
    assert plan(robot="lizi").param_tree().get(f"/lizi1/{back}") is True
    assert pair.get(f"/lizi1/{back}") is True and pair.get(f"/lizi2/{back}") is True
    assert plan().param_tree().get(f"/{back}", None) is None  # the hunter: ROS's choice
    # the lesson's lizis keep their file as typed: no alignment cost
    lesson = load_plan(resolve_launch_file("navigation_multi"), {}).param_tree()
    assert lesson.get("/lizi1/move_base_node/TrajectoryPlannerROS/pdist_scale") == 0.6
    assert lesson.get("/lizi1/move_base_node/TrajectoryPlannerROS/alignment_scale", None) is None
