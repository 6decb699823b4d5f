"""One run in this process (what a batch's child process does): rows and BARN's metrics."""

import os
from pathlib import Path

import pytest

from fleetsim.batch.barn import optimal_time_of, path_from_grid
from fleetsim.batch.spec import RunSpec
from fleetsim.batch.worker import run_here

BARN_DIR = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "barn"


@pytest.mark.scenario
def test_a_barn_run_has_the_protocols_columns(tmp_path: Path, monkeypatch):
    import numpy as np

    monkeypatch.setenv("FLEETSIM_BARN_DIR", str(BARN_DIR))
    os.environ.setdefault("MUJOCO_GL", "egl")
    args = (("barn_dir", str(BARN_DIR)), ("gui", "false"), ("world", "3"))
    run = RunSpec(0, "barn", args, seed=0, duration=3.0, until_goals=False, metrics=None)
    (row,) = run_here(run, tmp_path)
    assert row["robot"] == "/jackal" and row["collisions"] == 0 and row["mujoco_warnings"] == 0
    assert row["sim_time"] == pytest.approx(3.0)
    # 3 s is far too short for the 10 m: the protocol's run is not over, so no success
    assert row["barn_outcome"] == "unfinished" and row["success"] is False
    assert row["barn_metric"] == 0.0 and 7.0 < row["barn_final_gap"] < 10.5
    expected = optimal_time_of(path_from_grid(np.load(BARN_DIR / "path_3.npy")))
    assert row["barn_optimal_time"] == pytest.approx(expected)
    assert 0.0 < row["time"] < 3.0  # the protocol's clock starts when the jackal has moved


def test_the_collided_with_column_names_each_onset():
    from fleetsim.batch.worker import collision_text

    events = [(14.7, "lizi5", 7.821, 6.0), (26.5, "map_walls", 8.16, 6.594)]
    assert collision_text(events) == (
        "14.70 s lizi5 at (7.82, 6.00); 26.50 s map_walls at (8.16, 6.59)"
    )
    assert collision_text([]) == ""
