"""The results table: rows appended as runs finish, CSV and Parquet alike, resumable."""

from pathlib import Path

import pyarrow.parquet as pq
import pytest

from fleetsim.batch.results import ResultsTable, columns_for, read_results
from fleetsim.errors import BatchError

COLUMNS = columns_for(["speed"], {"barn_metric": "float"})


def row(run: int, run_id: str, error: str = "", **kw):
    base = {"run": run, "run_id": run_id, "scenario": "tiny", "seed": 0, "arg_speed": "0.1"}
    if error:
        return {**base, "robot": "", "success": False, "error": error}
    return {**base, "robot": "/lizi1", "path_length": 0.5, "time": None, "rtf": float("nan"), **kw}


def test_rows_reach_both_files_as_they_are_appended(tmp_path: Path):
    t = ResultsTable(tmp_path, COLUMNS)
    t.append([row(1, "b", barn_metric=0.25)])
    assert len(pq.read_table(tmp_path / "results.parquet")) == 1
    t.append([row(0, "a", success=True)])
    t.append([row(2, "c", error="timed out")])
    parquet = pq.read_table(tmp_path / "results.parquet").to_pylist()
    assert [r["run_id"] for r in parquet] == ["a", "b", "c"]  # sorted by place in the sweep
    assert parquet[1]["barn_metric"] == 0.25 and parquet[2]["error"] == "timed out"
    assert parquet[0]["rtf"] is None  # NaN is stored as null, as the CSV reads back
    lines = (tmp_path / "results.csv").read_text().splitlines()
    assert lines[0].split(",") == list(COLUMNS) and len(lines) == 4
    from_csv = read_results(tmp_path / "results.csv").to_pylist()  # in the order runs ended
    assert sorted(from_csv, key=lambda r: r["run"]) == parquet


def test_resume_keeps_finished_runs_and_drops_failed_ones(tmp_path: Path):
    t = ResultsTable(tmp_path, COLUMNS)
    t.append([row(0, "a", success=True), row(1, "b", error="crashed")])
    with pytest.raises(BatchError, match=r"already holds results: pass --resume"):
        ResultsTable(tmp_path, COLUMNS)
    again = ResultsTable(tmp_path, COLUMNS, resume=True)
    assert again.finished() == {"a"}
    assert again.table().to_pylist() == [t.table().to_pylist()[0]]
    assert len((tmp_path / "results.csv").read_text().splitlines()) == 2
    with pytest.raises(BatchError, match=r"written by another spec"):
        ResultsTable(tmp_path, columns_for(["turn"], {}), resume=True)


def test_bad_columns(tmp_path: Path):
    with pytest.raises(BatchError, match="'time' clashes with a results column"):
        columns_for([], {"time": "float"})
    with pytest.raises(BatchError, match="unknown type 'double'"):
        columns_for([], {"m": "double"})
    t = ResultsTable(tmp_path, COLUMNS)
    with pytest.raises(BatchError, match=r"unknown columns \['speed'\]"):
        t.append([{**row(0, "a"), "speed": 1}])
    with pytest.raises(BatchError, match="no batch results at"):
        read_results(tmp_path / "elsewhere")


def test_a_results_file_from_before_a_column_was_added_resumes_with_it_empty(tmp_path: Path):
    """A batch written before ``collided_with`` existed goes on with --resume (the column is
    empty in its rows); another spec's columns are still refused."""
    t = ResultsTable(tmp_path, COLUMNS)
    t.append([row(0, "a", success=True, path_length=2.5, collided_with="1.00 s lizi2")])
    lines = (tmp_path / "results.csv").read_text().splitlines()
    k = lines[0].split(",").index("collided_with")
    old = "\n".join(",".join(c for i, c in enumerate(line.split(",")) if i != k) for line in lines)
    (tmp_path / "results.csv").write_text(old + "\n")
    again = ResultsTable(tmp_path, COLUMNS, resume=True)
    assert again.finished() == {"a"} and again.rows[0]["collided_with"] == ""
    assert again.rows[0]["path_length"] == 2.5  # the columns after it read as they were
