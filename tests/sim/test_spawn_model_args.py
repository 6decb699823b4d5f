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
