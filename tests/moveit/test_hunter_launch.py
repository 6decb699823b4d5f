"""The robocluedo_robot_hunter launch files with the manual's names: run2.launch with the
simulator and with fake execution, and two hunters moving their arms at once."""

import logging

import numpy as np
import pytest

from fleetsim.launch.packages import default_finder
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.moveit import MoveGroupCommander
from fleetsim.msgs import sensor_msgs

from .conftest import assert_no_mujoco_warnings

pytestmark = pytest.mark.scenario
PKG = default_finder()("robocluedo_robot_hunter")


def session(name: str, **args: str) -> LaunchSession:
    return LaunchSession(load_plan(PKG / "launch" / name, args), seed=1)


def test_launch_files_have_the_manuals_names():
    names = {p.name for p in (PKG / "launch").glob("*.launch")}
    assert {
        "gazebo.launch", "demo.launch", "demo_gazebo.launch", "gazebo2.launch",
        "move_group.launch", "run2.launch",
    } <= names  # fmt: skip


def test_run2_gazebo_moves_the_arm_through_the_physics(caplog):
    with (
        caplog.at_level(logging.WARNING),
        session("run2.launch", sim_type="gazebo", launch_nav_stack="false") as s,
    ):
        s.run(duration=1.0)
        arm = MoveGroupCommander("arm_group", runtime=s.runtime)
        arm.set_named_target("cam_right")
        assert arm.go(), arm.last_result()
        np.testing.assert_allclose(
            arm.get_current_joint_values(), [-3.14, 0.1293, -0.4276, 0.2486], atol=0.01
        )
        assert_no_mujoco_warnings(s.monitor.sim.engine)
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING], caplog.text


def test_run2_rviz_moves_the_arm_with_fake_execution():
    with session("run2.launch", sim_type="rviz") as s:
        states = []
        s.runtime.graph.subscribe("/joint_states", sensor_msgs.JointState, states.append, 10, None)
        s.run(duration=0.5)
        assert "/gazebo" not in s.runtime.graph.nodes
        arm = MoveGroupCommander("arm_group", runtime=s.runtime)
        # fake_controllers.yaml's initial: the arm starts at home, as the manual's config has it
        np.testing.assert_allclose(
            arm.get_current_joint_values(),
            list(arm.get_named_target_values("home").values()),
            atol=1e-9,
        )
        arm.set_named_target("cam_back")
        assert arm.go()
        s.run(duration=0.2)
        last = dict(zip(states[-1].name, states[-1].position, strict=True))
        np.testing.assert_allclose(
            [last[j] for j in arm.get_active_joints()], [1.6828, 0.1293, -0.4276, 0.2486], atol=1e-6
        )


def test_two_hunters_in_two_namespaces():
    with session("two_hunters.launch") as s:
        s.run(duration=1.0)
        a1 = MoveGroupCommander("arm_group", ns="/hunter1", runtime=s.runtime)
        a2 = MoveGroupCommander("arm_group", ns="/hunter2", runtime=s.runtime)
        a1.set_named_target("cam_left")
        a2.set_named_target("cam_low")
        a1.go(wait=False)
        a2.go(wait=False)
        s.runtime.run(
            duration=40.0, until=lambda: a1._last.result is not None and a2._last.result is not None
        )
        assert a1._last.result.error_code.val == 1 and a2._last.result.error_code.val == 1
        assert (
            s.runtime.graph.nodes["/hunter1/controller_manager"]
            is not s.runtime.graph.nodes["/hunter2/controller_manager"]
        )


def test_run2_refuses_a_misspelt_sim_type_and_amcl_replaces_the_nav_stack():
    """``sim_type:=gazbo`` had started nothing and run on in silence; ``launch_amcl:=true``
    alone had been ignored (gmapping ran, no amcl) unless the nav stack was also turned off;
    an SDF world given to map_server says it needs a map YAML."""
    from fleetsim.errors import FleetsimError
    from fleetsim.nav.map_io import MapError, load_map

    with pytest.raises(FleetsimError, match="allowed values: gazebo, rviz, gazeborviz"):
        load_plan(PKG / "launch" / "run2.launch", {"sim_type": "gazbo"})
    plan = load_plan(PKG / "launch" / "run2.launch", {"launch_amcl": "true"})
    types = {(n.pkg, n.type) for n in plan.nodes}
    assert ("amcl", "amcl") in types and ("map_server", "map_server") in types
    assert ("gmapping", "slam_gmapping") not in types
    assert [t for t in types if t == ("move_base", "move_base")] == [("move_base", "move_base")]
    plan = load_plan(PKG / "launch" / "run2.launch", {})
    assert ("gmapping", "slam_gmapping") in {(n.pkg, n.type) for n in plan.nodes}
    from fleetsim.description.packages import ASSET_ROBOTS

    world = ASSET_ROBOTS.parent / "worlds" / "example.world"
    assert world.is_file()
    with pytest.raises(MapError, match="needs a map YAML .* not a .world file"):
        load_map(world)
