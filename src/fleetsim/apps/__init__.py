"""Application nodes from the seeds, above the simulator and the navigation stack.

The visual servoing tutorial's (grobot's) nodes: ``patrol_server`` / ``patrol_client`` drive a
robot round a circle through the ``Patrol`` action; ``spawn_marker_on_robot`` puts an ArUco marker
on a robot's back; ``follow_marker`` follows it with move_base goals. fleetsim's own
``predictive_follower`` (issue 19) tracks the marker (`TargetTracker`) and keeps it in view with
a sampling MPC; ``patrol_route`` drives a patrol on move_base goals with stops. sim/ and nav/
never import this package.
"""

from fleetsim.apps.follow_marker import FollowMarker
from fleetsim.apps.patrol_client import PatrolClient
from fleetsim.apps.patrol_route import PatrolRoute
from fleetsim.apps.patrol_server import PatrolServer
from fleetsim.apps.predictive_follower import PredictiveFollower
from fleetsim.apps.spawn_marker_on_robot import SpawnMarkerOnRobot
from fleetsim.apps.target_tracker import TargetTracker

__all__ = [
    "FollowMarker",
    "PatrolClient",
    "PatrolRoute",
    "PatrolServer",
    "PredictiveFollower",
    "SpawnMarkerOnRobot",
    "TargetTracker",
]
