"""Application nodes from the seeds, above the simulator and the navigation stack.

The visual servoing tutorial's (grobot's) nodes: ``patrol_server`` / ``patrol_client`` drive a
robot round a circle through the ``Patrol`` action. sim/ and nav/ never import this package.
"""

from fleetsim.apps.patrol_client import PatrolClient
from fleetsim.apps.patrol_server import PatrolServer

__all__ = ["PatrolClient", "PatrolServer"]
