"""BARN's protocol (../shared/data/barn/README.md) as scenario metrics for ``barn.launch``.

- success: the ground-truth position (``/jackal/ground_truth/state``, the simulator's p3d)
  within 1.0 m of the goal (-2.25, 13.0);
- collision: any contact of the jackal (the run's `RunMonitor`) ends the run as a failure;
- timeout: 100 s of simulated time pass; a goal move_base aborts ends the run early as
  ``aborted`` (counted with the timeouts: the robot would stand still until the 100 s pass);
- metric: success * optimal_time / clip(actual_time, 2 * optimal_time, 8 * optimal_time), with
  optimal_time = length of the reference path (``path_N.npy``, start and goal added) / 2 m/s.

The clock starts when the robot has moved 0.1 m from its start, as the BARN challenge's run
script does (the startup of the stack is not navigation time).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from fleetsim.batch.metrics import ScenarioMetrics
from fleetsim.errors import BatchError
from fleetsim.msgs import nav_msgs
from fleetsim.runtime import Node

START = (-2.25, 3.0)
GOAL = (-2.25, 13.0)
GOAL_RADIUS = 1.0  # m
TIME_LIMIT = 100.0  # s of sim time
MOVED = 0.1  # m from the start: the clock starts
OUTCOMES = ("success", "collision", "timeout", "aborted")


def path_from_grid(grid_path: np.ndarray) -> np.ndarray:
    """(K + 2, 2) reference path in the world frame (m): start, the (K, 2) grid path
    converted as the README gives it (x = 0.15 a - 4.575, y = 0.15 b + 5.075), goal."""
    g = np.asarray(grid_path, dtype=float)
    xy = np.column_stack([0.15 * g[:, 0] - 4.575, 0.15 * g[:, 1] + 5.075])
    return np.vstack([START, xy, GOAL])


def optimal_time_of(path: np.ndarray, speed: float = 2.0) -> float:
    """Optimal time (s): length (m) of the (K, 2) path over ``speed`` (m/s)."""
    return float(np.sum(np.hypot(*np.diff(path, axis=0).T))) / speed


def metric_of(success: bool, actual_time: float, optimal_time: float) -> float:
    """BARN's score of one run (0 on failure, at most 0.5)."""
    clipped = float(np.clip(actual_time, 2.0 * optimal_time, 8.0 * optimal_time))
    return float(success) * optimal_time / clipped


def _worlds_in(barn_dir: Path) -> str:
    numbers = sorted(int(p.stem.split("_")[1]) for p in barn_dir.glob("world_*.world"))
    if not numbers:
        return "none"
    return ", ".join(map(str, numbers[:8])) + (", ..." if len(numbers) > 8 else "")


class GroundTruth(Node):
    """The jackal's latest ground-truth (x, y) from its p3d, and where it first was."""

    def __init__(self, runtime) -> None:
        super().__init__(runtime, "barn_ground_truth", "/")
        self.xy: tuple[float, float] | None = None
        self.first: tuple[float, float] | None = None
        self.create_subscription(
            nav_msgs.Odometry, "/jackal/ground_truth/state", self._on_state, queue_size=1
        )

    def _on_state(self, msg) -> None:
        p = msg.pose.pose.position
        self.xy = (p.x, p.y)
        if self.first is None:
            self.first = self.xy


class BarnProtocol(ScenarioMetrics):
    """BARN's end conditions and per-run outcome, time and metric (see the module docstring)."""

    columns = {
        "barn_outcome": "str",
        "barn_time": "float",
        "barn_optimal_time": "float",
        "barn_metric": "float",
        "barn_final_gap": "float",
    }
    robot = "/jackal"

    @classmethod
    def check(cls, args: dict[str, str]) -> None:
        barn_dir = Path(args.get("barn_dir") or os.environ.get("FLEETSIM_BARN_DIR", ""))
        world = args.get("world", "3")
        for name in (f"world_{world}.world", f"path_{world}.npy"):
            if not (barn_dir / name).is_file():
                raise BatchError(
                    f"BARN world {world}: {barn_dir / name} does not exist (args world, "
                    f"barn_dir); worlds there: {_worlds_in(barn_dir)}"
                )

    def __init__(self, session, args: dict[str, str], time_limit: float = TIME_LIMIT) -> None:
        super().__init__(session, args)
        self.check(args)
        barn_dir = args.get("barn_dir") or os.environ.get("FLEETSIM_BARN_DIR", "")
        path = Path(barn_dir, f"path_{args.get('world', '3')}.npy")
        self.optimal = optimal_time_of(path_from_grid(np.load(path)))
        self.time_limit = time_limit
        self.truth = GroundTruth(session.runtime)
        self.started: float | None = None
        self.outcome = "timeout"
        self.over = False

    def done(self) -> bool:
        if self.over:
            return True
        truth, now = self.truth, self.session.runtime.now()
        if truth.xy is None:
            return False
        if self.started is None and math.dist(truth.xy, truth.first) >= MOVED:
            self.started = now
        robot = self.session.monitor.robots.get(self.robot)
        if robot is not None and robot.collisions > 0:
            self.outcome = "collision"
        elif math.dist(truth.xy, GOAL) <= GOAL_RADIUS:
            self.outcome = "success"
        elif robot is not None and robot.goals_failed > 0:
            self.outcome = "aborted"
        elif self.elapsed() < self.time_limit:
            return False
        self.over = True
        return True

    def elapsed(self) -> float:
        """s of sim time since the robot first moved 0.1 m (since 0 if it never did)."""
        return self.session.runtime.now() - (self.started or 0.0)

    def robot_metrics(self, robot) -> dict[str, Any]:
        if robot.namespace != self.robot:
            return {}
        elapsed = self.elapsed()
        success = self.over and self.outcome == "success"
        outcome = self.outcome if self.over else "unfinished"
        xy = self.truth.xy
        return {
            "success": success,
            "time": elapsed,  # the protocol's clock, not move_base's last result
            "barn_outcome": outcome,
            "barn_time": elapsed,
            "barn_optimal_time": self.optimal,
            "barn_metric": metric_of(success, elapsed, self.optimal),
            "barn_final_gap": math.dist(xy, GOAL) if xy is not None else float("nan"),
        }
