"""Parameters: declared once per node, validated on load, held in a rosparam-style tree.

A node declares its parameters in a frozen dataclass whose fields are made with `param`::

    @dataclass(frozen=True)
    class AmclParams:
        min_particles: int = param(100, range=(0, None), help="minimum allowed particles")
        max_vel_theta: float = param(1.0, unit="rad/s", aliases=("max_rotational_vel",))

`load_params` builds an instance from a mapping (usually the node's private namespace), converting
where ROS would (an int where a float is declared), rejecting wrong types and out-of-range values
with a `ParameterError` that names the parameter and where it came from, accepting old ROS names
with a warning, and warning about unknown keys with a "did you mean" suggestion.

`ParamTree` (in `fleetsim.runtime.param_tree`, re-exported here) is the parameter server; a
namespace read from it is a `ParamDict` that knows where each value was set, so `load_params`
names the YAML file and line of a value of the wrong type.
"""

from __future__ import annotations

import copy
import dataclasses
import logging
import math
import types
import typing
from collections.abc import Mapping
from typing import Any

from fleetsim.errors import ParameterError, did_you_mean
from fleetsim.runtime.param_tree import ParamDict, ParamTree
from fleetsim.runtime.param_yaml import load_yaml_file, load_yaml_text

__all__ = [
    "ParamDict",
    "ParamInfo",
    "ParamTree",
    "describe_params",
    "load_params",
    "load_yaml_file",
    "load_yaml_text",
    "param",
]

_log = logging.getLogger("fleetsim.params")

_MISSING = dataclasses.MISSING


def param(
    default: Any,
    *,
    unit: str = "",
    range: tuple[float | None, float | None] | None = None,
    choices: tuple[Any, ...] | None = None,
    aliases: tuple[str, ...] = (),
    help: str = "",
) -> Any:
    """Declare one parameter: its ROS default, unit, valid range or choices, old names, meaning.

    Mutable defaults (lists, dicts) are copied for each instance.
    """
    meta = {"unit": unit, "range": range, "choices": choices, "aliases": aliases, "help": help}
    if isinstance(default, list | dict | set):
        return dataclasses.field(default_factory=lambda d=default: copy.deepcopy(d), metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


@dataclasses.dataclass(frozen=True)
class ParamInfo:
    """One declared parameter, as documentation and validation see it."""

    name: str
    type: Any
    default: Any
    unit: str
    range: tuple[float | None, float | None] | None
    choices: tuple[Any, ...] | None
    aliases: tuple[str, ...]
    help: str


def describe_params(cls: type) -> list[ParamInfo]:
    """The declared parameters of a params dataclass, in declaration order."""
    hints = typing.get_type_hints(cls)
    out = []
    for f in dataclasses.fields(cls):
        default = f.default if f.default is not _MISSING else f.default_factory()  # type: ignore[misc]
        m = f.metadata
        out.append(
            ParamInfo(
                name=f.name,
                type=hints[f.name],
                default=default,
                unit=m.get("unit", ""),
                range=m.get("range"),
                choices=m.get("choices"),
                aliases=tuple(m.get("aliases", ())),
                help=m.get("help", ""),
            )
        )
    return out


def _type_label(tp: Any) -> str:
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_type_label(a) for a in typing.get_args(tp))
    if origin is not None:
        return getattr(origin, "__name__", str(origin))
    return "None" if tp is type(None) else getattr(tp, "__name__", str(tp))


def _convert(value: Any, tp: Any) -> Any:
    """Convert ``value`` to the declared type ``tp`` as ROS would, or raise TypeError."""
    if tp is Any:
        return value
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        errors = []
        for arg in typing.get_args(tp):
            try:
                return _convert(value, arg)
            except TypeError as e:
                errors.append(e)
        raise TypeError(_type_label(tp))
    if tp is type(None):
        if value is None:
            return None
        raise TypeError("None")
    if tp is bool:
        if isinstance(value, bool):
            return value
        raise TypeError("bool")
    if tp is int:
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        if isinstance(value, float) and value.is_integer():
            return int(value)
        raise TypeError("int")
    if tp is float:
        if isinstance(value, int | float) and not isinstance(value, bool):
            return float(value)
        raise TypeError("float")
    if tp is str:
        if isinstance(value, str):
            return value
        raise TypeError("str")
    if origin in (list, tuple) or tp in (list, tuple):
        if not isinstance(value, list | tuple):
            raise TypeError(_type_label(tp))
        args = typing.get_args(tp)
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(args) != len(value):
                raise TypeError(f"{len(args)}-element list")
            return tuple(_convert(v, a) for v, a in zip(value, args))
        item_tp = args[0] if args else Any
        items = [_convert(v, item_tp) for v in value]
        return tuple(items) if (origin is tuple or tp is tuple) else items
    if origin is dict or tp is dict:
        if not isinstance(value, Mapping):
            raise TypeError("dict")
        # a copy that keeps where each key was set, so that a node loading the dict's own
        # parameters (load_params) names the file and line of a bad one
        return ParamDict.copy_of(value)
    if isinstance(tp, type) and isinstance(value, tp):
        return value
    raise TypeError(_type_label(tp))


