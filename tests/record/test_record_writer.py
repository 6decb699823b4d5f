"""Recorder: ROS 2 MCAP readable by fleetsim, mcap_ros2 and rosbags; finalised on every exit."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader

from fleetsim.errors import RecordingError
from fleetsim.msgs import msgs_equal, std_msgs
from fleetsim.record import BagReader, Recorder

SRC = str(Path(__file__).resolve().parents[2] / "src")


def test_recording_reads_back_as_published(fake_run, tmp_path):
    rt, robots = fake_run(2)
    path = tmp_path / "run.mcap"
    rec = Recorder(rt, path)
    rt.run(1.0)
    rt.shutdown()
    assert rec.closed
    msgs = list(BagReader(path).messages(["/robot1/scan"]))
    assert len(msgs) == len(robots[1].scans) == 10
    for got, sent in zip(msgs, robots[1].scans):
        assert got.typename == "sensor_msgs/msg/LaserScan"
        assert got.log_time_ns == sent.header.stamp.to_nsec()  # log time is sim time
        assert msgs_equal(got.msg, sent)
    info = BagReader(path).info()
    counts = {t.name: t.count for t in info.topics}
    assert counts == {
        "/map": 1,
        "/robot0/odom": 20,
        "/robot0/scan": 10,
        "/robot1/odom": 20,
        "/robot1/scan": 10,
        "/tf": 40,
    }
    assert info.start_ns == 0 and info.end_ns == 1_000_000_000
    assert info.compression == "zstd"
    assert {t.name for t in info.topics if t.latched} == {"/map"}


def test_file_is_ros2_profile_cdr_with_ros2msg_schemas(fake_run, tmp_path):
    rt, _ = fake_run(1)
    path = tmp_path / "run.mcap"
    with Recorder(rt, path):
        rt.run(0.3)
    with open(path, "rb") as f:
        reader = make_reader(f)
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
    assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
    assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
    assert summary.chunk_indexes and all(c.compression == "zstd" for c in summary.chunk_indexes)
    schema = next(s for s in summary.schemas.values() if s.name == "sensor_msgs/msg/LaserScan")
    assert b"float32[] ranges" in schema.data and b"MSG: std_msgs/Header" in schema.data


def test_mcap_ros2_decoder_reads_it(fake_run, tmp_path):
    rt, robots = fake_run(1)
    path = tmp_path / "run.mcap"
    with Recorder(rt, path, topics=["/robot0/scan", "/map"]):
        rt.run(0.5)
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        got = [(c.topic, m) for _s, c, _m, m in reader.iter_decoded_messages()]
    assert [topic for topic, _ in got][:2] == ["/map", "/robot0/scan"]
    scans = [m for topic, m in got if topic == "/robot0/scan"]
    assert len(scans) == 5
    np.testing.assert_array_equal(np.asarray(scans[2].ranges), robots[0].scans[2].ranges)
    assert scans[2].header.frame_id == "robot0/base_laser"
    grid = next(m for topic, m in got if topic == "/map")
    assert grid.info.width == 20 and list(grid.data[:3]) == [100, 100, 100]


def test_rosbags_anyreader_reads_it(fake_run, tmp_path):
    rt, robots = fake_run(1)
    path = tmp_path / "run.mcap"
    with Recorder(rt, path):
        rt.run(0.5)
    with AnyReader([path]) as reader:
        conns = {c.topic: c for c in reader.connections}
        assert conns["/robot0/odom"].msgtype == "nav_msgs/msg/Odometry"
        scans = [
            (t, reader.deserialize(raw, c.msgtype))
            for c, t, raw in reader.messages(connections=[conns["/robot0/scan"]])
        ]
    assert [t for t, _ in scans] == [k * 100_000_000 for k in range(1, 6)]
    np.testing.assert_array_equal(scans[-1][1].ranges, robots[0].scans[-1].ranges)


def test_topics_appearing_mid_run_and_selection(fake_run, tmp_path):
    rt, _ = fake_run(1)
    path = tmp_path / "run.mcap"
    rec = Recorder(rt, path, topics=["robot0/scan", "/late"])
    rt.run(0.25)
    late = rt.graph.advertise("/late", std_msgs.String)
    late.publish(std_msgs.String(data="hello"))
    rt.run(0.25)
    rec.close()
    assert rec.recorded_topics == ["/late", "/robot0/scan"]
    msgs = list(BagReader(path).messages())
    assert {m.topic for m in msgs} == {"/late", "/robot0/scan"}
    (hello,) = [m for m in msgs if m.topic == "/late"]
    assert hello.msg.data == "hello" and hello.log_time_ns == 250_000_000


def test_error_in_a_node_loses_nothing(fake_run, tmp_path):
    rt, robots = fake_run(2, fail_at=0.55)
    path = tmp_path / "run.mcap"
    rec = Recorder(rt, path, chunk_size=512)
    with pytest.raises(RuntimeError, match="failed at t=0.60"):
        try:
            rt.run(5.0)
        finally:
            rec.close()
    reader = BagReader(path)
    assert reader.complete
    scans = [m for m in reader.messages() if m.topic == "/robot1/scan"]
    assert len(scans) == len(robots[1].scans) == 5  # t=0.6: robot0 failed before robot1 ran
    assert sum(t.count for t in reader.info().topics) == reader.info().message_count


def test_writes_incrementally_and_close_is_idempotent(fake_run, tmp_path):
    rt, _ = fake_run(2)
    path = tmp_path / "run.mcap"
    rec = Recorder(rt, path, chunk_size=4096)
    rt.run(1.0)
    assert path.stat().st_size > 20_000  # chunks hit the disk while running
    rec.close()
    size = path.stat().st_size
    rec.close()
    rt.shutdown()  # the shutdown hook calls close() again
    assert path.stat().st_size == size and BagReader(path).complete
    assert rec not in rt.graph.listeners and not rt.graph.topics["/tf"].subscriptions


def test_killed_process_leaves_readable_prefix(tmp_path):
    path = tmp_path / "killed.mcap"
    script = textwrap.dedent(
        f"""
        import os, sys
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        from conftest import FakeRobot
        from fleetsim.runtime import Runtime
        from fleetsim.record import Recorder
        rt = Runtime()
        FakeRobot(rt, "/robot0")
        rec = Recorder(rt, {str(path)!r}, chunk_size=2048)
        rt.run(1.0)
        os._exit(0)  # as if killed: no close, no atexit
        """
    )
    subprocess.run([sys.executable, "-c", script], check=True, env={"PYTHONPATH": SRC})
    reader = BagReader(path)
    assert not reader.complete
    with pytest.raises(RecordingError, match=r"killed\.mcap is truncated after \d+ messages"):
        list(reader.messages())
    kept = list(reader.messages(allow_truncated=True))
    assert 10 < len(kept) <= 50
    assert [m.log_time_ns for m in kept] == sorted(m.log_time_ns for m in kept)


def test_bad_arguments(fake_run, tmp_path):
    rt, _ = fake_run(1)
    with pytest.raises(RecordingError, match="compression 'gzip' is not supported; use one of"):
        Recorder(rt, tmp_path / "x.mcap", compression="gzip")
    (tmp_path / "file").write_text("")
    with pytest.raises(RecordingError, match=r"file/x\.mcap: cannot write the recording"):
        Recorder(rt, tmp_path / "file" / "x.mcap")
    with pytest.raises(RecordingError, match="topic name '' is empty"):
        Recorder(rt, tmp_path / "y.mcap", topics=[""])


def test_parameters_stored_as_metadata(fake_run, tmp_path):
    rt, _ = fake_run(1)
    rt.params.set("/robot0/move_base/local_costmap/footprint", [[0.3, 0.2], [-0.3, 0.2]])
    path = tmp_path / "run.mcap"
    with Recorder(rt, path, compression="lz4"):
        rt.run(0.1)
    reader = BagReader(path)
    fp = reader.params()["robot0"]["move_base"]["local_costmap"]["footprint"]
    assert fp == [[0.3, 0.2], [-0.3, 0.2]]
    assert reader.info().compression == "lz4"
