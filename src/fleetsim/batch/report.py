"""`fleetsim batch report`: summaries of a batch's results table, and plots as PNG.

Rows are grouped by launch arguments (by default every argument the batch swept, and the
scenario when it ran several). Per group: rows (runs x robots), errors (runs that failed or
crashed), the success rate with its 95 % Wilson score interval (rows whose robot had goals, or
whose scenario decides success; failed runs count as failures), medians of time (successful
rows) and path length, collisions, and the mean of every numeric scenario metric.

Plots: success rate (with the interval) and median time against each swept argument
(``success_vs_<arg>.png``; against the robot, ``success_vs_robot.png``, when only the seed
varied), and, for BARN results, one stacked bar of outcomes per world with
its mean metric above it (``barn_worlds.png``), the figure the BARN papers show.
"""

from __future__ import annotations

import csv
import math
import statistics
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyarrow as pa
from scipy.stats import binomtest

from fleetsim.batch.results import ARG_PREFIX, ROBOT_COLUMNS, RUN_COLUMNS, TAIL_COLUMNS
from fleetsim.errors import BatchError, did_you_mean

CONFIDENCE = 0.95
SUMMARY = "summary.csv"


def wilson_interval(successes: int, n: int, confidence: float = CONFIDENCE):
    """The Wilson score interval (low, high) of a success rate (scipy's binomtest)."""
    if n == 0:
        return (math.nan, math.nan)
    ci = binomtest(successes, n).proportion_ci(confidence_level=confidence, method="wilson")
    return (float(ci.low), float(ci.high))


@dataclass
class GroupSummary:
    key: tuple[str, ...]
    rows: int = 0
    errors: int = 0
    judged: int = 0  # rows with a success value
    successes: int = 0
    ci: tuple[float, float] = (math.nan, math.nan)
    median_time: float = math.nan
    median_path: float = math.nan
    collisions: int = 0
    metrics: dict[str, float] = field(default_factory=dict)

    @property
    def success_rate(self) -> float:
        return self.successes / self.judged if self.judged else math.nan


def _median(values) -> float:
    values = [v for v in values if v is not None and not math.isnan(v)]
    return statistics.median(values) if values else math.nan


def metric_columns(table: pa.Table) -> list[str]:
    """Numeric columns a scenario added (not the run's, the robot's generic or the tail)."""
    fixed = set(RUN_COLUMNS) | set(ROBOT_COLUMNS) | set(TAIL_COLUMNS)
    return [
        f.name
        for f in table.schema
        if f.name not in fixed
        and not f.name.startswith(ARG_PREFIX)
        and (pa.types.is_floating(f.type) or pa.types.is_integer(f.type))
    ]


def swept(table: pa.Table) -> list[str]:
    """Columns the batch varied: arguments with several values, the scenario if several."""
    out = []
    for name in table.column_names:
        if (name.startswith(ARG_PREFIX) or name == "scenario") and len(
            set(table.column(name).to_pylist())
        ) > 1:
            out.append(name)
    return out


def group_columns(table: pa.Table, by: list[str] | None) -> list[str]:
    """``by`` as column names (``world`` or ``arg_world``), or the swept columns."""
    if not by:
        return swept(table)
    out = []
    for name in by:
        for col in (name, ARG_PREFIX + name):
            if col in table.column_names:
                out.append(col)
                break
        else:
            known = [c.removeprefix(ARG_PREFIX) for c in table.column_names]
            raise BatchError(
                f"--by '{name}': the results have no such argument or column"
                f"{did_you_mean(name, known)}; arguments: "
                + ", ".join(
                    c[len(ARG_PREFIX) :] for c in table.column_names if c.startswith(ARG_PREFIX)
                )
            )
    return out


