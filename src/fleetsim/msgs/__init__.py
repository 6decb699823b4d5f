"""Message types with ROS 2 names and fields, ROS 1 name mapping, CDR codec, dict conversion.

Import per-package modules (``from fleetsim.msgs import geometry_msgs``) and use the classes
(``geometry_msgs.PoseStamped()``); look types up by name with `get_type`, which accepts ROS 1
(``geometry_msgs/PoseStamped``) and ROS 2 (``geometry_msgs/msg/PoseStamped``) spellings.
"""

from fleetsim.msgs import (
    actionlib_msgs,
    builtin_interfaces,
    geometry_msgs,
    nav_msgs,
    sensor_msgs,
    std_msgs,
    tf2_msgs,
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
    "deserialize",
    "from_dict",
    "geometry_msgs",
    "get_action_type",
    "get_srv_type",
    "get_type",
    "is_message",
    "make_action_type",
    "make_srv_type",
    "message",
    "msgdef",
    "msgs_equal",
    "nav_msgs",
    "resolve_name",
    "sensor_msgs",
    "serialize",
    "std_msgs",
    "tf2_msgs",
    "to_dict",
    "type_name",
]
