"""ros_control in the simulator: hardware interface, controller_manager, controllers, spawner.

``libgazebo_ros_control.so`` in a robot's URDF (with its ``<transmission>`` elements) gives the
robot a ``ControllerManager`` in its namespace (``fleetsim.sim.plugins.ros_control``); the
``controller_manager/spawner`` node loads and starts controllers configured in YAML.
"""

from fleetsim.control.controller_manager import ControllerManager
from fleetsim.control.controllers import CONTROLLER_TYPES, Controller
from fleetsim.control.hardware import SimRobotHW
from fleetsim.control.pid import Pid
from fleetsim.control.spawner import Spawner
from fleetsim.control.trajectory import Trajectory, sample

__all__ = [
    "CONTROLLER_TYPES",
    "Controller",
    "ControllerManager",
    "Pid",
    "SimRobotHW",
    "Spawner",
    "Trajectory",
    "sample",
]
