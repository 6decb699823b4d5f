"""The tiny sweep's serial table, run once for the tests that compare with it."""

import pytest
from batch_sweep import tiny_spec

from fleetsim.batch import run_batch


@pytest.fixture(scope="session")
def serial(tmp_path_factory):
    """The tiny sweep run on one worker."""
    out = tmp_path_factory.mktemp("serial")
    return run_batch(tiny_spec(), out, workers=1, progress=False).table()
