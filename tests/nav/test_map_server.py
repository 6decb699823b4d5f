"""map_server and map_saver nodes: arguments, latched topics, static_map, frame_id, saving."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from fleetsim.msgs import nav_msgs
from fleetsim.nav.errors import MapError
from fleetsim.nav.map_io import OccupancyMap, load_map
from fleetsim.nav.map_server import (
    MapSaver,
    MapServer,
    grid_msg_from_map,
    map_from_grid_msg,
    saver_options,
)
from fleetsim.runtime import Node, Runtime


def write_map(tmp_path, name="room"):
    """A 12 x 8 picture: free inside, a black border, one grey (unknown) cell."""
    px = np.full((8, 12), 254, dtype=np.uint8)
    px[0, :] = px[-1, :] = px[:, 0] = px[:, -1] = 0
    px[3, 5] = 205
    img = tmp_path / f"{name}.pgm"
    Image.fromarray(px).save(img)
    yml = tmp_path / f"{name}.yaml"
    yml.write_text(
        f"image: {img.name}\nresolution: 0.25\norigin: [-1.0, 2.0, 0.5]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return yml, img


class Catcher(Node):
    def __init__(self, rt, ns="/"):
        super().__init__(rt, "catcher", ns)
        self.maps, self.meta = [], []
        self.create_subscription(nav_msgs.OccupancyGrid, "map", self.maps.append)
        self.create_subscription(nav_msgs.MapMetaData, "map_metadata", self.meta.append)


def test_yaml_argument_publishes_latched_map_metadata_and_serves_static_map(tmp_path):
    yml, _ = write_map(tmp_path)
    rt = Runtime()
    rt.params.set("/map_server/frame_id", "/map")
    server = MapServer(rt, args=[str(yml)])
    out = Catcher(rt)  # subscribes after the publish: latched topics still deliver
    rt.run(duration=0.1)
    expected = load_map(yml)
    assert len(out.maps) == 1 and len(out.meta) == 1
    msg = out.maps[0]
    assert msg.header.frame_id == "map"  # the leading slash is dropped
    assert (msg.info.width, msg.info.height) == (12, 8)
    assert msg.info.resolution == pytest.approx(0.25)
    assert msg.info.origin.position.x == -1.0 and msg.info.origin.position.y == 2.0
    np.testing.assert_array_equal(msg.data.reshape(8, 12), expected.data)
    assert out.meta[0].width == 12
    resp = rt.graph.call_service("/static_map", nav_msgs.GetMap)
    np.testing.assert_array_equal(resp.map.data, msg.data)
    assert server.map.origin[2] == pytest.approx(0.5)
    assert map_from_grid_msg(msg).origin[2] == pytest.approx(0.5)


def test_legacy_image_and_resolution_form_as_one_string(tmp_path, caplog):
    _, img = write_map(tmp_path)
    rt = Runtime()
    server = MapServer(rt, "map_server", "/lizi1", args=[f"{img} 0.1"])
    assert server.map.resolution == pytest.approx(0.1)
    assert server.map.origin == (0.0, 0.0, 0.0)
    assert "deprecated" in caplog.text
    assert "/lizi1/map" in rt.graph.topics and "/lizi1/static_map" in rt.graph.services
    assert server.map.data[0, 0] == 100 and server.map.data[4, 5] == -1  # image row 3 -> row 4


def test_map_file_keyword_and_frame_id_default(tmp_path):
    yml, img = write_map(tmp_path)
    rt = Runtime()
    assert MapServer(rt, map_file=yml).grid_msg.header.frame_id == "map"
    other = MapServer(rt, "legacy", "/other", map_file=img, resolution=0.5)
    assert other.map.resolution == 0.5


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ([], r"expected a map file argument, got \[\]"),
        (["a.png", "fine"], r"resolution argument 'fine' is not a number"),
        (["missing.yaml"], r"map file missing.yaml does not exist"),
        (["a", "b", "c"], r"usage: map_server <map.yaml>"),
    ],
)
def test_bad_arguments_raise_map_error(args, match):
    with pytest.raises(MapError, match=match):
        MapServer(Runtime(), args=args)


def test_grid_msg_with_wrong_data_size_is_rejected():
    msg = grid_msg_from_map(OccupancyMap(np.zeros((3, 4), np.int8), 0.1, (0, 0, 0)))
    msg.info.width = 5
    with pytest.raises(MapError, match=r"holds 12 cells but info says 5 x 3 = 15"):
        map_from_grid_msg(msg, "test")
    msg.info.width, msg.info.resolution = 4, 0.0
    with pytest.raises(MapError, match=r"resolution must be > 0 m, got 0.0"):
        map_from_grid_msg(msg, "test")


@settings(max_examples=40, deadline=None)
@given(
    h=st.integers(1, 6),
    w=st.integers(1, 6),
    ox=st.floats(-50, 50),
    oy=st.floats(-50, 50),
    yaw=st.floats(-3.1, 3.1),
    seed=st.integers(0, 1000),
)
def test_grid_message_round_trip(h, w, ox, oy, yaw, seed):
    data = np.random.default_rng(seed).integers(-1, 101, (h, w)).astype(np.int8)
    occ = OccupancyMap(data, 0.05, (ox, oy, yaw))
    back = map_from_grid_msg(grid_msg_from_map(occ, "map"))
    np.testing.assert_array_equal(back.data, data)
    assert back.origin[0] == ox and back.origin[1] == oy
    assert math.isclose(back.origin[2], yaw, abs_tol=1e-9)


def test_map_saver_writes_the_first_map_it_receives(tmp_path):
    yml, _ = write_map(tmp_path)
    rt = Runtime()
    MapServer(rt, args=[str(yml)])
    out = tmp_path / "saved" / "copy"
    out.parent.mkdir()
    saver = MapSaver(rt, args=["-f", str(out), "--occ", "70"])
    rt.run(duration=0.1)
    assert saver.saved is not None
    pgm, yaml_path = saver.saved
    assert pgm.name == "copy.pgm" and yaml_path.exists()
    again = load_map(yaml_path)
    np.testing.assert_array_equal(again.data, load_map(yml).data)
    assert again.origin[:2] == (-1.0, 2.0)
    assert not rt.graph.topics["/map"].subscriptions[1:]  # the saver let go of the topic


@pytest.mark.parametrize(
    ("tokens", "match"),
    [
        (["-x"], r"unknown argument '-x'"),
        (["-f"], r"'-f' needs a value"),
        (["--occ", "high"], r"the threshold must be an integer"),
        (["--free", "120"], r"thresholds are in \[0, 100\]"),
        (["--occ", "20", "--free", "30"], r"--free \(30\) must be below --occ \(20\)"),
    ],
)
def test_map_saver_argument_errors(tokens, match):
    with pytest.raises(MapError, match=match):
        saver_options(tokens)


def test_map_saver_into_a_missing_directory_is_refused_at_start(tmp_path):
    """Not when the map comes, or at shutdown after a whole SLAM run (found by a new user)."""
    out = tmp_path / "no_such_dir" / "mymap"
    with pytest.raises(
        MapError, match=rf"/map_saver: -f {out}: the directory {out.parent} does not exist"
    ):
        MapSaver(Runtime(), args=["-f", str(out)])


def test_map_saver_defaults():
    assert saver_options([]) == ("map", 65, 25)


def test_map_saver_save_on_shutdown_writes_the_latest_map(tmp_path, caplog):
    from fleetsim.nav.map_server import grid_msg_from_map

    rt = Runtime()
    pub = Node(rt, "slam").create_publisher(nav_msgs.OccupancyGrid, "/map", 1, latch=True)
    out = tmp_path / "latest"
    saver = MapSaver(rt, args=["-f", str(out)], params={"save_on_shutdown": True})
    for value in (0, 100):
        grid = OccupancyMap(np.full((3, 4), value, dtype=np.int8), 0.1, (0.0, 0.0, 0.0))
        pub.publish(grid_msg_from_map(grid))
        rt.run(duration=0.1)
    assert saver.saved is None  # nothing written while the map may still grow
    rt.shutdown()
    assert (load_map(out.with_suffix(".yaml")).data == 100).all()
    # a run that ends before any map says so
    rt = Runtime()
    MapSaver(rt, args=["-f", str(tmp_path / "none")], params={"save_on_shutdown": True})
    with caplog.at_level("WARNING"):
        rt.shutdown()
    assert "no map received on /map; nothing saved" in caplog.text
