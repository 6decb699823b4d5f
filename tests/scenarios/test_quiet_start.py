"""The shipped scenarios print no WARNING line in a normal run (issue 14, start-up without noise).

Each runs a little longer than the grace period during which missing transforms are waited for
(`fleetsim.tf.patience`), so that a transform that never arrives would still be reported here;
MuJoCo must not have warned either (its warning counters, and no ``MUJOCO_LOG.TXT``).
"""

import logging
from pathlib import Path

import pytest

from fleetsim.cli.launch import resolve_launch_file
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.tf.patience import GRACE

pytestmark = pytest.mark.scenario

BARN = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "barn"

SCENARIOS = [
    ("navigation_multi", {"localization": "fake"}),
    ("navigation_multi", {"localization": "amcl"}),
    ("pioneer_multi", {}),
    ("hunter_run", {}),
    ("barn", {"barn_dir": str(BARN), "gui": "false"}),
    ("bringup", {}),
    ("navigation", {}),
    ("patrols", {}),
    ("visual_servoing", {}),
    ("slam_explore", {}),
    ("swap_corridor", {}),
    ("swap_corridor", {"localization": "amcl"}),
    # the pioneers' local costmap reads the map in odom (it warned that it took the map as if
    # in odom, before the static layer placed it by tf)
    ("swap_corridor", {"robots": "2", "model": "pioneer3at", "localization": "amcl"}),
    ("circle", {}),
    ("willow_swap", {}),
]
# nav_stack is not here: it is the manual's include (gmapping and move_base, no robot), which
# hunter_run launch_nav_stack:=true brings up with its robot; alone it rightly warns that no
# robot pose arrives.


@pytest.mark.parametrize(
    ("name", "args"),
    SCENARIOS,
    ids=[f"{n}-{'-'.join(a.values()) or 'default'}" for n, a in SCENARIOS],
)
def test_a_normal_run_prints_no_warning(name, args, caplog, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    caplog.set_level(logging.INFO)
    with LaunchSession(load_plan(resolve_launch_file(name), args), seed=1) as s:
        s.run(duration=GRACE + 1.0)
        engine = s.nodes["/gazebo"].engine
        mujoco_warnings = {i: w.number for i, w in enumerate(engine.data.warning) if w.number}
        assert len(engine.models) >= 1  # the robots were spawned: the run is a real one
    noise = [f"{r.name}: {r.getMessage()}" for r in caplog.records if r.levelno >= logging.WARNING]
    assert noise == []
    assert mujoco_warnings == {}
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
