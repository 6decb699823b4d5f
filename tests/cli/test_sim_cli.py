"""`fleetsim sim snapshot` writes a picture of a world."""

from pathlib import Path

import numpy as np
from PIL import Image
from typer.testing import CliRunner

from fleetsim.cli.sim import _robot_option, app
from fleetsim.errors import SimulationError

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[2].parent / "shared"

FIXTURE = "tests/sim/fixtures/diffbot.urdf"


def test_snapshot_of_a_barn_world_with_a_robot(tmp_path):
    out = tmp_path / "barn.png"
    res = CliRunner().invoke(
        app,
        [
            "snapshot",
            str(SHARED / "data/barn/world_3.world"),
            "-o",
            str(out),
            "--width",
            "320",
            "--height",
            "240",
            "--robot",
            f"{FIXTURE}:jackal:-2.25,3,1.57",
        ],
    )
    assert res.exit_code == 0, res.output
    assert "202 models" in res.output
    img = np.asarray(Image.open(out))
    assert img.shape == (240, 320, 3) and img.std() > 10


def test_bad_options():
    res = CliRunner().invoke(app, ["snapshot", "nothere.world"])
    assert res.exit_code != 0 and "world file 'nothere.world' not found" in str(res.exception)
    try:
        _robot_option("r.urdf:x:one,two")
    except SimulationError as exc:
        assert "pose must be X,Y[,YAW] numbers" in str(exc)
    else:
        raise AssertionError("no error")
    assert _robot_option("a/b.urdf.xacro") == ("a/b.urdf.xacro", "b", (0.0,) * 6)
