"""CDR (ROS 2 wire format) for fleetsim messages, through a private ``rosbags`` typestore.

The typestore starts from ROS 2 Humble's definitions. Each fleetsim class is checked against the
store's definition of the same name (so standard types are byte-compatible with ROS 2), types the
store lacks (gazebo_msgs, move_base_msgs, services, ...) are registered from the dataclass fields,
and the store is told to build fleetsim classes when it decodes. Encoding hands our objects to
rosbags' generated serialisers directly: field names match, so no conversion pass is needed.
"""

from __future__ import annotations

import dataclasses
import struct
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.serde import SerdeError
from rosbags.typesys import Stores, TypesysError, get_typestore

from fleetsim.errors import MessageError
from fleetsim.msgs.fields import Prim, SeqSpec
from fleetsim.msgs.registry import get_type, is_message, message_class, type_name

_STORE = get_typestore(Stores.ROS2_HUMBLE)
_READY: dict[str, type] = {}  # type name -> the class the store currently decodes into
_PLANS: dict[type, list[tuple[str, str, Any]]] = {}
_MSGDEFS: dict[str, str] = {}
_DUMMY = ("structure_needs_at_least_one_member", (Nodetype.BASE, ("uint8", 0)))


def _fielddesc(spec: Any) -> tuple:
    if isinstance(spec, Prim):
        return (Nodetype.BASE, (spec.name, spec.bound))
    if isinstance(spec, SeqSpec):
        sub = _fielddesc(spec.elem)
        if spec.length is not None:
            return (Nodetype.ARRAY, (sub, spec.length))
        return (Nodetype.SEQUENCE, (sub, spec.bound))
    return (Nodetype.NAME, spec.__msgtype__)


def fielddefs(cls: type) -> tuple[list, list]:
    """The rosbags field definition ``(constants, fields)`` of a message class."""
    consts = [(n, spec.name, v) for n, spec, v in cls.__msgconsts__]
    fields = [(n, _fielddesc(spec)) for n, spec in cls.__msgfields__] or [_DUMMY]
    return consts, fields


def _nested(spec: Any) -> type | None:
    if isinstance(spec, SeqSpec):
        return _nested(spec.elem)
    return spec if is_message(spec) else None


def _same(have: tuple, mine: tuple) -> bool:
    def fields(defs: tuple) -> list:
        return [(n.lower(), d) for n, d in defs[1]]

    return fields(have) == fields(mine) and list(have[0]) == list(mine[0])


def _prepare(cls: type) -> None:
    name = cls.__msgtype__
    if _READY.get(name) is cls:
        return
    for _, spec in cls.__msgfields__:
        sub = _nested(spec)
        if sub is not None:
            _prepare(sub)
    mine = fielddefs(cls)
    have = _STORE.fielddefs.get(name)
    if have is None:
        try:
            _STORE.register({name: mine})
        except TypesysError as exc:  # pragma: no cover - rosbags rejects the definition
            raise MessageError(f"cannot register message type '{name}' for CDR: {exc}") from exc
    elif not _same(have, mine):
        raise MessageError(
            f"message type '{name}' ({cls.__module__}.{cls.__name__}) has fields that differ "
            f"from ROS 2's definition: ours {mine[1]}, ROS 2 {have[1]}; fix the class"
        )
    if cls.__msgfields__:
        _STORE.types[name] = cls
    else:
        _STORE.types[name] = lambda *_dummy, _cls=cls: _cls()
    _STORE.cache.pop(name, None)  # a class registered again (same fields) replaces the old one
    _READY[name] = cls


def _plan(cls: type) -> list[tuple[str, str, Any]]:
    """Fields to check before encoding: numeric arrays, and messages that contain some."""
    plan = _PLANS.get(cls)
    if plan is None:
        plan = []
        for fname, spec in cls.__msgfields__:
            if isinstance(spec, SeqSpec) and spec.is_array:
                plan.append((fname, "array", spec))
            elif (sub := _nested(spec)) is not None and _plan(sub):
                plan.append((fname, "list" if isinstance(spec, SeqSpec) else "msg", sub))
        _PLANS[cls] = plan
    return plan


