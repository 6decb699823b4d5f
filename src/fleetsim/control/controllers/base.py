"""Controller base class and the registry of controller types by their ros_control names.

A controller is a node named for itself in its controller_manager's namespace, so its topics
and parameters are where ros_control puts them (``/<ns>/arm_group_controller/command``, the
YAML under ``/<ns>/arm_group_controller``). Lifecycle, as ``controller_interface::Controller``:
``starting(t)``, ``update(t, dt)`` every physics step while running, ``stopping(t)``.
"""

from __future__ import annotations

from typing import Any, ClassVar

from fleetsim.errors import ControlError, did_you_mean
from fleetsim.runtime import Node

#: ros_control type name ("effort_controllers/JointTrajectoryController") -> class
CONTROLLER_TYPES: dict[str, type[Controller]] = {}


def register(*type_names: str):
    """Class decorator: make a controller loadable under its ros_control type names."""

    def deco(cls):
        for name in type_names:
            CONTROLLER_TYPES[name] = cls
        return cls

    return deco


def controller_class(type_name: str, where: str) -> type[Controller]:
    cls = CONTROLLER_TYPES.get(type_name)
    if cls is None:
        raise ControlError(
            f"{where}: controller type '{type_name}' does not exist"
            f"{did_you_mean(type_name, CONTROLLER_TYPES)}; available: "
            f"{', '.join(sorted(CONTROLLER_TYPES))}"
        )
    return cls


def interface_of(type_name: str) -> str:
    """The hardware interface a type name asks for: ``effort_controllers/...`` -> "effort"."""
    pkg = type_name.split("/", 1)[0]
    return {
        "effort_controllers": "effort",
        "position_controllers": "position",
        "velocity_controllers": "velocity",
    }.get(pkg, "state")


class Controller(Node):
    """Base of every controller; ``hw`` is the robot's ``SimRobotHW``."""

    PARAM_NAMESPACES: ClassVar[tuple[str, ...]] = ("type",)

    def __init__(self, runtime, name: str, namespace: str, *, hw, type_name: str) -> None:
        self.hw = hw
        self.type_name = type_name
        self.interface = interface_of(type_name)
        self.running = False
        super().__init__(runtime, name, namespace)

    def claimed(self) -> list[str]:
        """The joints whose commands this controller owns (none for state controllers)."""
        return []

    def starting(self, t: float) -> None:
        """Called once when the controller is started (sim time t, s)."""

    def update(self, t: float, dt: float) -> None:
        """Called every physics step while running (sim time t, period dt, s)."""

    def stopping(self, t: float) -> None:
        """Called once when the controller is stopped."""

    def _require(self, value: Any, key: str) -> Any:
        if value in (None, "", [], {}):
            raise ControlError(
                f"{self.full_name}: parameter '{key}' not set (namespace: {self.full_name}); "
                "load the controller's YAML with <rosparam> before spawning it"
            )
        return value
