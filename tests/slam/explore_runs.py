"""What the slam_explore scenario tests share: the saved map scored against a world's true
occupancy, and the fleetsim loggers' records of a run."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from fleetsim.nav.map_io import load_map
from fleetsim.slam.quality import occupancy_precision_recall


def precision_recall(
    saved: Path, truth_yaml: Path, start: tuple[float, float]
) -> tuple[float, float]:
    """Occupied-cell precision and recall of the map saved at ``saved`` (map_saver's YAML)
    against the true map ``truth_yaml``, the robot having started at ``start`` (m)."""
    slam, truth = load_map(saved), load_map(truth_yaml)
    iy, ix = np.nonzero(slam.data == 100)
    xy = np.c_[
        slam.origin[0] + (ix + 0.5) * slam.resolution,
        slam.origin[1] + (iy + 0.5) * slam.resolution,
    ]
    p, r, _ = occupancy_precision_recall(
        xy, truth.data == 100, truth.resolution, truth.origin[:2], start
    )
    return p, r


class Records(logging.Handler):
    """The fleetsim loggers' records (the CLI replaces the root logger's handlers, caplog's)."""

    def __init__(self):
        super().__init__(logging.INFO)
        self.records: list[logging.LogRecord] = []

    def emit(self, record):
        self.records.append(record)
