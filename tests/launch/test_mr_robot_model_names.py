"""``include/mr_robot.launch`` (one robot of the multi-robot scenarios) takes the turtlebot3s
by their short names too, ``burger`` and ``waffle``, as ``one_robot.launch`` does: the same
robot, parameters and nodes as ``turtlebot3_burger`` / ``turtlebot3_waffle``. It took only the
package names, and ``model:=burger`` failed to find a ``burger`` package."""

from pathlib import Path

import pytest

from fleetsim.launch.runner import load_plan

ONE_ROBOT = """<launch>
  <group ns="tb1">
    <include file="$(find fleetsim_launch)/include/mr_robot.launch">
      <arg name="robot_name" value="tb1"/>
      <arg name="model" value="{model}"/>
      <arg name="x" value="1.0"/> <arg name="y" value="2.0"/> <arg name="yaw" value="0.0"/>
      <arg name="goal_x" value="5.0"/> <arg name="goal_y" value="2.0"/>
      <arg name="goal_yaw" value="0.0"/>
      <arg name="localization" value="amcl"/>
    </include>
  </group>
</launch>
"""


def plan_of(tmp_path: Path, model: str):
    path = tmp_path / f"{model}.launch"
    path.write_text(ONE_ROBOT.format(model=model))
    plan = load_plan(path)
    tree = plan.param_tree()
    params = {name: tree.get(name) for name in tree.names()}
    nodes = [(n.pkg, n.type, n.name, n.namespace, n.args, n.remaps) for n in plan.nodes]
    return params, nodes


@pytest.mark.parametrize("short", ["burger", "waffle"])
def test_short_turtlebot3_names_give_the_same_robot(tmp_path, short):
    params, nodes = plan_of(tmp_path, short)
    want_params, want_nodes = plan_of(tmp_path, f"turtlebot3_{short}")
    assert params == want_params
    assert nodes == want_nodes
    assert "turtlebot3" in params["/tb1/robot_description"]  # the turtlebot3's own URDF
