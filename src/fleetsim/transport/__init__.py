"""The Zenoh transport: a runtime's graph shared with other processes, tools and machines.

`ZenohBridge` attaches a runtime (a simulation listens as a peer; ``fleetsim node run`` joins as
a client and follows its ``/clock``); `SimulationClient` is what the command-line tools use.
"""

from fleetsim.transport.bridge import ZenohBridge
from fleetsim.transport.client import SimulationClient
from fleetsim.transport.keys import DEFAULT_ENDPOINT, Keys, default_endpoint, no_simulation

__all__ = [
    "DEFAULT_ENDPOINT",
    "Keys",
    "SimulationClient",
    "ZenohBridge",
    "default_endpoint",
    "no_simulation",
]
