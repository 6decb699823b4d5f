"""gazebo_msgs: model/link states, contacts, and the ``/gazebo/...`` world services.

Field layouts follow ROS 1 gazebo_msgs (which ROS 2's gazebo_msgs keeps for these types).
"""

from __future__ import annotations

from fleetsim.msgs.fields import Seq, bool_, float64, string
from fleetsim.msgs.geometry_msgs import Pose, Twist, Vector3, Wrench
from fleetsim.msgs.interfaces import make_srv_type
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("gazebo_msgs/msg/ModelState")
class ModelState:
    """Pose and twist of a model in ``reference_frame`` ("" or "world": the world frame)."""

    model_name: string
    pose: Pose
    twist: Twist
    reference_frame: string


@message("gazebo_msgs/msg/ModelStates")
class ModelStates:
    """All models' world poses and twists, by ``name`` (``/gazebo/model_states``)."""

    name: Seq[string]
    pose: Seq[Pose]
    twist: Seq[Twist]


@message("gazebo_msgs/msg/LinkState")
class LinkState:
    """Pose and twist of a link (``model::link``) in ``reference_frame``."""

    link_name: string
    pose: Pose
    twist: Twist
    reference_frame: string


@message("gazebo_msgs/msg/LinkStates")
class LinkStates:
    name: Seq[string]
    pose: Seq[Pose]
    twist: Seq[Twist]


@message("gazebo_msgs/msg/ContactState")
class ContactState:
    """Contacts between two collisions: per-point wrenches, positions, normals, depths (m)."""

    info: string
    collision1_name: string
    collision2_name: string
    wrenches: Seq[Wrench]
    total_wrench: Wrench
    contact_positions: Seq[Vector3]
    contact_normals: Seq[Vector3]
    depths: Seq[float64]


@message("gazebo_msgs/msg/ContactsState")
class ContactsState:
    header: Header
    states: Seq[ContactState]


@message("gazebo_msgs/srv/SpawnModel_Request")
class SpawnModelRequest:
    """Spawn ``model_xml`` (URDF or SDF text) as ``model_name`` at ``initial_pose``."""

    model_name: string
    model_xml: string
    robot_namespace: string
    initial_pose: Pose
    reference_frame: string


@message("gazebo_msgs/srv/SpawnModel_Response")
class SpawnModelResponse:
    success: bool_
    status_message: string


SpawnModel = make_srv_type("gazebo_msgs/srv/SpawnModel", SpawnModelRequest, SpawnModelResponse)


@message("gazebo_msgs/srv/DeleteModel_Request")
class DeleteModelRequest:
    model_name: string


@message("gazebo_msgs/srv/DeleteModel_Response")
class DeleteModelResponse:
    success: bool_
    status_message: string


DeleteModel = make_srv_type("gazebo_msgs/srv/DeleteModel", DeleteModelRequest, DeleteModelResponse)


@message("gazebo_msgs/srv/GetModelState_Request")
class GetModelStateRequest:
    """State of ``model_name`` relative to ``relative_entity_name`` ("" or "world": world)."""

    model_name: string
    relative_entity_name: string


@message("gazebo_msgs/srv/GetModelState_Response")
class GetModelStateResponse:
    header: Header
    pose: Pose
    twist: Twist
    success: bool_
    status_message: string


GetModelState = make_srv_type(
    "gazebo_msgs/srv/GetModelState", GetModelStateRequest, GetModelStateResponse
)


@message("gazebo_msgs/srv/SetModelState_Request")
class SetModelStateRequest:
    model_state: ModelState


@message("gazebo_msgs/srv/SetModelState_Response")
class SetModelStateResponse:
    success: bool_
    status_message: string


SetModelState = make_srv_type(
    "gazebo_msgs/srv/SetModelState", SetModelStateRequest, SetModelStateResponse
)


@message("gazebo_msgs/srv/GetLinkState_Request")
class GetLinkStateRequest:
    link_name: string
    reference_frame: string


@message("gazebo_msgs/srv/GetLinkState_Response")
class GetLinkStateResponse:
    link_state: LinkState
    success: bool_
    status_message: string


GetLinkState = make_srv_type(
    "gazebo_msgs/srv/GetLinkState", GetLinkStateRequest, GetLinkStateResponse
)


@message("gazebo_msgs/srv/SetLinkState_Request")
class SetLinkStateRequest:
    link_state: LinkState


@message("gazebo_msgs/srv/SetLinkState_Response")
class SetLinkStateResponse:
    success: bool_
    status_message: string


SetLinkState = make_srv_type(
    "gazebo_msgs/srv/SetLinkState", SetLinkStateRequest, SetLinkStateResponse
)


@message("gazebo_msgs/srv/GetWorldProperties_Request")
class GetWorldPropertiesRequest:
    pass


@message("gazebo_msgs/srv/GetWorldProperties_Response")
class GetWorldPropertiesResponse:
    """Sim time (s) and the names of the models in the world."""

    sim_time: float64
    model_names: Seq[string]
    rendering_enabled: bool_
    success: bool_
    status_message: string


GetWorldProperties = make_srv_type(
    "gazebo_msgs/srv/GetWorldProperties", GetWorldPropertiesRequest, GetWorldPropertiesResponse
)


@message("gazebo_msgs/srv/GetModelProperties_Request")
class GetModelPropertiesRequest:
    model_name: string


@message("gazebo_msgs/srv/GetModelProperties_Response")
class GetModelPropertiesResponse:
    parent_model_name: string
    canonical_body_name: string
    body_names: Seq[string]
    geom_names: Seq[string]
    joint_names: Seq[string]
    child_model_names: Seq[string]
    is_static: bool_
    success: bool_
    status_message: string


GetModelProperties = make_srv_type(
    "gazebo_msgs/srv/GetModelProperties", GetModelPropertiesRequest, GetModelPropertiesResponse
)
