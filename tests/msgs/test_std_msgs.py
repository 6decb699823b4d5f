from __future__ import annotations

from fleetsim.msgs import get_type, std_msgs


def test_header_has_no_seq():
    assert [f for f, _ in std_msgs.Header.__msgfields__] == ["stamp", "frame_id"]


def test_wrappers():
    for name in ("String", "Bool", "Int32", "Float64", "UInt8", "Int64", "Float32"):
        cls = get_type(f"std_msgs/{name}")
        assert cls is getattr(std_msgs, name)
        assert [f for f, _ in cls.__msgfields__] == ["data"]
    assert std_msgs.ColorRGBA(1.0, 0.5, 0.0, 1.0).g == 0.5
    assert std_msgs.Float64MultiArray().layout.dim == []
