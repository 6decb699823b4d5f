"""Metrics a scenario declares: its protocol's end conditions and extra columns per robot.

A scenario's metrics class watches a running session (`LaunchSession`), says when the
protocol's run is over (`ScenarioMetrics.done`) and adds columns to each robot's row of the
results table; it may also decide ``success`` by the protocol's own rule (BARN: within 1 m of
the goal by ground truth). Classes are found by name through `METRICS`, as launch nodes are
through the node registry: the scenario's name picks its metrics unless the spec names others
(``metrics: barn`` for a user's own BARN-like launch file).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any, ClassVar

from fleetsim.errors import BatchError, did_you_mean

#: metrics name (= the scenario it belongs to, by default) -> "module:Class"
METRICS: dict[str, str] = {
    "barn": "fleetsim.batch.barn:BarnProtocol",
}


class ScenarioMetrics:
    """Base of scenario metrics. ``columns`` maps each extra column to its type (``"float"``,
    ``"int"``, ``"str"`` or ``"bool"``), so the results table's schema is known before any run."""

    columns: ClassVar[dict[str, str]] = {}

    def __init__(self, session, args: dict[str, str]) -> None:
        self.session = session
        self.args = args

    @classmethod
    def check(cls, args: dict[str, str]) -> None:
        """Raise a `BatchError` if a run with these launch arguments cannot be scored (a
        missing reference file, ...): called for every combination before any run."""

    def done(self) -> bool:
        """True once the protocol's run is over (checked every few tenths of a sim second)."""
        return False

    def robot_metrics(self, robot) -> dict[str, Any]:
        """Extra columns for one robot (a `RobotResult`); ``success`` and ``time`` override
        the generic ones (the protocol's rule and clock)."""
        return {}


def metrics_class(name: str) -> type[ScenarioMetrics]:
    target = METRICS.get(name)
    if target is None:
        raise BatchError(
            f"unknown scenario metrics '{name}'{did_you_mean(name, METRICS)}; known: "
            f"{', '.join(METRICS)}"
        )
    module, _, attr = target.partition(":")
    return getattr(importlib.import_module(module), attr)


def metrics_name_for(scenario: str, metrics: str | None) -> str | None:
    """The metrics a run uses: the spec's, else the one registered for the scenario's name."""
    if metrics is not None:
        return metrics
    stem = Path(scenario).name.split(".")[0]
    return stem if stem in METRICS else None
