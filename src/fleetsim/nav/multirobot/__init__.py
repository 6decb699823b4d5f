"""Multi-robot navigation: robots that know about each other (collvoid's design).

- `position_share`: the ``/position_share`` topic's table of neighbours (`NeighbourTable`,
  `PositionShare`);
- `me_publisher`: the node that shares a robot's pose, velocity and uncertainty-inflated
  footprint (`MePublisher`, ``collvoid/me_publisher`` in launch files);
- `orca`: ORCA half-planes and linear programs (`orca_halfplanes`, `orca_velocity`);
- `polygon_vo`: ORCA half-planes of robots as their footprints' Minkowski sum, collvoid's
  ``use_polygon_footprint`` (`pair_shapes`, `polygon_orca_halfplanes`, `shape_gaps`);
- `holonomic`: preferred velocity, static obstacle points, differential-drive tracking;
- `footprint_check`: static obstacles against the real footprint on a command's rollout
  (`first_collisions`, `footprint_safe_command`);
- `deadlock`: the priority rule above ORCA (`DeadlockRule`);
- `yielding`: where a robot that yields goes (`refuge`, back along its way to a wide place);
- `uncertainty`: amcl's particle spread as a radius (`uncertainty_radius`).

The local planner plugin is `fleetsim.nav.controllers.collvoid_planner.CollvoidLocalPlanner`
(its base side in `collvoid_drive`),
the costmap layer `fleetsim.nav.costmap.robots_layer.RobotsLayer`.
"""

from fleetsim.nav.multirobot.deadlock import DeadlockRule, priority_key
from fleetsim.nav.multirobot.footprint_check import first_collisions, footprint_safe_command
from fleetsim.nav.multirobot.me_publisher import MePublisher, MePublisherParams
from fleetsim.nav.multirobot.orca import orca_halfplanes, orca_velocity
from fleetsim.nav.multirobot.position_share import (
    TOPIC,
    Neighbour,
    NeighbourTable,
    PositionShare,
    neighbour_from_msg,
)
from fleetsim.nav.multirobot.uncertainty import uncertainty_radius
from fleetsim.nav.multirobot.yielding import passage_width, refuge, too_narrow

__all__ = [
    "TOPIC",
    "DeadlockRule",
    "MePublisher",
    "MePublisherParams",
    "Neighbour",
    "NeighbourTable",
    "PositionShare",
    "first_collisions",
    "footprint_safe_command",
    "neighbour_from_msg",
    "orca_halfplanes",
    "orca_velocity",
    "passage_width",
    "priority_key",
    "refuge",
    "too_narrow",
    "uncertainty_radius",
]