def coerce_array(val: Any, spec: SeqSpec, where: str) -> np.ndarray:
    """``val`` as a 1-D contiguous array of the field's dtype, or a MessageError naming ``where``.

    Floats accept any real numbers; integers accept integers within the dtype's range; bools
    accept bools. A value of any shape is flattened (row-major), e.g. an (H, W, 3) image.
    """
    dtype = np.dtype(spec.elem.dtype)
    try:
        arr = val if isinstance(val, np.ndarray) else np.asarray(val)
    except ValueError as exc:  # ragged nested lists
        raise MessageError(f"{where}: expected a flat sequence of {spec.elem.name}: {exc}") from exc
    kind = arr.dtype.kind
    accepted = {"f": "biuf", "i": "biu", "u": "biu", "b": "b"}[dtype.kind]
    if arr.size and kind not in accepted:
        raise MessageError(
            f"{where}: expected {spec.elem.name} values, got {type(val).__name__} of "
            f"{arr.dtype} ({np.ravel(arr)[:3].tolist()}...)"
        )
    if arr.size and dtype.kind in "iu" and kind in "iu":
        info = np.iinfo(dtype)
        lo, hi = arr.min(), arr.max()
        if lo < info.min or hi > info.max:
            raise MessageError(
                f"{where}: values {lo}..{hi} do not fit {spec.elem.name} ({info.min}..{info.max})"
            )
    out = np.ascontiguousarray(arr.reshape(-1), dtype=dtype)
    if spec.length is not None and out.shape[0] != spec.length:
        raise MessageError(
            f"{where}: expected {spec.length} {spec.elem.name} values, got {out.shape[0]}"
        )
    return out


def normalized(msg: Any, where: str = "") -> Any:
    """``msg``, or a copy whose array fields have the declared dtype, 1-D and contiguous.

    The message itself is never changed (it may be shared with subscribers).
    """
    plan = _plan(type(msg))
    if not plan:
        return msg
    fixes = None
    for fname, kind, spec in plan:
        val = getattr(msg, fname)
        if kind == "array":
            if (
                type(val) is np.ndarray
                and val.dtype == spec.elem.dtype
                and val.ndim == 1
                and val.flags.c_contiguous
                and (spec.length is None or val.shape[0] == spec.length)
            ):
                continue
            new = coerce_array(val, spec, f"{where or type_name(msg)}.{fname}")
        elif kind == "msg":
            if type(val) is not spec:  # left for the encoder to report
                continue
            new = normalized(val, f"{where or type_name(msg)}.{fname}")
            if new is val:
                continue
        else:
            if not isinstance(val, list | tuple) or not all(type(v) is spec for v in val):
                continue
            base = f"{where or type_name(msg)}.{fname}"
            new = [normalized(v, f"{base}[{i}]") for i, v in enumerate(val)]
            if all(a is b for a, b in zip(new, val)):
                continue
        fixes = fixes or {}
        fixes[fname] = new
    return dataclasses.replace(msg, **fixes) if fixes else msg


def serialize(msg: Any) -> bytes:
    """Encode a message as CDR (little-endian, with the 4-byte encapsulation header)."""
    name = type_name(msg)
    cls = message_class(msg)
    if _READY.get(name) is not cls:
        _prepare(cls)
    msg = normalized(msg)
    try:
        return bytes(_STORE.serialize_cdr(msg, name, little_endian=True))
    except (struct.error, AttributeError, TypeError, ValueError, SerdeError) as exc:
        from fleetsim.msgs.dicts import find_invalid_field

        problem = find_invalid_field(msg)  # "<type>: field 'a.b' expected ..."
        raise MessageError(f"cannot serialize {problem or f'{name}: {exc}'}") from exc


def deserialize(data: bytes | bytearray | memoryview, typename: str | type) -> Any:
    """Decode CDR bytes into a message of ``typename`` (ROS 1 or ROS 2 name, or a class).

    Numeric array fields are read-only views into ``data`` (received messages are not mutated).
    """
    cls = typename if isinstance(typename, type) else get_type(typename)
    name = type_name(cls)
    if _READY.get(name) is not cls:
        _prepare(cls)
    try:
        return _STORE.deserialize_cdr(data, name)
    except (SerdeError, struct.error, TypeError, ValueError, IndexError) as exc:
        raise MessageError(f"cannot decode {len(data)} bytes as {name}: {exc}") from exc


def msgdef(typename: str | type) -> str:
    """The ros2msg schema text of a type with its dependencies, as MCAP's ``ros2msg`` expects.

    The type's own fields come first, then for each dependency a line of 80 ``=``, a
    ``MSG: pkg/Type`` line and its fields.
    """
    cls = typename if isinstance(typename, type) else get_type(typename)
    name = type_name(cls)
    text = _MSGDEFS.get(name)
    if text is None:
        _prepare(cls)
        text = _MSGDEFS[name] = _STORE.generate_msgdef(name, ros_version=2)[0]
    return text
