"""BagReader: clear errors for foreign and truncated files, info like `ros2 bag info`."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mcap.writer import Writer

from fleetsim.errors import RecordingError
from fleetsim.record import BagReader, format_info


def test_foreign_missing_and_folder(tmp_path):
    bad = tmp_path / "x.mcap"
    bad.write_bytes(b"#ROSBAG V2.0\n" + bytes(100))
    with pytest.raises(RecordingError, match=r"x\.mcap is not an MCAP file \(it starts with"):
        BagReader(bad)
    with pytest.raises(RecordingError, match=r"nothere\.mcap: no such file"):
        BagReader(tmp_path / "nothere.mcap")
    with pytest.raises(RecordingError, match="is a folder; give the .mcap file"):
        BagReader(tmp_path)
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    with pytest.raises(RecordingError, match="is not an MCAP file"):
        BagReader(empty)


def test_info_text(recording):
    info = BagReader(recording).info()
    text = format_info(info)
    assert "Duration:          1.000000000s" in text
    assert "Messages:          51" in text
    assert "Topic: /robot0/scan | Type: sensor_msgs/msg/LaserScan  | Count: 10" in text
    assert "Topic: /map" in text and "| latched" in text
    assert info.profile == "ros2" and info.library.startswith("fleetsim")


@settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(fraction=st.floats(0.0, 0.999))
def test_any_cut_is_reported_as_truncated_with_a_count(recording, tmp_path, fraction):
    data = recording.read_bytes()
    total = 51
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: max(8, int(len(data) * fraction))])
    reader = BagReader(cut)
    assert not reader.complete
    with pytest.raises(RecordingError, match=r"cut\.mcap is truncated after (\d+) messages") as e:
        list(reader.messages(decode=False))
    n = int(e.value.args[0].split("after ")[1].split(" ")[0])
    assert 0 <= n <= total
    kept = list(reader.messages(allow_truncated=True))
    assert len(kept) == n
    with pytest.raises(RecordingError, match="truncated after"):
        reader.info()


def test_corrupt_chunk_is_reported(recording, tmp_path):
    data = bytearray(recording.read_bytes())
    mid = len(data) // 2
    data[mid : mid + 64] = bytes(64)
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(bytes(data))
    with pytest.raises(
        RecordingError, match=r"bad\.mcap is (corrupt|truncated) after \d+ messages"
    ):
        list(BagReader(bad).messages())


def _foreign(path, encoding: str, schema_name: str, schema_encoding: str, data: bytes):
    with open(path, "wb") as f:
        w = Writer(f)
        w.start(profile="", library="test")
        sid = w.register_schema(schema_name, schema_encoding, b"")
        cid = w.register_channel("/foreign", encoding, sid)
        w.add_message(cid, log_time=5, data=data, publish_time=5)
        w.finish()


def test_foreign_encodings_and_types(tmp_path):
    path = tmp_path / "json.mcap"
    _foreign(path, "json", "Thing", "jsonschema", b"{}")
    with pytest.raises(
        RecordingError, match="topic /foreign is encoded as 'json'; fleetsim decodes"
    ):
        list(BagReader(path).messages())
    (raw,) = BagReader(path).messages(decode=False)
    assert raw.data == b"{}" and raw.log_time_ns == 5
    path = tmp_path / "unknown.mcap"
    _foreign(path, "cdr", "my_pkg/msg/Thing", "ros2msg", b"\x00\x01\x00\x00")
    with pytest.raises(
        RecordingError, match="topic /foreign: unknown message type 'my_pkg/msg/Thing'"
    ):
        list(BagReader(path).messages())
    path = tmp_path / "garbage.mcap"
    _foreign(path, "cdr", "std_msgs/msg/String", "ros2msg", b"\x00\x01\x00\x00\xff\xff\xff\x7f")
    with pytest.raises(RecordingError, match="topic /foreign: cannot decode 8 bytes as std_msgs"):
        list(BagReader(path).messages())
