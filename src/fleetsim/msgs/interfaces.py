"""Service and action types: `SrvType`, `ActionType` and their registries.

A service is a pair of messages registered as ``pkg/srv/Name_Request`` and ``_Response``. An
action is a goal, result and feedback plus the ROS 1 actionlib wrappers ``NameActionGoal``
(header, goal_id, goal), ``NameActionResult`` (header, status, result), ``NameActionFeedback``
(header, status, feedback) and ``NameAction``, which are what travels on the ``goal``,
``result``, ``feedback`` topics of a ROS 1 action (``/move_base/goal`` ...).
"""

from __future__ import annotations

from dataclasses import dataclass

from fleetsim.errors import MessageError, did_you_mean
from fleetsim.msgs.actionlib_msgs import GoalID, GoalStatus
from fleetsim.msgs.registry import message, register, type_name
from fleetsim.msgs.std_msgs import Header

_SRVS: dict[str, SrvType] = {}
_ACTIONS: dict[str, ActionType] = {}


@dataclass(frozen=True, slots=True)
class SrvType:
    """A service type: ``name`` ("nav_msgs/srv/GetMap"), ``Request`` and ``Response`` classes."""

    name: str
    Request: type
    Response: type

    def __repr__(self) -> str:
        return f"SrvType({self.name!r})"


@dataclass(frozen=True, slots=True)
class ActionType:
    """An action type: ``name`` ("move_base_msgs/action/MoveBase") and its message classes."""

    name: str
    Goal: type
    Result: type
    Feedback: type
    ActionGoal: type
    ActionResult: type
    ActionFeedback: type
    Action: type

    def __repr__(self) -> str:
        return f"ActionType({self.name!r})"


def _check_full(name: str, kind: str) -> tuple[str, str]:
    parts = name.split("/")
    if len(parts) != 3 or parts[1] != kind or not all(parts):
        raise MessageError(f"{kind} type name '{name}' must look like 'pkg/{kind}/Name'")
    return parts[0], parts[2]


def make_srv_type(name: str, request_cls: type, response_cls: type) -> SrvType:
    """Register and return the service ``name`` ("pkg/srv/Name") made of two message classes.

    The classes must be registered as ``pkg/srv/Name_Request`` and ``pkg/srv/Name_Response``;
    the ROS 1 names ``pkg/NameRequest`` and ``pkg/NameResponse`` become aliases of them.
    """
    pkg, base = _check_full(name, "srv")
    for cls, suffix in ((request_cls, "Request"), (response_cls, "Response")):
        if type_name(cls) != f"{name}_{suffix}":
            raise MessageError(
                f"service {name}: the {suffix.lower()} class is registered as "
                f"'{type_name(cls)}'; register it as '{name}_{suffix}'"
            )
        register(cls, f"{pkg}/{base}{suffix}", f"{pkg}/srv/{base}{suffix}")
    srv = SrvType(name, request_cls, response_cls)
    _SRVS[name] = srv
    return srv


def _wrapper(module: str, full: str, fields: dict[str, type]) -> type:
    cls = type(full.rsplit("/", 1)[1], (), {"__annotations__": fields, "__module__": module})
    return message(full)(cls)


def make_action_type(
    pkg: str, name: str, goal_cls: type, result_cls: type, feedback_cls: type
) -> ActionType:
    """Register and return the action ``pkg/action/name`` with its ROS 1 actionlib wrappers.

    ``goal_cls``, ``result_cls`` and ``feedback_cls`` are message classes, normally registered
    as ``pkg/msg/<name>Goal`` etc. (the ROS 1 names); the ROS 2 names ``pkg/action/<name>_Goal``
    become aliases. The wrappers ``pkg/msg/<name>ActionGoal``, ``...ActionResult``,
    ``...ActionFeedback`` and ``...Action`` are created here.
    """
    module = goal_cls.__module__
    msg = f"{pkg}/msg/{name}"
    action_goal = _wrapper(
        module, f"{msg}ActionGoal", {"header": Header, "goal_id": GoalID, "goal": goal_cls}
    )
    action_result = _wrapper(
        module,
        f"{msg}ActionResult",
        {"header": Header, "status": GoalStatus, "result": result_cls},
    )
    action_feedback = _wrapper(
        module,
        f"{msg}ActionFeedback",
        {"header": Header, "status": GoalStatus, "feedback": feedback_cls},
    )
    action = _wrapper(
        module,
        f"{msg}Action",
        {
            "action_goal": action_goal,
            "action_result": action_result,
            "action_feedback": action_feedback,
        },
    )
    for cls, part in ((goal_cls, "Goal"), (result_cls, "Result"), (feedback_cls, "Feedback")):
        register(cls, f"{pkg}/action/{name}_{part}")
    full = f"{pkg}/action/{name}"
    act = ActionType(
        full,
        goal_cls,
        result_cls,
        feedback_cls,
        action_goal,
        action_result,
        action_feedback,
        action,
    )
    _ACTIONS[full] = act
    return act


def _lookup(table: dict, name: str, kind: str) -> object:
    key = name.strip().lstrip("/")
    if key in table:
        return table[key]
    if key.count("/") == 1:
        pkg, base = key.split("/")
        full = f"{pkg}/{kind}/{base}"
        if full in table:
            return table[full]
    short = key.count("/") < 2
    known = [f"{n.split('/')[0]}/{n.split('/')[2]}" for n in table] if short else list(table)
    raise MessageError(f"unknown {kind} type '{name}'{did_you_mean(key, known)}")


def get_srv_type(name: str) -> SrvType:
    """The service type for ``nav_msgs/GetMap`` or ``nav_msgs/srv/GetMap``."""
    return _lookup(_SRVS, name, "srv")


def get_action_type(name: str) -> ActionType:
    """The action type for ``move_base_msgs/MoveBase`` or ``move_base_msgs/action/MoveBase``.

    The ROS 1 spelling ``move_base_msgs/MoveBaseAction`` is accepted too.
    """
    key = name.strip().lstrip("/")
    if key.endswith("Action") and key.count("/") == 1:
        key = key[: -len("Action")]
    return _lookup(_ACTIONS, key, "action")


def all_srv_types() -> dict[str, SrvType]:
    """Every registered service type by full name (a copy)."""
    return dict(_SRVS)


def all_action_types() -> dict[str, ActionType]:
    """Every registered action type by full name (a copy)."""
    return dict(_ACTIONS)
