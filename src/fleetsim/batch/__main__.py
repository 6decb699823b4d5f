"""``python -m fleetsim.batch RUN OUT [RECORD]``: one run of a batch (see `fleetsim.batch.worker`).

The entry point is the package, not ``-m fleetsim.batch.worker``: the package imports the
worker module, and running a module that is already imported would load it twice.
"""

import sys

from fleetsim.batch.worker import main

sys.exit(main(sys.argv[1:]))
