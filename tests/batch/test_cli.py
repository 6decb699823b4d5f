"""`fleetsim batch`: bad input is a one-line error naming it, before any run (no Ray, no
output folder)."""

import re
from pathlib import Path

import pytest

from fleetsim.cli.main import main

FIXTURES = Path(__file__).parent / "fixtures"
TINY = str(FIXTURES / "tiny.launch")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["no_such_scenario"], r"unknown scenario 'no_such_scenario'"),
        ([TINY, "--arg", "sped=1,2"], r"declares no arg 'sped' \(did you mean 'speed'\?\)"),
        ([TINY, "--arg", "speed=3..1"], r"arg 'speed': range '3..1' is empty"),
        ([TINY, "--arg", "speed=1..z"], r"arg 'speed': malformed range '1..z'"),
        ([TINY, "--arg", "speed"], r"--arg 'speed' is not of the form NAME=V1,V2"),
        ([TINY, "--seeds", "4..2"], r"arg 'seeds': range '4..2' is empty"),
        ([TINY, "--timeout", "0"], r"timeout must be > 0 s"),
        ([TINY, "--workers", "0"], r"--workers must be >= 1"),
        (["run", TINY, "--metrics", "nope"], r"unknown scenario metrics 'nope'"),
    ],
)
def test_bad_input_is_named_before_any_run(argv, message, tmp_path: Path, capsys):
    out = tmp_path / "out"
    assert main(["batch", *argv, "-o", str(out)]) == 1
    err = capsys.readouterr().err.replace("\n", " ")
    assert re.search(message, err), err
    assert not (out / "results.csv").exists()


def test_a_spec_file_is_told_from_a_launch_file(tmp_path: Path, capsys):
    spec = tmp_path / "sweep.yaml"
    spec.write_text(f"scenarios: [{TINY}]\nargs: {{speed: [1, 2], spin: 0}}\n")
    assert main(["batch", str(spec), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err.replace("\n", " ")
    assert "sweep.yaml: scenario" in err and "declares no arg 'spin'" in err
    assert main(["batch", str(spec), "--arg", "speed=1"]) == 1
    assert "is a batch spec: put --arg and --seeds in it" in capsys.readouterr().err


def test_a_yaml_launch_file_is_not_taken_for_a_spec(tmp_path: Path, capsys):
    f = tmp_path / "one.yaml"
    f.write_text("launch:\n- arg: {name: speed, default: '0.2'}\n")
    assert main(["batch", str(f), "--arg", "sped=1", "-o", str(tmp_path / "out")]) == 1
    assert "declares no arg 'sped' (did you mean 'speed'?)" in capsys.readouterr().err


def test_the_closing_line_tells_runs_that_missed_goals_from_errors_and_successes():
    from fleetsim.cli.batch import closing_line

    def row(run, success, error=""):
        return {"run_id": run, "success": success, "error": error}

    rows = [
        row("a", True), row("a", None),  # a robot without goals does not spoil the run
        row("b", True), row("b", False),  # one robot collided or missed: the run missed
        row("c", False, "timed out: still running after 20 s"),
        row("d", None),  # no robot had goals: not judged
    ]  # fmt: skip
    assert closing_line(rows, "out") == (
        "4 runs (1 ended in an error; of the 2 with goals, 1 reached every goal without a "
        "collision): out/results.csv, out/results.parquet"
    )


@pytest.mark.parametrize(("error", "status"), [("", 0), ("RuntimeError: no world", 1)])
def test_a_batch_with_a_run_that_ended_in_an_error_exits_1(error, status, tmp_path, monkeypatch):
    """Every run erroring (a world file that does not exist) had exited 0."""
    from types import SimpleNamespace

    import fleetsim.batch

    rows = [{"run_id": "r0", "success": None, "error": ""}]
    rows.append({"run_id": "r1", "success": None, "error": error})
    monkeypatch.setattr(fleetsim.batch, "run_batch", lambda *a, **k: SimpleNamespace(rows=rows))
    assert main(["batch", TINY, "-o", str(tmp_path / "out"), "--no-progress"]) == status
