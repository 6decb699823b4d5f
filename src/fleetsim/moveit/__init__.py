"""move_group: planning scene, kinematics (IK), OMPL planning, time parameterisation,
execution; ``MoveGroupCommander`` and ``PlanningSceneInterface`` with moveit_commander's names."""

from fleetsim.moveit.commander import MoveGroupCommander, MoveItCommanderException
from fleetsim.moveit.move_group import MoveGroup
from fleetsim.moveit.robot_model import RobotModel
from fleetsim.moveit.scene_interface import PlanningSceneInterface

__all__ = [
    "MoveGroup",
    "MoveGroupCommander",
    "MoveItCommanderException",
    "PlanningSceneInterface",
    "RobotModel",
]
