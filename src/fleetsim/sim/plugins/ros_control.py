"""The ROS side of ``libgazebo_ros_control.so``: a controller_manager per robot namespace.

``joint_actuation`` builds the actuators; this is what gazebo_ros_control does next, once the
robot is in the simulation: start the robot's ``controller_manager`` in its namespace. As
Gazebo loads ros_control's library by name, the controller_manager module is imported here by
name when the first robot with this plugin is spawned, so the simulator itself does not depend
on ``fleetsim.control``.
"""

from __future__ import annotations

import importlib

from fleetsim.sim.plugins.joint_actuation import JointActuationPlugin


def start_controller_managers(sim, entry) -> list:
    """A ``ControllerManager`` node for each ros_control plugin of ``entry`` (a spawned robot).

    Returns the nodes (each has ``destroy()``, called when the model is deleted)."""
    out = []
    for p in entry.plugins:
        if isinstance(p, JointActuationPlugin):
            control = importlib.import_module("fleetsim.control.controller_manager")
            out.append(control.ControllerManager(sim.runtime, p.ctx.namespace, sim=sim, plugin=p))
    return out
