"""Every robot shipped in assets/robots spawns, stays upright and drives where it is told."""

from pathlib import Path

import numpy as np
import pytest

from fleetsim.description import load_robot
from fleetsim.sim import Engine
from fleetsim.sim.build import rpy_from_quat
from fleetsim.sim.plugins.base import DrivePlugin

from .conftest import unread

ROBOTS = Path(__file__).resolve().parents[2] / "src" / "fleetsim" / "assets" / "robots"
FILES = sorted(ROBOTS.glob("*/urdf/*.urdf.xacro"))


@pytest.mark.parametrize("path", FILES, ids=[p.parts[-3] for p in FILES])
def test_asset_robot_drives_upright(path):
    e = Engine(None)
    entry = e.spawn_robot("bot", load_robot(path))
    unread(e)
    drive = next(p for p in entry.plugins if isinstance(p, DrivePlugin))
    worst_tilt = 0.0
    for _ in range(30):
        drive.command(0.3, 0.0, e.time)
        e.advance(0.05)
        roll, pitch, _ = rpy_from_quat(e.model_pose("bot")[1])
        worst_tilt = max(worst_tilt, abs(roll), abs(pitch))
    pos, quat = e.model_pose("bot")
    assert worst_tilt < 0.1
    assert 0.3 < pos[0] < 0.5 and abs(pos[1]) < 0.05
    assert abs(rpy_from_quat(quat)[2]) < 0.1
    assert np.linalg.norm(e.model_twist("bot")[0][:2]) == pytest.approx(0.3, abs=0.05)
