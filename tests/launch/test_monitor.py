"""The run monitor counts goals for robots whose move_base is not in the launch plan."""

import os
from pathlib import Path

from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import actionlib_msgs, move_base_msgs
from fleetsim.runtime import Node

#: the simulator and one lizi, no move_base: it would run in another process (node run)
ROBOT_ONLY = """<launch>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="gui" value="false"/>
  </include>
  <group ns="lizi1">
    <param name="tf_prefix" value="lizi1"/>
    <param name="robot_description"
           command="$(find xacro)/xacro $(find lizi)/urdf/lizi.urdf.xacro"/>
    <node name="spawn_urdf" pkg="gazebo_ros" type="spawn_model"
          args="-x 1 -y 2 -z 0.078 -urdf -param robot_description -model lizi1"/>
  </group>
</launch>
"""


def test_a_spawned_robot_without_move_base_in_the_plan_has_its_goals_counted(tmp_path: Path):
    os.environ.setdefault("MUJOCO_GL", "egl")
    f = tmp_path / "robot_only.launch"
    f.write_text(ROBOT_ONLY)
    with LaunchSession(load_plan(f), seed=1) as s:
        s.runtime.run(duration=0.3)  # the robot is spawned and sampled
        mb = move_base_msgs.MoveBase
        stand_in = Node(s.runtime, "move_base", "/lizi1")  # what a remote move_base publishes
        goal_pub = stand_in.create_publisher(mb.ActionGoal, "move_base/goal", 1)
        result_pub = stand_in.create_publisher(mb.ActionResult, "move_base/result", 1)
        assert not s.monitor.all_goals_done()
        goal_pub.publish(mb.ActionGoal(goal_id=actionlib_msgs.GoalID(id="g1")))
        s.runtime.run(duration=0.1)
        r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
        assert (r.model, r.goals_sent, r.goals_reached) == ("lizi1", 1, 0)
        assert not s.monitor.all_goals_done()
        status = actionlib_msgs.GoalStatus(
            goal_id=actionlib_msgs.GoalID(id="g1"), status=actionlib_msgs.GoalStatus.SUCCEEDED
        )
        result_pub.publish(mb.ActionResult(status=status))
        s.runtime.run(duration=0.1)
        assert (r.goals_sent, r.goals_reached, r.goals_failed) == (1, 1, 0)
        assert s.monitor.all_goals_done() and s.monitor.success()
