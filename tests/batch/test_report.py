"""Batch reports: grouped success rates with Wilson intervals, medians, PNG plots."""

import math
from pathlib import Path

import pyarrow as pa
import pytest
from PIL import Image

from fleetsim.batch.report import report, summarize, swept, wilson_interval
from fleetsim.batch.results import columns_for
from fleetsim.cli.main import main
from fleetsim.errors import BatchError

COLUMNS = columns_for(["world", "gui"], {"barn_outcome": "str", "barn_metric": "float"})


def test_wilson_interval_matches_the_formula():
    # 8 of 10, z = 1.96: (p + z^2/2n -+ z sqrt(p(1-p)/n + z^2/4n^2)) / (1 + z^2/n)
    low, high = wilson_interval(8, 10)
    assert low == pytest.approx(0.4902, abs=1e-3) and high == pytest.approx(0.9433, abs=1e-3)
    assert all(math.isnan(v) for v in wilson_interval(0, 0))  # no rows, no rate


def barn_table() -> pa.Table:
    rows = []
    outcomes = {"3": ["success", "success", "collision"], "9": ["timeout", "success", "aborted"]}
    for world, outs in outcomes.items():
        for seed, out in enumerate(outs):
            rows.append(
                {
                    "run": len(rows), "run_id": f"r{len(rows)}", "scenario": "barn",
                    "seed": seed, "arg_world": world, "arg_gui": "false", "robot": "/jackal",
                    "success": out == "success", "time": 20.0 + seed, "path_length": 10.0,
                    "collisions": int(out == "collision"), "barn_outcome": out,
                    "barn_metric": 0.2 if out == "success" else 0.0, "error": "",
                }
            )  # fmt: skip
    rows.append({**rows[-1], "run": 6, "run_id": "r6", "seed": 3, "error": "timed out"})
    rows[-1].update(success=False, time=None, path_length=None, barn_outcome="", barn_metric=None)
    return pa.Table.from_pylist([{k: r.get(k) for k in COLUMNS} for r in rows])


def test_summary_by_world():
    table = barn_table()
    assert swept(table) == ["arg_world"]
    g3, g9 = summarize(table, ["arg_world"])
    assert (g3.key, g3.rows, g3.successes, g3.judged, g3.errors) == (("3",), 3, 2, 3, 0)
    assert (g9.rows, g9.successes, g9.judged, g9.errors) == (4, 1, 4, 1)
    assert g3.ci == wilson_interval(2, 3)
    assert g3.median_time == 20.5  # successful rows only
    assert g3.collisions == 1
    assert g9.metrics["barn_metric"] == pytest.approx(0.2 / 3)  # the failed run has no metric


def test_report_writes_summary_and_plots(tmp_path: Path):
    groups, cols, files = report(barn_table(), None, tmp_path)
    names = sorted(f.name for f in files)
    assert names == ["barn_worlds.png", "success_vs_world.png", "summary.csv"]
    for f in files:
        if f.suffix == ".png":
            w, h = Image.open(f).size
            assert w > 300 and h > 200
    lines = (tmp_path / "summary.csv").read_text().splitlines()
    assert lines[0].startswith("world,rows,errors,judged,successes,success_rate,ci_low")
    assert len(lines) == 3
    with pytest.raises(BatchError, match=r"--by 'wrld'.*did you mean 'world'"):
        report(barn_table(), ["wrld"], tmp_path)


def test_report_command(tmp_path: Path, capsys):
    import pyarrow.parquet as pq

    pq.write_table(barn_table(), tmp_path / "results.parquet")
    assert main(["batch", "report", str(tmp_path), "--by", "world"]) == 0
    out = capsys.readouterr()
    assert "2/3 (67%)" in out.out and "barn_worlds.png" in out.err
    assert main(["batch", "report", str(tmp_path / "none")]) == 1
    assert "no batch results at" in capsys.readouterr().err


def test_a_batch_of_seeds_only_is_plotted_per_robot(tmp_path: Path):
    rows = [
        {"run": k, "run_id": f"r{k // 2}", "scenario": "swap", "seed": k // 2, "arg_world": "3",
         "robot": f"/lizi{k % 2 + 1}", "success": k != 3,
         "time": 30.0 + k, "path_length": 12.0, "collisions": int(k == 3), "error": ""}
        for k in range(6)
    ]  # fmt: skip
    table = pa.Table.from_pylist([{c: r.get(c) for c in columns_for(["world"], {})} for r in rows])
    assert swept(table) == []
    _, cols, files = report(table, None, tmp_path)
    assert cols == [] and sorted(f.name for f in files) == ["success_vs_robot.png", "summary.csv"]
    by_robot = summarize(table, ["robot"])
    assert [(g.key, g.successes, g.judged) for g in by_robot] == [
        (("/lizi1",), 3, 3), (("/lizi2",), 2, 3),
    ]  # fmt: skip
    w, h = Image.open(tmp_path / "success_vs_robot.png").size
    assert w > 300 and h > 200
