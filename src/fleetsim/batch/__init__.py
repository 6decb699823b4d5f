"""Batch experiments on Ray: sweeps of scenarios, launch arguments and seeds.

`load_spec` / `BatchSpec` say what to run, `run_batch` runs it (each run headless in its own
process, as a Ray task, locally or on a cluster) into a results table (`read_results`), and
`fleetsim.batch.report` summarises and plots it.
"""

from fleetsim.batch.results import ResultsTable, read_results
from fleetsim.batch.runs import run_batch
from fleetsim.batch.spec import BatchSpec, RunSpec, load_spec, parse_cli_args, parse_seeds

__all__ = [
    "BatchSpec",
    "ResultsTable",
    "RunSpec",
    "load_spec",
    "parse_cli_args",
    "parse_seeds",
    "read_results",
    "run_batch",
]
