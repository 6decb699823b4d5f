"""JointPositionController (effort PID) and JointGroupPositionController on a small arm."""

import logging

import numpy as np
import pytest

from fleetsim.control.spawner import Spawner, parse_spawner_args
from fleetsim.description import load_robot
from fleetsim.errors import ControlError
from fleetsim.msgs import control_msgs, std_msgs

from .conftest import SIM_FIXTURES

CONFIG = {
    "slider_position": {
        "type": "effort_controllers/JointPositionController",
        "joint": "slider",
        "pid": {"p": 400.0, "d": 40.0, "i": 0.0},
    },
    "shoulder_group": {
        "type": "position_controllers/JointGroupPositionController",
        "joints": ["shoulder"],
    },
    "wrist_velocity": {
        "type": "velocity_controllers/JointGroupVelocityController",
        "joints": ["wrist"],
    },
}


@pytest.fixture
def arm(world):
    world.spawn("arm", load_robot(SIM_FIXTURES / "arm.urdf"), (0, 0, 0, 0, 0, 0), CONFIG)
    sp = Spawner(world.rt, "spawner", "/arm", args=list(CONFIG))
    world.rt.run(0.2)
    assert sp.done and not sp.failed
    return world


def test_commands_reach_the_joints(arm):
    state = arm.collect(control_msgs.JointControllerState, "/arm/slider_position/state")
    pub = arm.probe.create_publisher(std_msgs.Float64, "/arm/slider_position/command")
    grp = arm.probe.create_publisher(std_msgs.Float64MultiArray, "/arm/shoulder_group/command")
    vel = arm.probe.create_publisher(std_msgs.Float64MultiArray, "/arm/wrist_velocity/command")
    pub.publish(std_msgs.Float64(0.1))
    grp.publish(std_msgs.Float64MultiArray(data=np.array([0.7])))
    vel.publish(std_msgs.Float64MultiArray(data=np.array([1.5])))
    arm.rt.run(1.5)
    hw = arm.cm("arm").hw
    assert hw.positions(["slider"])[0] == pytest.approx(0.1, abs=0.005)
    assert hw.positions(["shoulder"])[0] == pytest.approx(0.7, abs=0.02)
    # forwarded to the wrist's velocity servo (the fixture's 1 g hand makes that servo ring at
    # its force limit, so its speed is not checked here)
    assert hw.plugin.targets["wrist"] == 1.5
    assert state[-1].set_point == pytest.approx(0.1) and state[-1].p == 400.0
    pub.publish(std_msgs.Float64(5.0))  # beyond the slider's 0.2 m limit: clamped
    arm.rt.run(1.0)
    assert hw.positions(["slider"])[0] == pytest.approx(0.2, abs=0.01)


def test_bad_group_command_is_refused(arm, caplog):
    grp = arm.probe.create_publisher(std_msgs.Float64MultiArray, "/arm/shoulder_group/command")
    with caplog.at_level(logging.ERROR):
        grp.publish(std_msgs.Float64MultiArray(data=np.array([0.1, 0.2])))
        arm.rt.run(0.1)
    assert "Dimension of command (2) does not match number of joints (1)" in caplog.text


def test_spawner_arguments_and_failures(world, caplog):
    assert parse_spawner_args(["a", "--stopped", "--shutdown-timeout", "2", "b"], "s") == {
        "controllers": ["a", "b"],
        "stopped": True,
        "timeout": 30.0,
        "namespace": None,
    }
    with pytest.raises(ControlError, match="unknown option '--fast'"):
        parse_spawner_args(["a", "--fast"], "s")
    with pytest.raises(ControlError, match="no controller names"):
        parse_spawner_args(["--stopped"], "s")
    world.spawn("arm", load_robot(SIM_FIXTURES / "arm.urdf"), (0, 0, 0, 0, 0, 0), CONFIG)
    stopped = Spawner(world.rt, "s1", "/arm", args=["shoulder_group", "--stopped"])
    missing = Spawner(world.rt, "s2", "/arm", args=["no_such_controller"])
    lost = Spawner(world.rt, "s3", "/elsewhere", args=["x", "--timeout", "0.5"])
    with caplog.at_level(logging.ERROR):
        world.rt.run(1.0)
    assert stopped.done and not world.cm("arm").controllers["shoulder_group"].running
    assert missing.failed == "Failed to load no_such_controller"
    assert "namespace: '/arm/no_such_controller'" in caplog.text
    assert "/elsewhere/controller_manager/load_controller" in lost.failed
