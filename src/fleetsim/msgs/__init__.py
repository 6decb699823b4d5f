"""Message types with ROS 2 names and fields, ROS 1 name mapping, CDR codec, dict conversion.

Import per-package modules (``from fleetsim.msgs import geometry_msgs``) and use the classes
(``geometry_msgs.PoseStamped()``); look types up by name with `get_type`, which accepts ROS 1
(``geometry_msgs/PoseStamped``) and ROS 2 (``geometry_msgs/msg/PoseStamped``) spellings.
"""

from fleetsim.msgs import (
    actionlib_msgs,
    builtin_interfaces,
    control_msgs,
    controller_manager_msgs,
    fiducial_msgs,
    gazebo_msgs,
    gazebo_ros_link_attacher,
    geometry_msgs,
    grobot_utilities,
    move_base_msgs,
    moveit_msgs,
    nav_msgs,
    rosgraph_msgs,
    sensor_msgs,
    shape_msgs,
    std_msgs,
    std_srvs,
    tf2_msgs,
    trajectory_msgs,
    visualization_msgs,
)
from fleetsim.msgs.cdr import deserialize, msgdef, serialize
from fleetsim.msgs.dicts import from_dict, to_dict
from fleetsim.msgs.interfaces import (
    ActionType,
    SrvType,
    all_action_types,
    all_srv_types,
    get_action_type,
    get_srv_type,
    make_action_type,
    make_srv_type,
)
from fleetsim.msgs.registry import (
    all_types,
    get_type,
    is_message,
    message,
    msgs_equal,
    resolve_name,
    type_name,
)

__all__ = [
    "ActionType",
    "SrvType",
    "actionlib_msgs",
    "all_action_types",
    "all_srv_types",
    "all_types",
    "builtin_interfaces",
    "control_msgs",
    "controller_manager_msgs",
    "deserialize",
    "fiducial_msgs",
    "from_dict",
    "gazebo_msgs",
    "gazebo_ros_link_attacher",
    "geometry_msgs",
    "get_action_type",
    "get_srv_type",
    "get_type",
    "grobot_utilities",
    "is_message",
    "make_action_type",
    "make_srv_type",
    "message",
    "move_base_msgs",
    "moveit_msgs",
    "msgdef",
    "msgs_equal",
    "nav_msgs",
    "resolve_name",
    "rosgraph_msgs",
    "sensor_msgs",
    "serialize",
    "shape_msgs",
    "std_msgs",
    "std_srvs",
    "tf2_msgs",
    "to_dict",
    "trajectory_msgs",
    "type_name",
    "visualization_msgs",
]
