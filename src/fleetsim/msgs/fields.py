"""Field types for message classes: ROS primitive names, fixed arrays and sequences.

A message class annotates each field with the ROS type it has on the wire::

    @message("sensor_msgs/msg/LaserScan")
    class LaserScan:
        header: Header                  # nested message (default: Header())
        angle_min: float32              # primitive (default: 0.0)
        ranges: Seq[float32]            # numpy float32 array (default: empty)
        covariance: Arr[float64, 36]    # numpy float64 array of 36 (default: zeros)
        poses: Seq[Pose]                # list of Pose (default: [])
        names: Seq[string]              # list of str (default: [])

The annotations are ``typing.Annotated`` aliases whose metadata (`Prim`, `SeqSpec`) the
`fleetsim.msgs.registry.message` decorator reads to give every field its default, and the CDR
layer reads to describe the type to ``rosbags``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import Annotated, Any, get_args, get_origin

import numpy as np

from fleetsim.errors import MessageError


@dataclass(frozen=True, slots=True)
class Prim:
    """A ROS primitive type: its ROS name, the Python type of a value, and its NumPy dtype."""

    name: str
    py: type
    dtype: Any  # numpy dtype class used for arrays of this primitive (None for string)
    lo: int | None = None  # integer range, inclusive
    hi: int | None = None
    bound: int = 0  # string<=N bound (0: unbounded)

    @property
    def default(self) -> Any:
        return self.py()


@dataclass(frozen=True, slots=True)
class SeqSpec:
    """A fixed-length array (``length``) or a sequence (``length is None``, optional ``bound``).

    ``elem`` is a `Prim` or a message class. Numeric and bool elements are held as NumPy arrays
    of ``elem.dtype``; strings and messages as Python lists.
    """

    elem: Any
    length: int | None = None
    bound: int = 0

    @property
    def is_array(self) -> bool:
        """True when values are NumPy arrays (numeric or bool elements)."""
        return isinstance(self.elem, Prim) and self.elem.dtype is not None


def _int(name: str, bits: int, signed: bool, dtype: Any) -> Any:
    lo, hi = (-(2 ** (bits - 1)), 2 ** (bits - 1) - 1) if signed else (0, 2**bits - 1)
    return Annotated[int, Prim(name, int, dtype, lo, hi)]


bool_ = Annotated[bool, Prim("bool", bool, np.bool_)]
byte = _int("byte", 8, True, np.byte)  # rosbags packs byte as a signed int8
char = _int("char", 8, False, np.uint8)
int8 = _int("int8", 8, True, np.int8)
uint8 = _int("uint8", 8, False, np.uint8)
int16 = _int("int16", 16, True, np.int16)
uint16 = _int("uint16", 16, False, np.uint16)
int32 = _int("int32", 32, True, np.int32)
uint32 = _int("uint32", 32, False, np.uint32)
int64 = _int("int64", 64, True, np.int64)
uint64 = _int("uint64", 64, False, np.uint64)
float32 = Annotated[float, Prim("float32", float, np.float32)]
float64 = Annotated[float, Prim("float64", float, np.float64)]
string = Annotated[str, Prim("string", str, None)]

_ALIASES = (bool_, byte, char, int8, uint8, int16, uint16, int32, uint32, int64, uint64)
_ALIASES += (float32, float64, string)
PRIMITIVES: dict[str, Prim] = {get_args(a)[1].name: get_args(a)[1] for a in _ALIASES}


def spec_of(hint: Any, where: str) -> Any:
    """Return the field spec (a `Prim`, a `SeqSpec` or a message class) of an annotation."""
    if get_origin(hint) is Annotated:
        for meta in get_args(hint)[1:]:
            if isinstance(meta, Prim | SeqSpec):
                return meta
    if isinstance(hint, type) and hasattr(hint, "__msgfields__"):
        return hint
    raise MessageError(
        f"{where}: annotation {hint!r} is not a message field type; use a primitive alias "
        "(float64, int32, string, ...), a message class, Seq[...] or Arr[..., n] "
        "from fleetsim.msgs.fields"
    )


class Seq:
    """``Seq[elem]`` is an unbounded sequence, ``Seq[elem, n]`` one bounded to ``n`` items."""

    def __class_getitem__(cls, item: Any) -> Any:
        elem, bound = item if isinstance(item, tuple) else (item, 0)
        spec = SeqSpec(spec_of(elem, "Seq[...]"), None, bound)
        return Annotated[np.ndarray if spec.is_array else list, spec]


class Arr:
    """``Arr[elem, n]`` is a fixed-length array of ``n`` items."""

    def __class_getitem__(cls, item: Any) -> Any:
        elem, length = item
        spec = SeqSpec(spec_of(elem, "Arr[...]"), int(length))
        return Annotated[np.ndarray if spec.is_array else list, spec]


def _fixed_list(make: Any, n: int) -> list:
    return [make() for _ in range(n)]


def default_field(spec: Any) -> Any:
    """Return the dataclass ``field(...)`` holding the default value of a field of ``spec``."""
    if isinstance(spec, Prim):
        return field(default=spec.default)
    if isinstance(spec, SeqSpec):
        n = spec.length or 0
        if spec.is_array:
            return field(default_factory=partial(np.zeros, n, spec.elem.dtype))
        if spec.length is None:
            return field(default_factory=list)
        make = spec.elem.py if isinstance(spec.elem, Prim) else spec.elem
        return field(default_factory=partial(_fixed_list, make, n))
    return field(default_factory=spec)


def spec_text(spec: Any) -> str:
    """ROS .msg spelling of a field type: ``float64``, ``geometry_msgs/Point[]``, ``uint8[9]``."""
    if isinstance(spec, Prim):
        return f"string<={spec.bound}" if spec.bound else spec.name
    if isinstance(spec, SeqSpec):
        count = (
            str(spec.length) if spec.length is not None else f"<={spec.bound}" * bool(spec.bound)
        )
        return f"{spec_text(spec.elem)}[{count}]"
    pkg, _, name = spec.__msgtype__.split("/")
    return f"{pkg}/{name}"
