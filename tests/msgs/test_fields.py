from __future__ import annotations

import numpy as np
import pytest

from fleetsim.errors import MessageError
from fleetsim.msgs import geometry_msgs
from fleetsim.msgs.fields import (
    PRIMITIVES,
    Arr,
    Prim,
    Seq,
    SeqSpec,
    default_field,
    float32,
    spec_of,
    spec_text,
    string,
    uint8,
)


def test_primitives_table():
    assert set(PRIMITIVES) == {
        "bool", "byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32",
        "int64", "uint64", "float32", "float64", "string",
    }  # fmt: skip
    assert PRIMITIVES["uint16"].hi == 65535 and PRIMITIVES["int8"].lo == -128
    assert PRIMITIVES["string"].default == ""


def test_specs_and_text():
    seq = spec_of(Seq[float32], "t")
    assert seq == SeqSpec(PRIMITIVES["float32"], None, 0) and seq.is_array
    assert spec_text(seq) == "float32[]"
    assert spec_text(spec_of(Arr[uint8, 9], "t")) == "uint8[9]"
    assert spec_text(spec_of(Seq[uint8, 4], "t")) == "uint8[<=4]"
    pts = spec_of(Seq[geometry_msgs.Point], "t")
    assert not pts.is_array and spec_text(pts) == "geometry_msgs/Point[]"
    assert not spec_of(Seq[string], "t").is_array
    assert isinstance(spec_of(string, "t"), Prim)
    with pytest.raises(MessageError, match=r"^here: annotation <class 'int'>"):
        spec_of(int, "here")


def test_defaults_are_fresh_objects():
    f = default_field(spec_of(Arr[float32, 3], "t"))
    a, b = f.default_factory(), f.default_factory()
    assert a is not b and a.dtype == np.float32 and a.shape == (3,)
    g = default_field(spec_of(Arr[geometry_msgs.Point, 2], "t"))
    pts = g.default_factory()
    assert len(pts) == 2 and pts[0] is not pts[1]
    assert default_field(spec_of(Arr[string, 2], "t")).default_factory() == ["", ""]
