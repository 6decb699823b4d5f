"""Renders: the PNG's pixels show the map and robots where they are; the MP4 has every frame."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest

from fleetsim.errors import FleetsimError, RecordingError
from fleetsim.record import Recorder
from fleetsim.runtime import Runtime
from fleetsim.viz.render import frame_times_ns, render
from fleetsim.viz.robots import colour_of

BLUE = np.array(colour_of(0)) * 255  # robot0, the first robot found
ORANGE = np.array(colour_of(1)) * 255


def _near(pixel, rgb, tol=30):
    return np.abs(pixel.astype(float) - rgb).max() <= tol


def test_png_pixels(room_recording, tmp_path):
    path, duration = room_recording
    res = render(path, tmp_path / "out.png", width=400)
    img = iio.imread(res.path)
    assert img.shape == (res.height, res.width, 3) == (320, 400, 3)
    x_end = 2.0 + 0.5 * duration  # both robots drive at 0.5 m/s from x = 2
    # robot0's 0.6 x 0.4 m footprint behind its centre, off the heading line
    col, row = res.world_to_pixel(x_end - 0.2, 2.0 - 0.1)
    assert _near(img[row, col], BLUE), img[row, col]
    col, row = res.world_to_pixel(x_end - 0.1, 2.0 + 0.3)  # in a 0.46 m circle, not the box
    assert not _near(img[row, col], BLUE)
    # robot1 has no footprint parameter: a 0.46 m circle
    col, row = res.world_to_pixel(x_end - 0.25, 6.0 - 0.25)
    assert _near(img[row, col], ORANGE), img[row, col]
    # the map: a wall is black, free space white, the unknown patch grey
    wall = img[res.world_to_pixel(0.05, 4.0)[::-1]]
    free = img[res.world_to_pixel(1.0, 4.0)[::-1]]
    unknown = img[res.world_to_pixel(7.75, 4.0)[::-1]]
    assert wall.max() < 40 and free.min() > 240 and 190 < unknown.mean() < 220
    # the trail behind robot0 (it started at x = 2) is drawn in its colour
    col, row = res.world_to_pixel(2.5, 2.0)
    assert img[row, col][2] > img[row, col][0] + 40


def test_mp4_frame_count_and_last_frame(room_recording, tmp_path):
    path, duration = room_recording
    res = render(path, tmp_path / "out.mp4", fps=5, speed=2.0, width=240)
    assert res.frames == len(frame_times_ns(0, int(duration * 1e9), 5, 2.0)) == 11
    frames = iio.imread(res.path, index=None)
    assert frames.shape == (11, res.height, res.width, 3)
    assert frames[0].min() < 40 and frames[0].max() > 240  # t = 0: the map, no robot yet
    col, row = res.world_to_pixel(2.2 - 0.2, 6.0 - 0.2)  # frame 1 is t = 0.4 s: x = 2.2
    assert _near(frames[1][row, col], ORANGE, tol=60), frames[1][row, col]
    col, row = res.world_to_pixel(2.0 + 0.5 * duration - 0.2, 6.0 - 0.2)
    assert _near(frames[-1][row, col], ORANGE, tol=60)


def test_frame_times():
    t = frame_times_ns(1_000, 1_000 + 2_000_000_000, fps=10, speed=1.0)
    assert t.shape == (21,) and t[0] == 1_000 and t[-1] == 1_000 + 2_000_000_000
    assert frame_times_ns(0, 0, 10, 1.0).tolist() == [0]


def test_bad_requests(room_recording, tmp_path):
    path, _ = room_recording
    with pytest.raises(
        FleetsimError, match=r"out\.gif: cannot render to '\.gif'; use \.png or \.mp4"
    ):
        render(path, tmp_path / "out.gif")
    with pytest.raises(FleetsimError, match="fps must be > 0, got 0"):
        render(path, tmp_path / "out.mp4", fps=0)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(path.read_bytes()[:5000])
    with pytest.raises(RecordingError, match=r"cut\.mcap is truncated after \d+ messages"):
        render(cut, tmp_path / "out.png")
    empty = tmp_path / "empty.mcap"
    rt = Runtime()
    with Recorder(rt, empty):
        rt.run(0.1)
    with pytest.raises(FleetsimError, match="nothing to draw: the recording has no /map map"):
        render(empty, tmp_path / "out.png")
