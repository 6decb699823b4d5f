"""patrol_client as grobot's patrol_robot.xml launches it: args '<radius> <clockwise>', one
endless goal to the robot's own patrol_server 2 s of sim time after start."""

from pathlib import Path

import pytest

from fleetsim.apps.patrol_client import patrol_goal_from_args
from fleetsim.errors import ParameterError
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import grobot_utilities

ROBOTS = Path(__file__).resolve().parents[2] / "src/fleetsim/assets/robots"

LAUNCH = """<launch>
  <param name="/use_sim_time" value="true"/>
  <include file="$(find gazebo_ros)/launch/empty_world.launch"/>
  <group ns="karl">
    <param name="tf_prefix" value="karl"/>
    <param name="robot_description" command="$(find xacro)/xacro {burger}"/>
    <node name="spawn_robot" pkg="gazebo_ros" type="spawn_model"
          args="-urdf -model karl -x -2.0 -y 2.0 -Y 0 -param robot_description"/>
    <node name="patrol_server" pkg="grobot_utilities" type="patrol_server" output="screen"/>
    <node name="patrol_client" pkg="grobot_utilities" type="patrol_client" args="0.3 true"/>
  </group>
</launch>
"""


def test_goal_from_args_as_the_script_reads_them():
    goal = patrol_goal_from_args(["1.5", "True"], "w")
    assert (goal.radius, goal.clockwise, goal.num_patrols) == (1.5, True, 0)
    assert patrol_goal_from_args(["1.5", "false"], "w").clockwise is False
    assert patrol_goal_from_args(["2", "yes"], "w").clockwise is False  # only 'true' is true
    with pytest.raises(ParameterError, match=r"w: args must be '<radius> <clockwise>'"):
        patrol_goal_from_args(["1.5"], "w")
    with pytest.raises(ParameterError, match=r"w: radius 'wide' is not a number"):
        patrol_goal_from_args(["wide", "true"], "w")
    with pytest.raises(ParameterError, match=r"w: radius must be a positive number .* -1.0"):
        patrol_goal_from_args(["-1", "true"], "w")


def test_launched_in_a_robot_group_the_client_starts_an_endless_patrol(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "patrol.launch"
    path.write_text(
        LAUNCH.format(burger=ROBOTS / "turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro")
    )
    goals = []
    with LaunchSession(load_plan(path), seed=1) as s:
        s.runtime.graph.subscribe(
            "/karl/patrol_server/goal", grobot_utilities.Patrol.ActionGoal, goals.append
        )
        s.run(duration=1.9)
        assert goals == []  # rospy.sleep(2) first
        s.run(duration=0.4)
        assert len(goals) == 1
        goal = goals[0].goal
        assert (goal.radius, goal.clockwise, goal.num_patrols) == (pytest.approx(0.3), True, 0)
        assert 2.0 <= goals[0].header.stamp.to_sec() <= 2.1 + 1e-9
        s.run(duration=2 * 3.1416 * 0.3 / 0.1 + 2.0)
        client = s.nodes["/karl/patrol_client"]
        assert client.completed_patrols == 1 and not client.handle.done
        engine = s.nodes["/gazebo"].engine
        assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
