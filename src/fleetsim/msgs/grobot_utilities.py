"""grobot_utilities: the ``Patrol`` action of the tutorial's patrol_server / patrol_client.

``Patrol.action``::

    float32 radius
    bool clockwise
    uint32 num_patrols
    ---
    bool success
    ---
    uint32 completed_patrols

The action is served under patrol_server's full node name (``/karl/patrol_server/goal``, ...).
"""

from __future__ import annotations

from fleetsim.msgs.fields import bool_, float32, uint32
from fleetsim.msgs.interfaces import make_action_type
from fleetsim.msgs.registry import message


@message("grobot_utilities/msg/PatrolGoal")
class PatrolGoal:
    radius: float32
    clockwise: bool_
    num_patrols: uint32


@message("grobot_utilities/msg/PatrolResult")
class PatrolResult:
    success: bool_


@message("grobot_utilities/msg/PatrolFeedback")
class PatrolFeedback:
    completed_patrols: uint32


Patrol = make_action_type("grobot_utilities", "Patrol", PatrolGoal, PatrolResult, PatrolFeedback)
PatrolActionGoal = Patrol.ActionGoal
PatrolActionResult = Patrol.ActionResult
PatrolActionFeedback = Patrol.ActionFeedback
PatrolAction = Patrol.Action
