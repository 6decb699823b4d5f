"""gazebo_ros_control joint actuation (position, velocity, effort) and joint states."""

import pytest

from fleetsim.description import load_robot
from fleetsim.errors import SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.plugins.base import JointStateReading
from fleetsim.sim.plugins.joint_actuation import JointActuationPlugin

from ..conftest import FIXTURES


@pytest.fixture
def arm():
    e = Engine(None)
    entry = e.spawn_robot("arm", load_robot(FIXTURES / "arm.urdf"), (0, 0, 0, 0, 0, 0))
    ctl = next(p for p in entry.plugins if isinstance(p, JointActuationPlugin))
    return e, ctl


def test_position_velocity_and_effort_interfaces(arm):
    e, ctl = arm
    assert ctl.modes == {"shoulder": "position", "wrist": "velocity", "slider": "effort"}
    ctl.command("shoulder", 0.8)
    ctl.command("wrist", 1.5)
    ctl.command("slider", 5.0)
    readings = e.advance(1.0)
    states = ctl.states(e)
    assert states["shoulder"][0] == pytest.approx(0.8, abs=0.02)
    assert states["wrist"][1] == pytest.approx(1.5, abs=0.05)
    assert states["slider"][0] == pytest.approx(0.2, abs=0.01)  # pushed to its limit
    js = [r for r in readings if isinstance(r, JointStateReading)][-1]
    assert js.topic == "joint_states" and js.names == ["shoulder", "wrist", "slider"]
    assert js.position[0] == pytest.approx(0.8, abs=0.02)
    assert js.effort[2] == pytest.approx(5.0)


def test_bad_commands(arm):
    e, ctl = arm
    with pytest.raises(SimulationError, match="no actuated joint 'elbow'"):
        ctl.command("elbow", 1.0)
    with pytest.raises(SimulationError, match="command for 'wrist' must be finite"):
        ctl.command("wrist", float("nan"))


def test_update_hook_runs_a_pd_loop_at_the_physics_rate(arm):
    e, ctl = arm
    calls = []

    def pd(plugin, engine, t):
        pos, vel = plugin.states(engine)["slider"]
        plugin.command("slider", 200.0 * (0.1 - pos) - 20.0 * vel)
        calls.append(t)

    ctl.add_update_hook(pd)
    e.advance(1.0)
    assert len(calls) == round(1.0 / e.model.opt.timestep)
    assert ctl.states(e)["slider"][0] == pytest.approx(0.1, abs=0.005)
