"""std_srvs: Empty, Trigger and SetBool services."""

from __future__ import annotations

from fleetsim.msgs.fields import bool_, string
from fleetsim.msgs.interfaces import make_srv_type
from fleetsim.msgs.registry import message


@message("std_srvs/srv/Empty_Request")
class EmptyRequest:
    pass


@message("std_srvs/srv/Empty_Response")
class EmptyResponse:
    pass


Empty = make_srv_type("std_srvs/srv/Empty", EmptyRequest, EmptyResponse)


@message("std_srvs/srv/Trigger_Request")
class TriggerRequest:
    pass


@message("std_srvs/srv/Trigger_Response")
class TriggerResponse:
    success: bool_
    message: string


Trigger = make_srv_type("std_srvs/srv/Trigger", TriggerRequest, TriggerResponse)


@message("std_srvs/srv/SetBool_Request")
class SetBoolRequest:
    data: bool_


@message("std_srvs/srv/SetBool_Response")
class SetBoolResponse:
    success: bool_
    message: string


SetBool = make_srv_type("std_srvs/srv/SetBool", SetBoolRequest, SetBoolResponse)
