"""The `message` decorator, the type registry and ROS 1 / ROS 2 name resolution.

Every message class is registered under its ROS 2 full name (``geometry_msgs/msg/PoseStamped``).
`get_type` also accepts the ROS 1 spelling (``geometry_msgs/PoseStamped``), a leading slash, and
the ROS 1 names that ROS 2 renamed (`ROS1_TYPE_RENAMES`).
"""

from __future__ import annotations

import inspect
import math
import sys
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar, get_args, get_origin

import numpy as np

from fleetsim.errors import MessageError, did_you_mean
from fleetsim.msgs.fields import default_field, spec_of

T = TypeVar("T")

_TYPES: dict[str, type] = {}
_ALIASES: dict[str, str] = {}

#: ROS 1 type names whose ROS 2 counterpart has another name (besides the ``/msg/`` infix).
ROS1_TYPE_RENAMES: dict[str, str] = {
    "time": "builtin_interfaces/msg/Time",
    "duration": "builtin_interfaces/msg/Duration",
    "std_msgs/Time": "builtin_interfaces/msg/Time",
    "std_msgs/Duration": "builtin_interfaces/msg/Duration",
    "Header": "std_msgs/msg/Header",
    "roslib/Header": "std_msgs/msg/Header",
    "tf/tfMessage": "tf2_msgs/msg/TFMessage",
    "tf2_msgs/tfMessage": "tf2_msgs/msg/TFMessage",
}

#: ROS 1 field names that ROS 2 renamed, per ROS 2 type; ``None`` means the field was dropped.
ROS1_FIELD_RENAMES: dict[str, dict[str, str | None]] = {
    "builtin_interfaces/msg/Time": {"secs": "sec", "nsecs": "nanosec"},
    "builtin_interfaces/msg/Duration": {"secs": "sec", "nsecs": "nanosec"},
    "std_msgs/msg/Header": {"seq": None},
    "sensor_msgs/msg/CameraInfo": {"D": "d", "K": "k", "R": "r", "P": "p"},
}


def message(typename: str) -> Callable[[type[T]], type[T]]:
    """Class decorator: make a slotted dataclass message registered as ``typename``.

    Annotated fields without a value get the ROS default (0, 0.0, False, "", empty sequence,
    zero-filled fixed array, default nested message). ``ClassVar`` annotations are ROS constants
    (``PENDING: ClassVar[uint8] = 0``).
    """
    _split_full(typename)

    def wrap(cls: type[T]) -> type[T]:
        where = f"{typename} ({cls.__module__}.{cls.__qualname__})"
        caller = sys._getframe(1).f_locals  # names local to a function defining the class
        try:
            hints = typing.get_type_hints(cls, localns=dict(caller), include_extras=True)
        except NameError as exc:
            raise MessageError(f"{where}: an annotation names an unknown type: {exc}") from exc
        fields, consts = [], []
        for fname in inspect.get_annotations(cls):
            hint = hints[fname]
            if get_origin(hint) is ClassVar:
                spec = spec_of(get_args(hint)[0], f"{where}.{fname}")
                consts.append((fname, spec, cls.__dict__[fname]))
                continue
            spec = spec_of(hint, f"{where}.{fname}")
            if fname not in cls.__dict__:
                setattr(cls, fname, default_field(spec))
            fields.append((fname, spec))
        if not fields:  # ROS 2 gives empty structs one dummy byte; CDR reads it from here
            cls.structure_needs_at_least_one_member = 0
        cls.__msgtype__ = typename
        new = dataclass(slots=True)(cls)
        new.__msgfields__ = tuple(fields)
        new.__msgconsts__ = tuple(consts)
        register(new)
        return new

    return wrap


def _split_full(typename: str) -> tuple[str, str, str]:
    parts = typename.split("/")
    if len(parts) != 3 or parts[1] not in ("msg", "srv", "action") or not all(parts):
        raise MessageError(
            f"message type name '{typename}' must be a ROS 2 full name 'pkg/msg/Name' "
            "(or pkg/srv/Name_Request, pkg/action/Name_Goal)"
        )
    return parts[0], parts[1], parts[2]


def register(cls: type, *aliases: str) -> None:
    """Register a message class under its ``__msgtype__`` and any extra alias names."""
    name = cls.__msgtype__
    have = _TYPES.get(name)
    if have is not None and have is not cls and have.__msgfields__ != cls.__msgfields__:
        raise MessageError(
            f"message type '{name}' is already registered by {have.__module__}.{have.__name__} "
            f"with other fields; give {cls.__module__}.{cls.__name__} another name"
        )
    _TYPES[name] = cls
    for alias in aliases:
        _ALIASES[alias] = name


def all_types() -> dict[str, type]:
    """Every registered message class by ROS 2 full name (a copy)."""
    return dict(_TYPES)


def resolve_name(name: str) -> str:
    """Return the registered ROS 2 full name for a ROS 1 or ROS 2 type name, or raise."""
    key = name.strip().lstrip("/")
    if key in _TYPES:
        return key
    full = _ALIASES.get(key) or ROS1_TYPE_RENAMES.get(key)
    if full is None and key.count("/") == 1:
        pkg, base = key.split("/")
        full = f"{pkg}/msg/{base}"
    if full is not None and full in _TYPES:
        return full
    short = key.count("/") < 2
    known = [_short(n) for n in _TYPES] if short else list(_TYPES)
    raise MessageError(
        f"unknown message type '{name}'{did_you_mean(key, known)}; "
        "fleetsim.msgs.all_types() lists the known types"
    )


def _short(full: str) -> str:
    pkg, _, base = full.split("/")
    return f"{pkg}/{base}"


def get_type(name: str) -> type:
    """Return the message class for ``name``: ``geometry_msgs/PoseStamped``, ``.../msg/...``."""
    return _TYPES[resolve_name(name)]


def type_name(cls_or_msg: Any) -> str:
    """The ROS 2 full name of a message class or instance (``geometry_msgs/msg/PoseStamped``)."""
    name = getattr(cls_or_msg, "__msgtype__", None)
    if not isinstance(name, str):
        raise MessageError(f"{cls_or_msg!r} is not a fleetsim message class or instance")
    return name


def message_class(msg: Any) -> type:
    """The registered class a message is: its own, or for a lazily built message (a scan whose
    ranges are cast when read, ``fleetsim.sim.messages.LazyLaserScan``) the class it stands
    for (``__lazy_of__``)."""
    cls = type(msg)
    return getattr(cls, "__lazy_of__", cls)


def is_message(obj: Any) -> bool:
    """True for a message class or instance made by `message`."""
    return hasattr(obj, "__msgfields__")


def msgs_equal(a: Any, b: Any) -> bool:
    """Deep equality of two messages (or field values): arrays elementwise, NaN equals NaN."""
    if is_message(a) or is_message(b):
        if type(a) is not type(b):
            return False
        return all(msgs_equal(getattr(a, f), getattr(b, f)) for f, _ in a.__msgfields__)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        x, y = np.asarray(a), np.asarray(b)
        if x.shape != y.shape:
            return False
        if x.dtype.kind == "f" or y.dtype.kind == "f":
            return bool(np.array_equal(x, y, equal_nan=True))
        return bool(np.array_equal(x, y))
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(msgs_equal(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b)
