"""spawn_model's command line, as gazebo_ros reads it."""

import pytest

from fleetsim.errors import SimulationError
from fleetsim.sim.spawn_model import parse_spawn_args


def test_lesson_form():
    args = "-x 20 -y 15 -z 0 -urdf -param /robot_description -model lizi1".split()
    s = parse_spawn_args(args)
    assert s["pose"] == [20.0, 15.0, 0.0, 0.0, 0.0, 0.0]
    assert s["param"] == "/robot_description" and s["model"] == "lizi1"
    assert "-urdf" in s["flags"]


def test_orientation_joints_and_namespace():
    s = parse_spawn_args(
        "-sdf -file m.sdf -model box -Y 1.5 -R 0.1 -robot_namespace /r -J j1 0.3 -unpause".split()
    )
    assert s["pose"][3] == 0.1 and s["pose"][5] == 1.5
    assert s["robot_namespace"] == "/r" and s["joints"] == {"j1": 0.3}
    assert {"-sdf", "-unpause"} <= s["flags"]


def test_wait_takes_a_model_name():
    # the tutorial's patrol_robot.xml: -wait ground_plane
    s = parse_spawn_args("-urdf -param d -model karl -wait ground_plane -x 1".split())
    assert s["wait"] == "ground_plane" and s["pose"][0] == 1.0
    with pytest.raises(SimulationError, match="'-wait' needs a value"):
        parse_spawn_args("-urdf -param d -model karl -wait".split())


def test_wait_holds_the_spawn_until_the_model_exists():
    from fleetsim.runtime import Runtime
    from fleetsim.sim.node import Simulator
    from fleetsim.sim.spawn_model import SpawnModel

    rt = Runtime(seed=0)
    sim = Simulator(rt)
    rt.params.set("/crate_description", CRATE)
    rt.params.set("/box_description", CRATE)
    first = SpawnModel(
        rt, "spawn_box", args="-sdf -param box_description -model box -wait crate -y 2".split()
    )
    rt.run(duration=0.5)
    assert not first.done and "box" not in sim.engine.models  # no crate yet
    SpawnModel(rt, "spawn_crate", args="-sdf -param crate_description -model crate".split())
    rt.run(duration=0.5)
    assert first.done and first.response.success and "box" in sim.engine.models


CRATE = """<sdf version="1.6"><model name="m"><static>true</static><link name="l">
  <collision name="c"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision>
  </link></model></sdf>"""


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ("-urdf -param d", "-model NAME is required"),
        ("-urdf -model a", "exactly one of -file, -param, -database"),
        ("-urdf -file a -param b -model a", "exactly one of"),
        ("-urdf -sdf -file a -model a", "one of -urdf and -sdf"),
        ("-urdf -file a -model a -x abc", "-x expects a number, got 'abc'"),
        ("-urdf -file a -model a -x nan", "-x must be finite"),
        ("-urdf -file a -model a -q 1", "unknown argument '-q'"),
        ("-urdf -file a -model", "'-model' needs a value"),
    ],
)
def test_bad_args_are_named(args, match):
    with pytest.raises(SimulationError, match=match):
        parse_spawn_args(args.split(), "/lizi1/spawn")