def _describe_value(value: Any) -> str:
    return f"{type(value).__name__} {value!r}"


def _set_at(origins: Mapping[str, str], key: str) -> str:
    origin = origins.get(key)
    return f" (set at {origin})" if origin else ""


def load_params(
    cls: type,
    values: Mapping[str, Any] | None,
    where: str = "",
    *,
    ignore: tuple[str, ...] | frozenset[str] = (),
    logger: logging.Logger | None = None,
    also_known: tuple[str, ...] | frozenset[str] = (),
) -> Any:
    """Build a ``cls`` instance from ``values``, validating every field.

    Parameters
    ----------
    cls : a frozen dataclass whose fields were declared with `param`.
    values : the raw parameters (for a node, its private namespace as a dict).
    where : where the values came from, for messages (``"/lizi1/amcl"`` or ``"amcl.yaml"``).
    ignore : keys that belong to someone else (sub-namespaces read by plugins); not warned about.
    logger : where warnings go (renamed and unknown parameters).
    also_known : names others read at this level (the pre-Hydro costmap's layer keys), offered
        as "did you mean" for an unknown key besides ``cls``'s own.
    """
    log = logger or _log
    origins = getattr(values, "origins", None) or {}
    values = dict(values or {})
    infos = {i.name: i for i in describe_params(cls)}
    alias_of = {a: i.name for i in infos.values() for a in i.aliases}
    prefix = f"{where}: " if where else ""
    kwargs: dict[str, Any] = {}
    for key, raw in values.items():
        name = key
        if key in alias_of:
            name = alias_of[key]
            if name in values:
                log.warning(
                    "%sparameter '%s' is the old name of '%s'; both are set, using '%s'",
                    prefix,
                    key,
                    name,
                    name,
                )
                continue
            log.warning(
                "%sparameter '%s' is deprecated, use '%s'%s",
                prefix,
                key,
                name,
                _set_at(origins, key),
            )
        elif key not in infos:
            if key not in ignore:
                known = [k for k in (*infos, *alias_of, *also_known) if k != key]
                log.warning(
                    "%sunknown parameter '%s'%s%s",
                    prefix,
                    key,
                    did_you_mean(key, known),
                    _set_at(origins, key),
                )
            continue
        info = infos[name]
        try:
            value = _convert(raw, info.type)
        except TypeError:
            raise ParameterError(
                f"{prefix}parameter '{key}' must be {_type_label(info.type)}, "
                f"got {_describe_value(raw)}{_set_at(origins, key)}"
            ) from None
        try:
            _check_range(info, key, value, prefix)
        except ParameterError as e:
            raise ParameterError(f"{e}{_set_at(origins, key)}") from None
        kwargs[name] = value
    return cls(**kwargs)


def _check_range(info: ParamInfo, key: str, value: Any, prefix: str) -> None:
    if info.choices is not None and value not in info.choices:
        options = ", ".join(repr(c) for c in info.choices)
        raise ParameterError(
            f"{prefix}parameter '{key}' must be one of {options}, got {value!r}"
            f"{did_you_mean(str(value), [str(c) for c in info.choices])}"
        )
    if info.range is None or value is None:
        return
    lo, hi = info.range
    if isinstance(value, float) and math.isnan(value):
        raise ParameterError(f"{prefix}parameter '{key}' is NaN")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf" if hi is None else f"{hi:g}"
        unit = f" {info.unit}" if info.unit else ""
        raise ParameterError(
            f"{prefix}parameter '{key}' = {value!r} is out of range [{lo_s}, {hi_s}]{unit}"
        )
