"""``include/one_robot.launch`` (and ``robots.launch`` around it) with ``model:=``: the model
alone picks the robot's description, parameters, laser topic and ground-truth topic, so a user's
launch file gives a turtlebot3 or a jackal its whole stack without passing its description by
hand. Explicit ``description`` / ``laser_topic`` / ``params`` still win."""

from __future__ import annotations

import logging
from pathlib import Path

import pytest
import yaml

import fleetsim
from fleetsim.description.xacro import expand_xacro
from fleetsim.errors import LaunchError
from fleetsim.launch.runner import LaunchSession, load_plan

USER_LAUNCH = """<launch>
  <arg name="model" default="lizi"/>
  <arg name="localization" default="fake"/>
  <param name="/use_sim_time" value="true"/>
  <node pkg="map_server" type="map_server" name="map_server"
        args="$(find fleetsim_maps)/open_room.yaml">
    <param name="frame_id" value="/map"/>
  </node>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="world_name" value="$(find fleetsim_maps)/open_room.yaml"/>
    <arg name="gui" value="false"/>
  </include>
  <group ns="robot1">
    <param name="tf_prefix" value="robot1"/>
    <include file="$(find fleetsim_launch)/include/one_robot.launch">
      <arg name="init_pose" value="-x 4.0 -y 7.0 -z 0"/>
      <arg name="robot_name" value="robot1"/>
      <arg name="model" value="$(arg model)"/>
      <arg name="localization" value="$(arg localization)"/>
    </include>
  </group>
  <node pkg="fleetsim" type="send_goals" name="send_goals">
    <rosparam>
      frame_id: map
      start_delay: 1.0
      goals:
        robot1: [[6.0, 7.0, 0.0]]
    </rosparam>
  </node>
</launch>
"""

# model -> (the description's package, the params directory, laser topic, ground truth topic)
MODELS = {
    "lizi": ("lizi", "lizi", "base_scan", "base_pose_ground_truth"),
    "pioneer3at": ("pioneer3at", "pioneer3at", "scan", "base_pose_ground_truth"),
    "burger": ("turtlebot3_burger", "burger", "scan", "odom"),
    "turtlebot3_waffle": ("turtlebot3_waffle", "waffle", "scan", "odom"),
    "jackal": ("jackal", "jackal", "front/scan", "ground_truth/state"),
    "hunter": ("hunter", "hunter", "/scan", "odom"),
}


def _user_launch(tmp_path: Path) -> Path:
    path = tmp_path / "my_robot.launch"
    path.write_text(USER_LAUNCH)
    return path


ASSETS = Path(fleetsim.__file__).parent / "assets"


def _node(plan, name):
    (node,) = [n for n in plan.nodes if n.name == name]
    return node


def _planner_params(plan) -> dict:
    loads = [
        p.value for p in plan.params if p.kind == "load" and p.name == "/robot1/move_base_node"
    ]
    return next(v["TrajectoryPlannerROS"] for v in loads if "TrajectoryPlannerROS" in v)


@pytest.mark.parametrize("model", sorted(MODELS))
def test_the_model_picks_description_params_laser_and_ground_truth(tmp_path, model):
    package, params, scan, truth = MODELS[model]
    plan = load_plan(_user_launch(tmp_path), {"model": model, "localization": "amcl"})
    (description,) = [p for p in plan.params if p.name == "/robot1/robot_description"]
    urdf, _ = expand_xacro(ASSETS / "robots" / package / "urdf" / f"{package}.urdf.xacro")
    assert description.value == urdf
    shipped = yaml.safe_load(
        (ASSETS / "launch" / "params" / params / "base_local_planner_params.yaml").read_text()
    )
    assert _planner_params(plan) == shipped["TrajectoryPlannerROS"]
    assert _node(plan, "amcl").remaps["scan"] == scan
    plan = load_plan(_user_launch(tmp_path), {"model": model})
    assert _node(plan, "fake_localization").remaps["base_pose_ground_truth"] == truth
    # the shared map frame, whatever the model's YAML says (turtlebot3_navigation's `map`)
    frame = plan.param_tree().get("/robot1/move_base_node/global_costmap/global_frame")
    assert frame == "/map"


