"""The tiny sweep the batch tests run: ``fixtures/tiny.launch`` (a lizi driven on an empty
world) for 1.5 s of sim time, speed 0.2 or 0.4 m/s give or take a few percent drawn from the
seed, seeds 0 and 1, so that every run's path length differs and a mixed-up row would show.
"""

from pathlib import Path

from fleetsim.batch import BatchSpec
from fleetsim.batch.results import WALL_CLOCK_COLUMNS

FIXTURES = Path(__file__).parent / "fixtures"


def tiny_spec(seeds=(0, 1), **kw) -> BatchSpec:
    args = kw.pop("args", {"speed": ["0.2", "0.4"]})
    return BatchSpec(
        scenarios=["tiny.launch"], args=args, seeds=list(seeds), duration=1.5, timeout=60.0,
        workdir=FIXTURES, **kw,
    )  # fmt: skip


def comparable(table) -> list[dict]:
    """The table's rows without what depends on the machine (wall time, real-time factor)."""
    return table.drop_columns(list(WALL_CLOCK_COLUMNS)).to_pylist()
