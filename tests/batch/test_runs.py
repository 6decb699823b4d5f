"""Batches on an embedded Ray: the same table serially and on 2 workers, resume, faults
(the tiny sweep of conftest.py)."""

from pathlib import Path

import pytest
from batch_sweep import FIXTURES, comparable, tiny_spec

from fleetsim.batch import run_batch

pytestmark = [pytest.mark.scenario, pytest.mark.timeout(300)]


def test_serial_rows_are_real_runs(serial):
    rows = serial.to_pylist()
    assert [(r["arg_speed"], r["seed"]) for r in rows] == [
        ("0.2", 0), ("0.2", 1), ("0.4", 0), ("0.4", 1),
    ]  # fmt: skip
    for r in rows:
        assert r["error"] == "" and r["robot"] == "/lizi1" and r["collisions"] == 0
        assert r["sim_time"] == pytest.approx(1.5) and r["mujoco_warnings"] == 0
        assert r["rtf"] > 0 and r["wall_time"] > 0
        assert r["success"] is None  # the robot had no goals
    lengths = [r["path_length"] for r in rows]
    assert len(set(lengths)) == 4  # the seed changes each run
    assert 0.15 < lengths[0] < 0.45 and 1.5 < lengths[2] / lengths[0] < 2.5
    assert not (FIXTURES / "MUJOCO_LOG.TXT").exists()


def test_two_workers_and_resume_give_the_serial_table(serial, tmp_path: Path):
    first = run_batch(tiny_spec(seeds=[1]), tmp_path, workers=2, progress=False)
    assert len(first.rows) == 2
    # the full sweep, resumed: only the two runs with seed 0 are left to run
    table = run_batch(tiny_spec(), tmp_path, workers=2, resume=True, progress=False)
    assert comparable(table.table()) == comparable(serial)
    for r in table.rows:
        assert (tmp_path / r["run_dir"] / "result.json").is_file()
        assert (tmp_path / r["run_dir"] / "log.txt").is_file()


def test_failed_runs_are_rows_with_the_reason_and_the_batch_finishes(tmp_path: Path):
    faults = ["none", "raise", "hang", "kill", "kill_parent"]
    spec = tiny_spec(seeds=[0], args={"fault": faults})
    spec.timeout = 20.0
    table = run_batch(spec, tmp_path, workers=2, progress=False, record=True)
    rows = {r["arg_fault"]: r for r in table.table().to_pylist()}
    assert sorted(rows) == sorted(faults)
    assert rows["none"]["error"] == "" and rows["none"]["path_length"] > 0.1
    assert (tmp_path / rows["none"]["run_dir"] / "run.mcap").stat().st_size > 1000
    assert rows["raise"]["error"] == "RuntimeError: drive: failing on purpose"
    assert "failing on purpose" in (tmp_path / rows["raise"]["run_dir"] / "log.txt").read_text()
    assert rows["hang"]["error"].startswith("timed out: still running after 20 s")
    assert rows["kill"]["error"] == "the run's process was killed by SIGKILL"
    assert "WorkerCrashedError" in rows["kill_parent"]["error"], rows["kill_parent"]["error"]
    for fault in faults[1:]:
        assert rows[fault]["success"] is False and rows[fault]["robot"] == ""
    lines = (tmp_path / "results.csv").read_text().splitlines()
    assert len(lines) == 1 + len(faults)
