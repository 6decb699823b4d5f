"""controller_manager_msgs: the controller_manager's services (ROS 1 ros_control layout)."""

from __future__ import annotations

from typing import ClassVar

from fleetsim.msgs.fields import Seq, bool_, float64, int32, string
from fleetsim.msgs.interfaces import make_srv_type
from fleetsim.msgs.registry import message


@message("controller_manager_msgs/msg/HardwareInterfaceResources")
class HardwareInterfaceResources:
    hardware_interface: string
    resources: Seq[string]


@message("controller_manager_msgs/msg/ControllerState")
class ControllerState:
    """One loaded controller: ``state`` is "running", "stopped" or "initialized"."""

    name: string
    state: string
    type: string
    claimed_resources: Seq[HardwareInterfaceResources]


@message("controller_manager_msgs/srv/ListControllers_Request")
class ListControllersRequest:
    pass


@message("controller_manager_msgs/srv/ListControllers_Response")
class ListControllersResponse:
    controller: Seq[ControllerState]


ListControllers = make_srv_type(
    "controller_manager_msgs/srv/ListControllers", ListControllersRequest, ListControllersResponse
)


@message("controller_manager_msgs/srv/ListControllerTypes_Request")
class ListControllerTypesRequest:
    pass


@message("controller_manager_msgs/srv/ListControllerTypes_Response")
class ListControllerTypesResponse:
    types: Seq[string]
    base_classes: Seq[string]


ListControllerTypes = make_srv_type(
    "controller_manager_msgs/srv/ListControllerTypes",
    ListControllerTypesRequest,
    ListControllerTypesResponse,
)


@message("controller_manager_msgs/srv/LoadController_Request")
class LoadControllerRequest:
    name: string


@message("controller_manager_msgs/srv/LoadController_Response")
class LoadControllerResponse:
    ok: bool_


LoadController = make_srv_type(
    "controller_manager_msgs/srv/LoadController", LoadControllerRequest, LoadControllerResponse
)


@message("controller_manager_msgs/srv/UnloadController_Request")
class UnloadControllerRequest:
    name: string


@message("controller_manager_msgs/srv/UnloadController_Response")
class UnloadControllerResponse:
    ok: bool_


UnloadController = make_srv_type(
    "controller_manager_msgs/srv/UnloadController",
    UnloadControllerRequest,
    UnloadControllerResponse,
)


@message("controller_manager_msgs/srv/SwitchController_Request")
class SwitchControllerRequest:
    BEST_EFFORT: ClassVar[int32] = 1
    STRICT: ClassVar[int32] = 2

    start_controllers: Seq[string]
    stop_controllers: Seq[string]
    strictness: int32
    start_asap: bool_
    timeout: float64


@message("controller_manager_msgs/srv/SwitchController_Response")
class SwitchControllerResponse:
    ok: bool_


SwitchController = make_srv_type(
    "controller_manager_msgs/srv/SwitchController",
    SwitchControllerRequest,
    SwitchControllerResponse,
)
