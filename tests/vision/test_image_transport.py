from __future__ import annotations

import numpy as np
import pytest

from fleetsim.msgs import sensor_msgs
from fleetsim.vision import VisionError, compress_image, decompressed_array, image_array
from fleetsim.vision.image_transport import bgr_array, gray_array, image_message


def _rgb():
    rng = np.random.default_rng(0)
    return rng.integers(0, 255, (6, 8, 3), dtype=np.uint8)


def test_raw_arrays_and_padded_rows():
    rgb = _rgb()
    msg = image_message(rgb, "rgb8")
    assert np.array_equal(image_array(msg), rgb)
    assert np.array_equal(bgr_array(msg), rgb[..., ::-1])
    assert gray_array(msg).shape == (6, 8)
    padded = np.zeros((6, 30), np.uint8)
    padded[:, :24] = rgb.reshape(6, 24)
    msg2 = sensor_msgs.Image(height=6, width=8, encoding="rgb8", step=30, data=padded.reshape(-1))
    assert np.array_equal(image_array(msg2), rgb)


def test_png_round_trip_is_exact_and_jpeg_close():
    msg = image_message(_rgb(), "rgb8")
    png = compress_image(msg, "png")
    assert png.format == "rgb8; png compressed bgr8"
    assert np.array_equal(decompressed_array(png), _rgb()[..., ::-1])
    flat = image_message(np.full((16, 16, 3), 90, np.uint8), "rgb8")
    jpg = decompressed_array(compress_image(flat), gray=True)
    assert np.abs(jpg.astype(int) - 90).max() <= 2


def test_errors_name_what_is_wrong():
    bad = sensor_msgs.Image(
        height=6, width=8, encoding="rgb8", step=24, data=np.zeros(10, np.uint8)
    )
    with pytest.raises(VisionError, match=r"image on /cam: 8x6 rgb8 with step 24 does not fit 10"):
        image_array(bad, "/cam")
    with pytest.raises(VisionError, match="does not fit an image of 3 channel"):
        image_message(_rgb(), "mono8")
    with pytest.raises(VisionError, match="'jpeg' or 'png'"):
        compress_image(image_message(_rgb(), "rgb8"), "webp")