def summarize(table: pa.Table, by: list[str]) -> list[GroupSummary]:
    rows = table.to_pylist()
    metrics = metric_columns(table)
    groups: dict[tuple, list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        groups[tuple(str(r[c]) for c in by)].append(r)
    out = []
    for key in sorted(groups, key=_sort_key):
        g = groups[key]
        s = GroupSummary(key, rows=len(g))
        s.errors = sum(bool(r["error"]) for r in g)
        judged = [r for r in g if r["success"] is not None]
        s.judged, s.successes = len(judged), sum(bool(r["success"]) for r in judged)
        s.ci = wilson_interval(s.successes, s.judged)
        s.median_time = _median(r["time"] for r in judged if r["success"])
        s.median_path = _median(r["path_length"] for r in g if not r["error"])
        s.collisions = sum(r["collisions"] or 0 for r in g)
        for m in metrics:
            values = [r[m] for r in g if r[m] is not None and not math.isnan(r[m])]
            s.metrics[m] = statistics.fmean(values) if values else math.nan
        out.append(s)
    return out


def _sort_key(key: tuple[str, ...]):
    """Numbers in numeric order, then text."""
    return tuple((0, float(k), "") if _is_number(k) else (1, 0.0, k) for k in key)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def write_summary(groups: list[GroupSummary], by: list[str], path: Path) -> None:
    metrics = list(groups[0].metrics) if groups else []
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(
            [c.removeprefix(ARG_PREFIX) for c in by]
            + ["rows", "errors", "judged", "successes", "success_rate", "ci_low", "ci_high"]
            + ["median_time", "median_path_length", "collisions"]
            + [f"mean_{m}" for m in metrics]
        )
        for g in groups:
            w.writerow(
                [*g.key, g.rows, g.errors, g.judged, g.successes, g.success_rate, *g.ci]
                + [g.median_time, g.median_path, g.collisions]
                + [g.metrics[m] for m in metrics]
            )


# -- plots ----------------------------------------------------------------------------------
def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_against(table: pa.Table, column: str, path: Path) -> None:
    """Success rate (Wilson interval as error bars) and median time against ``column``."""
    plt = _pyplot()
    groups = summarize(table, [column])
    labels = [g.key[0] for g in groups]
    numeric = all(_is_number(v) for v in labels)
    x = [float(v) for v in labels] if numeric else list(range(len(labels)))
    rate = [g.success_rate for g in groups]
    err = [
        [r - g.ci[0] if g.judged else 0 for r, g in zip(rate, groups)],
        [g.ci[1] - r if g.judged else 0 for r, g in zip(rate, groups)],
    ]
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.4, 6.0), sharex=True)
    # names (robots, scenarios) and integer values (world numbers, counts) are points, not a
    # curve between them
    curve = numeric and not all(float(v).is_integer() for v in labels)
    style = "o-" if curve else "o"
    a1.errorbar(x, rate, yerr=err, fmt=style, capsize=4)
    a1.set_ylim(-0.05, 1.05)
    a1.set_ylabel(f"success rate ({CONFIDENCE:.0%} Wilson CI)")
    a2.plot(x, [g.median_time for g in groups], style.replace("o", "s"), color="tab:orange")
    a2.set_ylabel("median time to goal [s]")
    name = column.removeprefix(ARG_PREFIX)
    a2.set_xlabel(name)
    if not numeric:
        a2.set_xticks(x, labels)
        a2.set_xlim(-0.5, len(x) - 0.5)
    a1.set_title(f"{len(table)} rows; success and time against {name}")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_barn(table: pa.Table, path: Path) -> None:
    """One stacked bar per BARN world: fractions of success, collision and timeout (aborted
    and failed runs counted with the timeouts), the world's mean metric above it."""
    plt = _pyplot()
    rows = table.to_pylist()
    worlds = sorted({r["arg_world"] for r in rows}, key=lambda w: float(w))
    kinds = {"success": "tab:green", "collision": "tab:red", "timeout": "tab:gray"}
    frac = {k: [] for k in kinds}
    mean_metric = []
    for w in worlds:
        rs = [r for r in rows if r["arg_world"] == w]
        outcome = [r["barn_outcome"] if r["barn_outcome"] in kinds else "timeout" for r in rs]
        for k in kinds:
            frac[k].append(outcome.count(k) / len(rs))
        mean_metric.append(statistics.fmean(r["barn_metric"] or 0.0 for r in rs))
    fig, ax = plt.subplots(figsize=(max(6.4, 0.35 * len(worlds) + 2), 4.0))
    x = list(range(len(worlds)))
    bottom = [0.0] * len(worlds)
    for k, color in kinds.items():
        ax.bar(x, frac[k], bottom=bottom, color=color, label=k)
        bottom = [b + f for b, f in zip(bottom, frac[k])]
    for xi, m in zip(x, mean_metric):
        ax.text(xi, 1.02, f"{m:.2f}", ha="center", fontsize=7, rotation=90, va="bottom")
    ax.set_xticks(x, worlds, rotation=90 if len(worlds) > 12 else 0)
    ax.set_xlabel("BARN world")
    ax.set_ylabel("fraction of runs")
    ax.set_ylim(0, 1.25)
    ax.legend(loc="upper right", ncol=3, fontsize=8)
    n = len(rows)
    ax.set_title(f"BARN: {n} runs, outcome per world (mean metric above each bar)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def report(
    table: pa.Table, by: list[str] | None, outdir: Path
) -> tuple[list[GroupSummary], list[str], list[Path]]:
    """Summaries grouped by ``by`` (default: the swept columns) and the plots; returns the
    groups, the grouping columns and the files written."""
    cols = group_columns(table, by)
    groups = summarize(table, cols)
    outdir.mkdir(parents=True, exist_ok=True)
    files = [outdir / SUMMARY]
    write_summary(groups, cols, files[0])
    # nothing swept (seeds only): each robot's success over the seeds, and its time
    for col in (swept(table) or ["robot"]) if not by else cols:
        p = outdir / f"success_vs_{col.removeprefix(ARG_PREFIX)}.png"
        plot_against(table, col, p)
        files.append(p)
    if {"barn_outcome", "barn_metric", "arg_world"} <= set(table.column_names):
        p = outdir / "barn_worlds.png"
        plot_barn(table, p)
        files.append(p)
    return groups, cols, files
