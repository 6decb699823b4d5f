"""Controllers by ros_control type name (``CONTROLLER_TYPES``)."""

from fleetsim.control.controllers import (  # noqa: F401  (registration side effects)
    forward,
    joint_state,
    joint_trajectory,
)
from fleetsim.control.controllers.base import CONTROLLER_TYPES, Controller, controller_class

__all__ = ["CONTROLLER_TYPES", "Controller", "controller_class"]
