"""Messages to and from plain dicts, for YAML (``rostopic pub`` style) and JSON.

``from_dict("geometry_msgs/PoseStamped", {"header": {"frame_id": "map"},
"pose": {"position": {"x": 22}}})`` fills unspecified fields with defaults, accepts ints for
floats, ROS 1 field names that ROS 2 renamed (``secs``, ``nsecs``, ``Header.seq``), a number of
seconds for a Time or Duration, and a bare value for a one-field message (``"hello"`` for a
std_msgs/String). Anything else is a MessageError naming the field path.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from fleetsim.errors import MessageError, did_you_mean
from fleetsim.msgs.fields import Prim, SeqSpec
from fleetsim.msgs.registry import ROS1_FIELD_RENAMES, get_type, is_message, type_name

_TIME_TYPES = ("builtin_interfaces/msg/Time", "builtin_interfaces/msg/Duration")
_FLOAT_WORDS = {  # strings accepted for float fields (YAML spells them .inf, .nan)
    "inf": math.inf, "+inf": math.inf, "-inf": -math.inf, "nan": math.nan,
    ".inf": math.inf, "+.inf": math.inf, "-.inf": -math.inf, ".nan": math.nan,
}  # fmt: skip


def to_dict(msg: Any) -> dict[str, Any]:
    """A message as nested dicts of plain Python values (arrays become lists)."""
    return {fname: _plain(getattr(msg, fname)) for fname, _ in msg.__msgfields__}


def _plain(val: Any) -> Any:
    if is_message(val):
        return to_dict(val)
    if isinstance(val, np.ndarray):
        return val.tolist()
    if isinstance(val, list | tuple):
        return [_plain(v) for v in val]
    if isinstance(val, np.generic):
        return val.item()
    return val


def from_dict(typename_or_cls: str | type, data: Any, where: str | None = None) -> Any:
    """Build a message of a type (ROS 1/2 name or class) from nested dicts.

    ``where`` names the source in error messages (a file and line, a command line); it defaults
    to the type's name.
    """
    if isinstance(typename_or_cls, str):
        cls = get_type(typename_or_cls)
    elif is_message(typename_or_cls):
        cls = typename_or_cls
    else:
        raise MessageError(f"{typename_or_cls!r} is not a message type name or class")
    return _build(cls, data, where or type_name(cls), "", False)


def find_invalid_field(msg: Any) -> str | None:
    """A description of the first field of ``msg`` whose value does not fit its type, or None."""
    try:
        _build(type(msg), to_dict(msg), type_name(msg), "", True)
    except MessageError as exc:
        return str(exc)
    return None


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name


def _label(path: str) -> str:
    return f"field '{path}'" if path else "message"


def _build(cls: type, data: Any, where: str, path: str, strict: bool) -> Any:
    """A ``cls`` from ``data``; ``strict`` turns off conveniences (None, seconds, bare value)."""
    if type(data) is cls:
        return data
    name = cls.__msgtype__
    if not strict:
        if data is None:
            return cls()
        if name in _TIME_TYPES and isinstance(data, int | float) and not isinstance(data, bool):
            return cls.from_sec(float(data))
    specs = dict(cls.__msgfields__)
    if not isinstance(data, Mapping):
        if len(specs) == 1 and not strict:
            data = {next(iter(specs)): data}
        else:
            raise MessageError(
                f"{where}: {_label(path)} expected a mapping of {name} fields "
                f"({', '.join(specs) or 'none'}), got {type(data).__name__} {data!r}"
            )
    renames = ROS1_FIELD_RENAMES.get(name, {})
    kwargs = {}
    for key, val in data.items():
        fname = key
        if key not in specs and key in renames:
            fname = renames[key]
            if fname is None:  # a ROS 1 field that ROS 2 dropped (Header.seq)
                continue
        spec = specs.get(fname)
        if spec is None:
            raise MessageError(
                f"{where}: unknown field '{_join(path, str(key))}' in {name}"
                f"{did_you_mean(str(key), specs)}; its fields are {', '.join(specs) or 'none'}"
            )
        kwargs[fname] = _value(spec, val, where, _join(path, fname), strict)
    return cls(**kwargs)


def _value(spec: Any, val: Any, where: str, path: str, strict: bool) -> Any:
    if isinstance(spec, Prim):
        return _prim(spec, val, where, path)
    if isinstance(spec, SeqSpec):
        if spec.is_array:
            from fleetsim.msgs.cdr import coerce_array

            if isinstance(val, str | bytes | Mapping) or np.ndim(val) == 0:
                _wrong(spec_label(spec), val, where, path)
            if spec.elem.py is float and isinstance(val, list | tuple):
                val = [_float_word(v) for v in val]
            return coerce_array(val, spec, f"{where}: {_label(path)}")
        if not isinstance(val, list | tuple):
            _wrong(spec_label(spec), val, where, path)
        if spec.length is not None and len(val) != spec.length:
            raise MessageError(
                f"{where}: {_label(path)} expected {spec.length} items, got {len(val)}"
            )
        return [_value(spec.elem, v, where, f"{path}[{i}]", strict) for i, v in enumerate(val)]
    return _build(spec, val, where, path, strict)


def spec_label(spec: Any) -> str:
    """How a field type is named in messages: ``float64``, ``float32[]``, ``geometry_msgs/Pose``."""
    from fleetsim.msgs.fields import spec_text

    return spec_text(spec)


def _wrong(expected: str, val: Any, where: str, path: str) -> None:
    raise MessageError(
        f"{where}: {_label(path)} expected {expected}, got {type(val).__name__} {val!r}"
    )


def _float_word(v: Any) -> Any:
    return _FLOAT_WORDS.get(v.strip().lower(), v) if isinstance(v, str) else v


def _prim(spec: Prim, val: Any, where: str, path: str) -> Any:
    if spec.py is float:
        val = _float_word(val)
        if isinstance(val, bool | np.bool_) or not isinstance(
            val, int | float | np.integer | np.floating
        ):
            _wrong(spec.name, val, where, path)
        return float(val)
    if spec.py is int:
        if isinstance(val, bool | np.bool_) or not isinstance(val, int | np.integer):
            _wrong(spec.name, val, where, path)
        if not spec.lo <= val <= spec.hi:
            raise MessageError(
                f"{where}: {_label(path)} value {val} is out of range for {spec.name} "
                f"({spec.lo}..{spec.hi})"
            )
        return int(val)
    if spec.py is bool:
        if not isinstance(val, bool | np.bool_):
            _wrong(spec.name, val, where, path)
        return bool(val)
    if not isinstance(val, str):
        _wrong(spec.name, val, where, path)
    if spec.bound and len(val) > spec.bound:
        raise MessageError(f"{where}: {_label(path)} is longer than {spec.bound} characters")
    return val
