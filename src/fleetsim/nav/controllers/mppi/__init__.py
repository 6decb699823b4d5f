"""Nav2's MPPI controller (``nav2_mppi_controller::MPPIController``) as a local planner."""

from fleetsim.nav.controllers.mppi.controller import PLUGIN, MPPIController
from fleetsim.nav.controllers.mppi.critics import CRITICS, Critic, CriticData
from fleetsim.nav.controllers.mppi.loading import load_mppi
from fleetsim.nav.controllers.mppi.params import AckermannConstraints, MPPIParams

__all__ = [
    "CRITICS",
    "PLUGIN",
    "AckermannConstraints",
    "Critic",
    "CriticData",
    "MPPIController",
    "MPPIParams",
    "load_mppi",
]