def _with_include_args(tmp_path, **args) -> Path:
    extra = "".join(f'\n      <arg name="{k}" value="{v}"/>' for k, v in args.items())
    text = (
        _user_launch(tmp_path)
        .read_text()
        .replace(
            '<arg name="model" value="$(arg model)"/>',
            '<arg name="model" value="$(arg model)"/>' + extra,
        )
    )
    path = tmp_path / "explicit.launch"
    path.write_text(text)
    return path


def test_a_model_of_the_users_own_takes_what_is_passed(tmp_path):
    """A model fleetsim does not ship, with its description, parameters and laser topic given
    (the pioneer's files here): nothing is looked up by the model's name."""
    params = ASSETS / "launch" / "params" / "pioneer3at"
    path = _with_include_args(
        tmp_path,
        description="$(find pioneer3at)/urdf/pioneer3at.urdf.xacro",
        params=str(params),
        laser_topic="my_scan",
    )
    plan = load_plan(path, {"model": "my_p3at", "localization": "amcl"})
    (description,) = [p for p in plan.params if p.name == "/robot1/robot_description"]
    urdf, _ = expand_xacro(ASSETS / "robots" / "pioneer3at" / "urdf" / "pioneer3at.urdf.xacro")
    assert description.value == urdf
    shipped = yaml.safe_load((params / "base_local_planner_params.yaml").read_text())
    assert _planner_params(plan) == shipped["TrajectoryPlannerROS"]
    assert _node(plan, "amcl").remaps["scan"] == "my_scan"


def test_a_model_of_the_users_own_without_a_description_names_it(tmp_path):
    with pytest.raises(LaunchError, match="my_p3at"):
        load_plan(_user_launch(tmp_path), {"model": "my_p3at"})


def test_an_explicit_description_still_wins(tmp_path):
    path = _with_include_args(tmp_path, description="$(find pioneer3at)/urdf/pioneer3at.urdf.xacro")
    plan = load_plan(path, {"model": "lizi"})
    (description,) = [p for p in plan.params if p.name == "/robot1/robot_description"]
    urdf, _ = expand_xacro(ASSETS / "robots" / "pioneer3at" / "urdf" / "pioneer3at.urdf.xacro")
    assert description.value == urdf
    lizi = ASSETS / "launch" / "params" / "lizi" / "base_local_planner_params.yaml"
    assert _planner_params(plan) == yaml.safe_load(lizi.read_text())["TrajectoryPlannerROS"]


def test_robots_launch_hands_the_model_and_what_is_passed_to_each_robot():
    """`navigation_multi`'s include of three robots: the model alone, or with its files."""
    from fleetsim.cli.launch import resolve_launch_file

    plan = load_plan(resolve_launch_file("pioneer_multi"), {"localization": "amcl"})
    amcls = [n for n in plan.nodes if n.name == "amcl"]
    assert [n.remaps["scan"] for n in amcls] == ["scan"] * 3
    plan = load_plan(resolve_launch_file("navigation_multi"), {"localization": "amcl"})
    assert [n.remaps["scan"] for n in plan.nodes if n.name == "amcl"] == ["base_scan"] * 3


@pytest.mark.scenario
def test_a_burger_from_one_robot_launch_reaches_its_goal_quietly(monkeypatch, tmp_path, caplog):
    """The turtlebot3's `global_frame: map` is the shared /map, and fake_localization reads its
    drive's world odometry: the goal 2 m ahead is reached, with no WARNING on the way."""
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    plan = load_plan(_user_launch(tmp_path), {"model": "burger"})
    with caplog.at_level(logging.WARNING), LaunchSession(plan, seed=1) as s:
        # its wheels are placed from the drive's joint states (publishWheelJointState), with
        # no joint_state_publisher to publish them at 0 as well
        assert "/robot1/joint_state_publisher" not in s.nodes
        wheel = []
        for seconds in (6.0, 1.0):  # while it drives to its goal
            s.run(duration=seconds)
            tf = s.runtime.tf_buffer.lookup_transform("robot1/base_link", "robot1/wheel_left_link")
            wheel.append(tf.transform.rotation)
        assert abs(wheel[0].x - wheel[1].x) + abs(wheel[0].w - wheel[1].w) > 0.05  # it rolls
        s.run(duration=9.0)
        engine = s.nodes["/gazebo"].engine
        assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}
        (result,) = [r for r in s.monitor.results() if r.namespace.strip("/") == "robot1"]
        assert (result.goals_reached, result.collisions) == (1, 0), result
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == []
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
