"""map_server loading / map_saver writing."""

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from fleetsim.nav.errors import MapError
from fleetsim.nav.map_io import (
    OccupancyMap,
    load_map,
    load_map_image,
    occupancy_from_pixels,
    save_map,
)

#: the shared data folder beside the repository (../shared from its root)
SHARED = Path(__file__).resolve().parents[2].parent / "shared"

WILLOW = Path(SHARED, "data/maps/willow-full.yaml")


def test_willow_loads_with_origin_row_first():
    m = load_map(WILLOW)
    assert (m.width, m.height) == (540, 587)
    assert m.resolution == pytest.approx(0.1)
    assert set(np.unique(m.data).tolist()) <= {-1, 0, 100}
    raw = np.asarray(Image.open(WILLOW.with_suffix(".pgm")))
    # data row 0 is the image's bottom row
    assert np.array_equal(m.data[0] == 100, raw[-1] < 0.35 * 255)


def test_trinary_scale_raw_thresholds():
    px = np.array([[0, 128, 200, 255]], dtype=np.uint8)
    tri = occupancy_from_pixels(px, negate=False, occupied_thresh=0.65, free_thresh=0.196)
    assert tri.tolist() == [[100, -1, -1, 0]]
    scale = occupancy_from_pixels(
        px, negate=False, occupied_thresh=0.65, free_thresh=0.196, mode="scale"
    )
    occ = (255 - 128) / 255
    assert scale[0, 1] == int(1 + 98 * (occ - 0.196) / (0.65 - 0.196))
    assert scale[0, 0] == 100 and scale[0, 3] == 0
    raw = occupancy_from_pixels(
        px, negate=True, occupied_thresh=0.65, free_thresh=0.196, mode="raw"
    )
    assert raw.view(np.uint8).tolist() == [[255, 127, 55, 0]]
    neg = occupancy_from_pixels(px, negate=True, occupied_thresh=0.65, free_thresh=0.196)
    assert neg.tolist() == [[0, -1, 100, 100]]


def test_save_then_load_round_trip(tmp_path):
    data = np.array([[0, 100, -1], [50, 20, 100]], dtype=np.int8)
    pgm, yml = save_map(OccupancyMap(data, 0.05, (1.0, -2.0, 0.0)), tmp_path / "map")
    assert pgm.read_bytes().startswith(b"P5\n# CREATOR: map_saver.cpp 0.050 m/pix\n3 2\n255\n")
    assert "occupied_thresh: 0.65" in yml.read_text()
    back = load_map(yml)
    assert back.origin == (1.0, -2.0, 0.0)
    assert back.data.tolist() == [[0, 100, -1], [-1, 0, 100]]


def test_legacy_image_resolution_form(tmp_path):
    Image.fromarray(np.array([[0, 255]], dtype=np.uint8)).save(tmp_path / "m.png")
    m = load_map_image(tmp_path / "m.png", 0.5)
    assert m.data.tolist() == [[100, 0]] and m.origin == (0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("image: x.pgm\nresolution: 0.1\n", "does not contain a 'origin' field"),
        (
            "image: x.pgm\nresolution: 0.1\norigin: [0, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.2\n",
            "origin' must be \\[x, y, yaw\\]",
        ),
        (
            "image: x.pgm\nresolution: -1\norigin: [0, 0, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.2\n",
            "resolution must be a positive number",
        ),
        (
            "image: nope.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.2\nmode: trinary\n",
            "nope.pgm does not exist",
        ),
        (
            "image: x.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.2\nmode: fancy\n",
            "'mode' is 'fancy'",
        ),
    ],
)
def test_bad_yaml_names_the_field(tmp_path, text, match):
    f = tmp_path / "bad.yaml"
    f.write_text(text)
    with pytest.raises(MapError, match=match):
        load_map(f)
