"""Player: republishes a recording on sim time, latched topics latched, bad input named."""

from __future__ import annotations

import pytest

from fleetsim.errors import RecordingError
from fleetsim.msgs import msgs_equal, nav_msgs, sensor_msgs, std_msgs
from fleetsim.record import BagReader, Player, Recorder
from fleetsim.runtime import Runtime


@pytest.fixture
def recording(fake_run, tmp_path):
    rt, robots = fake_run(1)
    path = tmp_path / "run.mcap"
    with Recorder(rt, path):
        rt.run(1.0)
    return path, robots[0]


def test_replay_on_sim_time_with_offset(recording):
    path, robot = recording
    rt = Runtime()
    rt.run(2.0)
    got = []
    rt.graph.subscribe("/robot0/scan", sensor_msgs.LaserScan, lambda m: got.append((rt.now(), m)))
    player = Player(rt, path)
    rt.run(until=lambda: player.done, duration=10.0)
    assert player.published == 51 and player.done
    assert [round(t, 9) for t, _ in got] == [round(2.0 + 0.1 * k, 9) for k in range(1, 11)]
    assert all(msgs_equal(m, s) for (_, m), s in zip(got, robot.scans))
    assert player.end_time == pytest.approx(3.0)


def test_latched_map_reaches_late_subscribers(recording):
    path, _ = recording
    rt = Runtime()
    player = Player(rt, path, topics=["/map"], start=0.0)
    rt.run(0.5)
    maps = []
    rt.graph.subscribe("/map", nav_msgs.OccupancyGrid, maps.append)
    rt.spin_once()
    assert len(maps) == 1 and maps[0].info.width == 20 and player.done


def test_record_play_record_is_identical(recording, tmp_path):
    path, _ = recording
    rt = Runtime()
    again = tmp_path / "again.mcap"
    rec = Recorder(rt, again)
    player = Player(rt, path, start=0.0)
    rt.run(until=lambda: player.done, duration=5.0)
    rec.close()
    a = [(m.topic, m.log_time_ns, m.data) for m in BagReader(path).messages(decode=False)]
    b = [(m.topic, m.log_time_ns, m.data) for m in BagReader(again).messages(decode=False)]
    assert sorted(a) == sorted(b)


def test_bad_input(recording):
    path, _ = recording
    rt = Runtime()
    with pytest.raises(RecordingError, match=r"has no topic /nope; it records /map, /robot0/odom"):
        Player(rt, path, topics=["/nope"])
    rt.graph.advertise("/robot0/scan", std_msgs.String)
    player = Player(rt, path, topics=["/robot0/scan"])
    with pytest.raises(RecordingError, match="cannot play .*topic /robot0/scan already carries"):
        rt.run(1.0)
    player.stop()
    assert player.done
