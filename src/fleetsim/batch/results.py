"""The results table of a batch: one row per run and robot, written as runs finish.

``results.csv`` is appended row by row (an interrupted batch loses nothing) and
``results.parquet`` is rewritten from all rows after each run, sorted by the run's place in the
sweep and the robot, through a temporary file and an atomic rename (a Parquet file is only
readable once its footer is written, so it cannot be appended to). A run that failed is one row
with its ``error``; ``--resume`` keeps the rows of the runs that finished without an error and
runs the others again.

Columns: ``run`` (place in the sweep), ``run_id``, ``scenario``, ``seed``, ``arg_<name>`` per
launch argument, the robot's results (`ROBOT_COLUMNS`), the scenario's metrics, ``error`` and
``run_dir`` (relative to the batch's output folder).
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from fleetsim.errors import BatchError

CSV = "results.csv"
PARQUET = "results.parquet"
ARG_PREFIX = "arg_"
TYPES = {"int": pa.int64(), "float": pa.float64(), "str": pa.string(), "bool": pa.bool_()}

RUN_COLUMNS = {"run": "int", "run_id": "str", "scenario": "str", "seed": "int"}
ROBOT_COLUMNS = {
    "robot": "str",  # namespace; "" for a run without robots or one that failed
    "success": "bool",  # every goal reached (ground truth) without a collision; null: no goals
    "goals_sent": "int",
    "goals_reached": "int",
    "time": "float",  # s of sim time at the robot's last goal result
    "path_length": "float",  # m, ground truth
    "collisions": "int",
    # each collision's onset: "14.70 s lizi5 at (7.82, 6.00)", "; "-separated (a robot-robot
    # contact is in both robots' rows)
    "collided_with": "str",
    "last_status": "str",
    "sim_time": "float",  # s of sim time the run lasted
    "wall_time": "float",  # s of wall time of the run's process (start-up included)
    "rtf": "float",  # real-time factor of the simulation loop
    "mujoco_warnings": "int",
}
TAIL_COLUMNS = {"error": "str", "run_dir": "str"}
#: columns added since the first release: a results file written before one of them was added
#: is resumed with it empty (collided_with: stop 52)
ADDED_COLUMNS = ("collided_with",)
#: columns that depend on the machine, not on the run: left out when comparing tables
WALL_CLOCK_COLUMNS = ("wall_time", "rtf")


def columns_for(arg_names: list[str], metric_columns: dict[str, str]) -> dict[str, str]:
    cols = dict(RUN_COLUMNS)
    cols.update({ARG_PREFIX + n: "str" for n in sorted(arg_names)})
    cols.update(ROBOT_COLUMNS)
    for name, kind in metric_columns.items():
        if name in cols or name in TAIL_COLUMNS:
            raise BatchError(f"scenario metrics column '{name}' clashes with a results column")
        if kind not in TYPES:
            raise BatchError(f"scenario metrics column '{name}': unknown type '{kind}'")
        cols[name] = kind
    cols.update(TAIL_COLUMNS)
    return cols


def _to_text(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "" if math.isnan(v) else repr(v)
    return str(v)


def _from_text(text: str, kind: str) -> Any:
    if text == "":
        return "" if kind == "str" else None
    if kind == "int":
        return int(text)
    if kind == "float":
        return float(text)
    if kind == "bool":
        return text == "true"
    return text


class ResultsTable:
    """The results of one batch in ``outdir`` (see the module docstring)."""

    def __init__(self, outdir: Path, columns: dict[str, str], resume: bool = False) -> None:
        self.outdir = Path(outdir)
        self.columns = columns
        self.schema = pa.schema([(n, TYPES[k]) for n, k in columns.items()])
        self.rows: list[dict[str, Any]] = []
        self.outdir.mkdir(parents=True, exist_ok=True)
        path = self.outdir / CSV
        if path.exists():
            if not resume:
                raise BatchError(
                    f"{path} already holds results: pass --resume to go on with them, or "
                    "choose another output folder (-o)"
                )
            self.rows = [r for r in self._read(path) if not r["error"]]
        self._rewrite_csv()
        self._write_parquet()

    def _read(self, path: Path) -> list[dict[str, Any]]:
        with path.open(newline="") as f:
            reader = csv.DictReader(f)
            have = list(reader.fieldnames or [])
            older = [c for c in self.columns if c in have or c not in ADDED_COLUMNS]
            if have != list(self.columns) and have != older:
                raise BatchError(
                    f"{path}: its columns ({', '.join(have)}) are not this batch's "
                    f"({', '.join(self.columns)}): it was written by another spec; "
                    "choose another output folder (-o)"
                )
            return [
                {k: _from_text(r.get(k, ""), self.columns[k]) for k in self.columns} for r in reader
            ]

    def finished(self) -> set[str]:
        """run_ids of the runs already in the table (finished without an error)."""
        return {r["run_id"] for r in self.rows}

    def reindex(self, index_of: dict[str, int]) -> int:
        """Renumber kept rows by their run's place in this sweep (``run_id -> run``), after a
        resume with a changed spec; returns how many rows belong to no run of the sweep (they
        are kept as they were)."""
        outside = 0
        for row in self.rows:
            if row["run_id"] in index_of:
                row["run"] = index_of[row["run_id"]]
            else:
                outside += 1
        self._rewrite_csv()
        self._write_parquet()
        return outside

    def append(self, rows: list[dict[str, Any]]) -> None:
        """Add one run's rows to both files."""
        for row in rows:
            unknown = set(row) - set(self.columns)
            if unknown:
                raise BatchError(f"results row has unknown columns {sorted(unknown)}")
        full = [{k: self._value(row, k) for k in self.columns} for row in rows]
        with (self.outdir / CSV).open("a", newline="") as f:
            w = csv.writer(f)
            for row in full:
                w.writerow([_to_text(row[k]) for k in self.columns])
            f.flush()
            os.fsync(f.fileno())
        self.rows.extend(full)
        self._write_parquet()

    def _value(self, row: dict[str, Any], key: str) -> Any:
        """A cell as it reads back from the CSV (text columns: "" rather than null)."""
        v = row.get(key)
        if self.columns[key] == "str":
            return "" if v is None else str(v)
        if self.columns[key] == "float" and v is not None:
            return None if math.isnan(float(v)) else float(v)
        return v

    def _rewrite_csv(self) -> None:
        tmp = self.outdir / (CSV + ".tmp")
        with tmp.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(list(self.columns))
            for row in self.rows:
                w.writerow([_to_text(row[k]) for k in self.columns])
        os.replace(tmp, self.outdir / CSV)

    def table(self) -> pa.Table:
        rows = sorted(self.rows, key=lambda r: (r["run"], r["robot"] or ""))
        return pa.Table.from_pylist(rows, schema=self.schema)

    def _write_parquet(self) -> None:
        tmp = self.outdir / (PARQUET + ".tmp")
        pq.write_table(self.table(), tmp)
        os.replace(tmp, self.outdir / PARQUET)


def read_results(path: str | Path) -> pa.Table:
    """A batch's results: its output folder, ``results.parquet`` or ``results.csv``."""
    path = Path(path)
    if path.is_dir():
        path = path / PARQUET if (path / PARQUET).exists() else path / CSV
    if not path.exists():
        raise BatchError(f"no batch results at {path} (give a batch's output folder)")
    if path.suffix == ".parquet":
        return pq.read_table(path)
    if path.suffix == ".csv":
        from pyarrow import csv as pacsv

        # arguments stay text, as they were given on the command line
        with path.open(newline="") as f:
            header = next(csv.reader(f), [])
        known = {**RUN_COLUMNS, **ROBOT_COLUMNS, **TAIL_COLUMNS}
        types = {c: TYPES[known[c]] for c in header if c in known}
        types.update({c: pa.string() for c in header if c.startswith(ARG_PREFIX)})
        options = pacsv.ConvertOptions(
            column_types=types, true_values=["true"], false_values=["false"]
        )
        return pacsv.read_csv(path, convert_options=options)
    raise BatchError(f"{path}: batch results are a .parquet or .csv file, or their folder")
