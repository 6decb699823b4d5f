"""gazebo_ros_link_attacher: the Attach service (``/link_attacher_node/attach``, ``.../detach``).

Both services use this type: join (or separate) ``link_name_1`` of ``model_name_1`` and
``link_name_2`` of ``model_name_2``; ``ok`` reports success.
"""

from __future__ import annotations

from fleetsim.msgs.fields import bool_, string
from fleetsim.msgs.interfaces import make_srv_type
from fleetsim.msgs.registry import message


@message("gazebo_ros_link_attacher/srv/Attach_Request")
class AttachRequest:
    model_name_1: string
    link_name_1: string
    model_name_2: string
    link_name_2: string


@message("gazebo_ros_link_attacher/srv/Attach_Response")
class AttachResponse:
    ok: bool_


Attach = make_srv_type("gazebo_ros_link_attacher/srv/Attach", AttachRequest, AttachResponse)
