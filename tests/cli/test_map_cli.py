"""fleetsim map show / save (from an MCAP recording and from a running simulation)."""

import socket
import threading

import numpy as np
import pytest
from PIL import Image
from typer.testing import CliRunner

from fleetsim.cli.map import app
from fleetsim.msgs import geometry_msgs, nav_msgs
from fleetsim.nav.map_io import OccupancyMap, load_map, save_map
from fleetsim.record import Recorder
from fleetsim.runtime import Node, Runtime

runner = CliRunner()


def small_map():
    data = np.zeros((10, 20), np.int8)
    data[0, :] = 100
    data[5:, 15:] = -1
    return OccupancyMap(data, 0.1, (-1.0, 2.0, 0.0))


def grid_msg(occ):
    g = nav_msgs.OccupancyGrid()
    g.header.frame_id = "map"
    g.info.resolution = occ.resolution
    g.info.height, g.info.width = occ.data.shape
    g.info.origin = geometry_msgs.Pose(
        position=geometry_msgs.Point(x=occ.origin[0], y=occ.origin[1])
    )
    g.data = occ.data.ravel().copy()
    return g


class MapPublisher(Node):
    def __init__(self, rt, occ, topic="/map"):
        super().__init__(rt, "map_server")
        self.create_publisher(nav_msgs.OccupancyGrid, topic, latch=True).publish(grid_msg(occ))


def test_show_prints_metadata_and_draws(tmp_path):
    save_map(small_map(), tmp_path / "m")
    out = tmp_path / "m.png"
    r = runner.invoke(app, ["show", str(tmp_path / "m.yaml"), "-o", str(out), "--width", "400"])
    assert r.exit_code == 0, r.output
    assert "size: 20 x 10 cells, resolution 0.1 m/cell" in r.output
    assert "extent: x -1 .. 1 m, y 2 .. 3 m" in r.output
    assert "cells: 77.5 % free, 10.0 % occupied, 12.5 % unknown" in r.output
    img = Image.open(out)
    assert img.format == "PNG" and img.size[0] == 400
    r = runner.invoke(app, ["show", str(tmp_path / "m.yaml")])
    assert r.exit_code == 0 and "Created" not in r.output


def test_show_errors(tmp_path):
    r = runner.invoke(app, ["show", str(tmp_path / "nope.yaml")])
    assert r.exit_code == 1 and "nope.yaml" in r.output
    save_map(small_map(), tmp_path / "m")
    r = runner.invoke(app, ["show", str(tmp_path / "m.yaml"), "-o", str(tmp_path / "m.jpg")])
    assert r.exit_code == 1 and "give a .png name" in r.output


def test_save_from_a_recording_round_trips(tmp_path):
    occ = small_map()
    rt = Runtime()
    bag = tmp_path / "run.mcap"
    rec = Recorder(rt, bag)
    MapPublisher(rt, occ)
    rt.run(duration=0.1)
    rec.close()
    r = runner.invoke(app, ["save", "-f", str(tmp_path / "out"), "--bag", str(bag)])
    assert r.exit_code == 0, r.output
    assert "Saved a 20 x 10 map at 0.1 m/cell" in r.output
    back = load_map(tmp_path / "out.yaml")
    assert np.array_equal(back.data, occ.data) and back.origin == pytest.approx(occ.origin)
    r = runner.invoke(app, ["save", "--bag", str(bag), "--topic", "/other_map"])
    assert r.exit_code == 1 and "no messages on /other_map" in r.output
    assert "OccupancyGrid topics there: /map" in r.output


def test_save_from_a_running_simulation(tmp_path):
    from fleetsim.transport import ZenohBridge

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        ep = f"tcp/127.0.0.1:{s.getsockname()[1]}"
    rt = Runtime()
    occ = small_map()
    MapPublisher(rt, occ)
    ZenohBridge(rt, listen=[ep])
    stop = threading.Event()
    thread = threading.Thread(target=lambda: rt.run(until=stop.is_set, rate=1.0), daemon=True)
    thread.start()
    try:
        r = runner.invoke(app, ["save", "-f", str(tmp_path / "live"), "--connect", ep])
        assert r.exit_code == 0, r.output
        assert np.array_equal(load_map(tmp_path / "live.yaml").data, occ.data)
        r = runner.invoke(app, ["save", "--connect", ep, "--topic", "/nomap"])
        assert r.exit_code == 1 and "has no topic /nomap" in r.output
        # the grids there are, named (a SLAM robot's map is in its namespace)
        assert "OccupancyGrids are on /map" in " ".join(r.output.split())
    finally:
        stop.set()
        thread.join(10)
        rt.shutdown()
