"""tf_echo text, the text tree and writing view_frames output."""

import pytest

from fleetsim.errors import TransportError
from fleetsim.msgs import geometry_msgs
from fleetsim.tf import Buffer
from fleetsim.transport.tfview import echo_text, frames_text, write_frames


def _buffer():
    buf = Buffer()
    for stamp in (1.0, 1.5, 2.0):
        t = geometry_msgs.TransformStamped()
        t.header.frame_id, t.child_frame_id = "lizi1/odom", "lizi1/base_link"
        t.header.stamp.sec, t.header.stamp.nanosec = int(stamp), int(stamp % 1 * 1e9)
        t.transform.translation.x = 1.0
        t.transform.rotation.z, t.transform.rotation.w = 0.7071067811865476, 0.7071067811865476
        buf.set_transform(t, authority="/lizi1/diff_drive")
    s = geometry_msgs.TransformStamped()
    s.header.frame_id, s.child_frame_id = "map", "lizi1/odom"
    buf.set_transform(s, authority="/amcl", is_static=True)
    return buf


def test_echo_text_like_tf_echo():
    text = echo_text(_buffer().lookup_transform("map", "lizi1/base_link", 0.0))
    assert text.splitlines() == [
        "At time 2.000",
        "- Translation: [1.000, 0.000, 0.000]",
        "- Rotation: in Quaternion [0.000, 0.000, 0.707, 0.707]",
        "            in RPY (radian) [0.000, -0.000, 1.571]",
        "            in RPY (degree) [0.000, -0.000, 90.000]",
    ]


def test_frames_text_tree():
    assert frames_text(_buffer().frames_info()) == (
        "map\n  lizi1/odom  [/amcl, static]\n    lizi1/base_link  [/lizi1/diff_drive, 2.0 Hz]\n"
    )
    assert frames_text({}) == ""


def test_write_frames(tmp_path):
    dot = _buffer().all_frames_as_dot(2.0)
    assert write_frames(dot, tmp_path / "f.gv").read_text() == dot
    png = write_frames(dot, tmp_path / "f.png")
    assert png.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(TransportError, match=r"cannot write .*f\.txt: use a \.pdf, \.png"):
        write_frames(dot, tmp_path / "f.txt")
