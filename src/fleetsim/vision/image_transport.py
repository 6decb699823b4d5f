"""Images as arrays: sensor_msgs ``Image`` and ``CompressedImage`` to and from NumPy.

What cv_bridge and image_transport's ``compressed`` plugin do for C++ nodes: `image_array`
gives a raw image's pixels as an (H, W, C) or (H, W) uint8 array (no copy when rows are not
padded), `compress_image` JPEG- or PNG-encodes an array as image_transport publishes it on
``<base>/compressed`` (``format`` is ``"rgb8; jpeg compressed bgr8"``, as the plugin writes it),
and `decompressed_array` decodes one. OpenCV does the coding (`cv2.imencode`/`cv2.imdecode`).
"""

from __future__ import annotations

import cv2
import numpy as np

from fleetsim.msgs import sensor_msgs
from fleetsim.vision.errors import VisionError

#: channels of each 8-bit encoding we read
CHANNELS = {"rgb8": 3, "bgr8": 3, "mono8": 1, "rgba8": 4, "bgra8": 4}


def image_array(msg: sensor_msgs.Image, topic: str = "") -> np.ndarray:
    """The pixels of an 8-bit ``Image``: (H, W, C) uint8, or (H, W) for ``mono8``."""
    where = f"image on {topic}" if topic else "image"
    ch = CHANNELS.get(msg.encoding)
    if ch is None:
        raise VisionError(
            f"{where}: encoding '{msg.encoding}' is not supported; use one of {', '.join(CHANNELS)}"
        )
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    data = np.asarray(msg.data, dtype=np.uint8)
    if h < 1 or w < 1 or step < w * ch or data.size < h * step:
        raise VisionError(
            f"{where}: {w}x{h} {msg.encoding} with step {step} does not fit {data.size} bytes"
        )
    rows = data[: h * step].reshape(h, step)[:, : w * ch]
    return rows.reshape(h, w) if ch == 1 else rows.reshape(h, w, ch)


def gray_array(msg: sensor_msgs.Image, topic: str = "") -> np.ndarray:
    """The image as (H, W) uint8 grey levels (what the ArUco detector reads)."""
    img = image_array(msg, topic)
    code = {
        "rgb8": cv2.COLOR_RGB2GRAY,
        "bgr8": cv2.COLOR_BGR2GRAY,
        "rgba8": cv2.COLOR_RGBA2GRAY,
        "bgra8": cv2.COLOR_BGRA2GRAY,
    }.get(msg.encoding)
    return img if code is None else cv2.cvtColor(img, code)


def bgr_array(msg: sensor_msgs.Image, topic: str = "") -> np.ndarray:
    """The image as (H, W, 3) uint8 BGR (cv_bridge's ``toCvCopy(msg, BGR8)``), a copy."""
    img = image_array(msg, topic)
    code = {
        "rgb8": cv2.COLOR_RGB2BGR,
        "mono8": cv2.COLOR_GRAY2BGR,
        "rgba8": cv2.COLOR_RGBA2BGR,
        "bgra8": cv2.COLOR_BGRA2BGR,
    }.get(msg.encoding)
    return img.copy() if code is None else cv2.cvtColor(img, code)


def image_message(pixels: np.ndarray, encoding: str, header=None) -> sensor_msgs.Image:
    """A ``sensor_msgs/Image`` holding ``pixels`` ((H, W, C) or (H, W) uint8)."""
    arr = np.ascontiguousarray(pixels, dtype=np.uint8)
    h, w = arr.shape[:2]
    ch = 1 if arr.ndim == 2 else arr.shape[2]
    if CHANNELS.get(encoding) != ch:
        raise VisionError(f"encoding '{encoding}' does not fit an image of {ch} channel(s)")
    msg = sensor_msgs.Image(height=h, width=w, encoding=encoding, step=w * ch, data=arr.reshape(-1))
    if header is not None:
        msg.header = header
    return msg


def compress_image(
    msg: sensor_msgs.Image, fmt: str = "jpeg", quality: int = 80
) -> sensor_msgs.CompressedImage:
    """Encode a raw image as image_transport's ``compressed`` plugin does (JPEG quality 80)."""
    if fmt not in ("jpeg", "png"):
        raise VisionError(f"compressed format must be 'jpeg' or 'png', got {fmt!r}")
    img = image_array(msg)
    if msg.encoding in ("rgb8", "rgba8"):
        img = cv2.cvtColor(
            img, cv2.COLOR_RGB2BGR if msg.encoding == "rgb8" else cv2.COLOR_RGBA2BGRA
        )
    params = [cv2.IMWRITE_JPEG_QUALITY, quality] if fmt == "jpeg" else []
    ok, buf = cv2.imencode(".jpg" if fmt == "jpeg" else ".png", img, params)
    if not ok:
        raise VisionError(f"OpenCV could not {fmt}-encode a {msg.width}x{msg.height} image")
    target = "bgr8" if img.ndim == 3 and img.shape[2] == 3 else msg.encoding
    return sensor_msgs.CompressedImage(
        header=msg.header,
        format=f"{msg.encoding}; {fmt} compressed {target}",
        data=buf.reshape(-1),
    )


def decompressed_array(msg: sensor_msgs.CompressedImage, topic: str = "", gray: bool = False):
    """Decode a ``CompressedImage``: (H, W, 3) uint8 BGR, or (H, W) grey when ``gray``."""
    data = np.asarray(msg.data, dtype=np.uint8)
    flag = cv2.IMREAD_GRAYSCALE if gray else cv2.IMREAD_COLOR
    img = cv2.imdecode(data, flag) if data.size else None
    if img is None:
        where = f" on {topic}" if topic else ""
        raise VisionError(
            f"compressed image{where} (format '{msg.format}', {data.size} bytes) could not be "
            "decoded as JPEG or PNG"
        )
    return img
