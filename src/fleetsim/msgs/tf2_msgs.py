"""tf2_msgs: TFMessage, the type of ``/tf`` and ``/tf_static`` (ROS 1's ``tf/tfMessage``)."""

from __future__ import annotations

from fleetsim.msgs.fields import Seq
from fleetsim.msgs.geometry_msgs import TransformStamped
from fleetsim.msgs.registry import message


@message("tf2_msgs/msg/TFMessage")
class TFMessage:
    transforms: Seq[TransformStamped]
